"""The CLI answers hostile input with one clear line on stderr and exit 2, and changes nothing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rrbot_workshop import cli


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = cli.main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _one_clear_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rrbot-workshop") and " error: " in lines[0], err
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture
def files(tmp_path: Path) -> Path:
    (tmp_path / "empty.yaml").write_bytes(b"")
    (tmp_path / "comment.yaml").write_bytes(b"# nothing\n")
    (tmp_path / "binary.yaml").write_bytes(bytes(range(256)) * 4)
    (tmp_path / "latin1.yaml").write_bytes("contr\xf4leur: 1\n".encode("latin-1"))
    (tmp_path / "deep.yaml").write_text("a: " + "[" * 20000 + "]" * 20000 + "\n")
    (tmp_path / "folder.yaml").mkdir()
    (tmp_path / "bom.yaml").write_bytes(b"\xef\xbb\xbfcontroller_manager:\n  ros__parameters:\n    update_rate: 100\n")
    return tmp_path


@pytest.mark.parametrize(("name", "says"), [
    ("empty.yaml", "is empty"), ("comment.yaml", "is empty"), ("binary.yaml", "binary file"),
    ("latin1.yaml", "is not UTF-8 text"), ("deep.yaml", "nested too deeply"), ("folder.yaml", "is a folder"),
    ("missing.yaml", "cannot be read"),
])
def test_lint_reports_an_unusable_yaml_as_an_error(name: str, says: str, files: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(["lint", str(files / name)], capsys)
    assert code == cli.LINT_ERRORS and says in out and "no problems found" not in out and "Traceback" not in out


def test_lint_reads_a_file_with_a_byte_order_mark(files: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(["lint", str(files / "bom.yaml")], capsys)
    assert code == 0 and "no problems found" in out


@pytest.mark.parametrize("argv", [
    ["grade", "1", "--root", "/nonexistent/rrbot"], ["grade", "1", "--root", "/"], ["grade", "1", "--root", ""],
    ["grade", "1", "--timeout", "-1"], ["grade", "1", "--timeout", "0"], ["grade", "1", "--timeout", "nan"],
    ["grade", "1", "--timeout", "inf"], ["progress", "--root", "/nonexistent/rrbot"],
    ["progress", "--timeout=-inf"], ["progress", "--timeout", "soon"], ["grade", "x"], ["lint", "x.yaml", "--xacro-arg", "a:=b\nc"],
    ["lint", "x.yaml", "--xacro-arg", "a-b:=c"], ["lint", "x.yaml", "--xacro-arg", "novalue"],
    ["export", "--ros2", ""], ["export", "--student", ""],
], ids=repr)
def test_bad_arguments_get_one_line_and_exit_2(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(argv, capsys)
    assert code == cli.USAGE_ERROR
    _one_clear_line(err)


def test_grade_root_at_a_file_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "f.txt"
    f.write_text("x")
    code, _, err = _run(["grade", "1", "--root", str(f)], capsys)
    assert code == cli.USAGE_ERROR and "is a file" in _one_clear_line(err)


def test_python_m_rrbot_workshop_help_exits_0() -> None:
    done = subprocess.run([sys.executable, "-m", "rrbot_workshop", "--help"], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0 and "usage:" in done.stdout
