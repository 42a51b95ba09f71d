"""The learner's and the instructor's way through the course, on a copy of this repository.

* the start command serves the course folder on 127.0.0.1: exercises reachable and editable through JupyterLab's
  contents API, the notebooks as the learner's own copies, the tracked notebooks out of sight;
* a learner who solved tasks and ran notebooks still gets a green test command, and ``git status`` shows only their
  exercise files;
* ``export --student`` takes the exercises as committed, never an instructor's solved ones.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HAS_GIT = shutil.which("git") is not None and (ROOT / ".git").exists()
needs_solutions = pytest.mark.skipif(not (ROOT / "solutions").is_dir(), reason="this copy of the course has no solutions/")
_IDENTITY = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.invalid", "GIT_COMMITTER_NAME": "t",
             "GIT_COMMITTER_EMAIL": "t@example.invalid"}
pytestmark = pytest.mark.skipif(not HAS_GIT, reason="needs git and a git checkout of the course")


#: The environment the course's test command was given (a student copy tested with CI's environment), kept for the
#: clone's own commands, which then run on it with the clone's package first on PYTHONPATH.
_GIVEN = "RRBOT_WORKSHOP_PYTHON"


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("RRBOT_WORKSHOP_", "GIT_")) or k == _GIVEN}
    env.pop("PYTHONPATH", None)  # the clone's launcher puts its own folder there
    env.update(_IDENTITY)
    return env


def _share_venv(target: Path) -> None:
    """Point ``target``'s ``.venv`` at this checkout's, which must be set up for this ``pyproject.toml``: a stale one
    would make the copy's set-up reinstall into it, through the link, from a folder the test then deletes. With an
    environment given to the test command, the clone's commands use that one instead."""
    if os.environ.get(_GIVEN):
        return
    stamp = ROOT / ".venv" / ".installed"
    want = hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest()
    if not stamp.is_file() or stamp.read_text().strip() != want:
        pytest.fail("this checkout's .venv is not set up for its pyproject.toml: run ./workshop test once first",
                    pytrace=False)
    (target / ".venv").symlink_to(ROOT / ".venv")


@pytest.fixture(scope="module")
def clone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh clone of this repository's HEAD that shares this checkout's installed environment."""
    target = tmp_path_factory.mktemp("learner") / "course"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(target)], check=True, env=_env())
    _share_venv(target)  # already set up: no second installation
    return target


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _api(port: int, token: str, path: str, method: str = "GET", body: dict | None = None) -> tuple[int, dict]:
    request = urllib.request.Request(
        f"http://127.0.0.1:{port}/api/contents/{path}", method=method,
        data=json.dumps(body).encode() if body is not None else None,
        headers={"Authorization": f"token {token}", "Content-Type": "application/json"},
    )
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, json.loads(response.read() or b"{}")
    except urllib.error.HTTPError as exc:
        return exc.code, {}


@pytest.mark.slow
def test_start_command_serves_the_exercises_and_the_learners_notebooks(clone: Path) -> None:
    port, token = _free_port(), "rrbot-test-token"
    proc = subprocess.Popen(
        [sys.executable, str(clone / "workshop.py"), "start", "--no-browser", f"--port={port}",
         "--ServerApp.port_retries=0", f"--IdentityProvider.token={token}"],
        cwd=clone, env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 90
        status = 0
        while time.monotonic() < deadline and status != 200:
            time.sleep(0.5)
            assert proc.poll() is None, "the start command exited"
            try:
                status, listing = _api(port, token, "")
            except OSError:
                status = 0
        assert status == 200, "JupyterLab did not answer on 127.0.0.1"
        names = {item["name"] for item in listing["content"]}
        assert {"exercises", "my_notebooks"} <= names, names
        assert "notebooks" not in names, "the tracked notebooks must stay out of the learner's file browser"
        status, notebook = _api(port, token, "my_notebooks/00_intro.ipynb")
        assert status == 200 and notebook["type"] == "notebook"
        path = "exercises/task03_components/answers.py"
        status, model = _api(port, token, path)
        assert status == 200, f"{path} is not reachable ({status})"
        edited = model["content"] + "\n# edited in JupyterLab\n"
        status, _ = _api(port, token, path, "PUT", {"type": "file", "format": "text", "content": edited})
        assert status == 200
        assert (clone / path).read_text() == edited
        subprocess.run(["git", "checkout", "--", path], cwd=clone, check=True, env=_env())
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)


def test_notebook_copies_are_refreshed_with_a_backup(tmp_path: Path) -> None:
    sys.path.insert(0, str(ROOT))
    from rrbot_workshop.classroom.launcher import refresh_notebook_copies

    (tmp_path / "notebooks").mkdir()
    course = tmp_path / "notebooks" / "01_x.ipynb"
    course.write_text("v1")
    assert refresh_notebook_copies(tmp_path, now=0) == ["01_x.ipynb: copied to my_notebooks/"]
    mine = tmp_path / "my_notebooks" / "01_x.ipynb"
    mine.write_text("v1 with my outputs")
    assert refresh_notebook_copies(tmp_path, now=0) == []  # the course did not change: the learner's copy stays
    assert mine.read_text() == "v1 with my outputs"
    course.write_text("v2")
    lines = refresh_notebook_copies(tmp_path, now=0)
    backup = tmp_path / "my_notebooks" / "backups" / time.strftime("%Y%m%d-%H%M%S", time.localtime(0)) / "01_x.ipynb"
    assert lines and "backups" in lines[0]
    assert backup.read_text() == "v1 with my outputs" and mine.read_text() == "v2"


@pytest.mark.slow
@needs_solutions
def test_solved_exercises_and_saved_notebooks_keep_the_tests_green(clone: Path) -> None:
    """Solve tasks 1 and 2, run two notebooks from my_notebooks/: the course's own tests still pass, and git sees only
    the learner's exercise files."""
    for task in ("task01_description", "task02_mock_hardware"):
        shutil.copytree(clone / "solutions" / task, clone / "exercises" / task, dirs_exist_ok=True)
    sys.path.insert(0, str(ROOT))
    from rrbot_workshop.classroom.launcher import refresh_notebook_copies

    refresh_notebook_copies(clone)
    python = str(ROOT / ".venv" / "bin" / "python")
    for name in ("01_description.ipynb", "02_mock_hardware.ipynb"):
        subprocess.run([python, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute", "--inplace", name],
                       cwd=clone / "my_notebooks", env=_env(), check=True, capture_output=True)
    selection = ["-q", "-p", "no:cacheprovider", *(f"tests/unit/test_graders.py::{test}[{task}]" for task in (1, 2)
                                                    for test in ("test_solution_gets_full_marks",
                                                                 "test_untouched_exercise_does_not_get_full_marks"))]
    result = subprocess.run([sys.executable, "workshop.py", "test", *selection], cwd=clone, env=_env(),
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    nbval = ["--nbval", "--nbval-current-env", "--nbval-sanitize-with", "notebooks/nbval_sanitize.cfg", "-p",
             "no:cacheprovider", "notebooks/01_description.ipynb", "notebooks/02_mock_hardware.ipynb"]
    result = subprocess.run([sys.executable, "workshop.py", "test", *nbval], cwd=clone,
                            env={**_env(), "RRBOT_WORKSHOP_TRACK": "exercises"}, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    changed = subprocess.run(["git", "status", "--porcelain"], cwd=clone, env=_env(), capture_output=True,
                             text=True, check=True).stdout.splitlines()
    assert changed and all(line[3:].startswith("exercises/") for line in changed), changed
    subprocess.run(["git", "checkout", "--", "exercises"], cwd=clone, check=True, env=_env())


@pytest.mark.slow
@needs_solutions
def test_student_copy_from_a_solved_tree_has_the_pristine_exercises(clone: Path, tmp_path: Path) -> None:
    """An instructor's clone with solved exercises hands out the exercises as committed, without solutions/."""
    solved = clone / "exercises" / "task01_description"
    shutil.copytree(clone / "solutions" / "task01_description", solved, dirs_exist_ok=True)
    target = tmp_path / "student"
    env = _env()
    assert not target.exists()
    result = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "export", "--student", str(target)],
                            cwd=clone, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "Not in the copy: uncommitted changes" in result.stdout
    subprocess.run(["git", "checkout", "--", "exercises"], cwd=clone, check=True, env=env)
    assert not (target / "solutions").exists()
    tracked = subprocess.run(["git", "ls-files", "exercises"], cwd=clone, env=env, capture_output=True, text=True,
                             check=True).stdout.split()
    assert tracked, "no exercise files are committed"
    for rel in tracked:  # the learner's git-ignored files (attempt log, caches) are not part of the copy
        assert (target / rel).read_bytes() == (clone / rel).read_bytes(), f"{rel} differs from the committed exercise"
    assert not (target / "exercises" / ".progress").exists(), "a learner's attempt log was handed out"
    log = subprocess.run(["git", "log", "--oneline"], cwd=target, env=env, capture_output=True, text=True, check=True)
    assert len(log.stdout.splitlines()) == 1, "the student copy is a repository with one commit"
    assert "solutions track" not in (target / "README.md").read_text()
    graded = subprocess.run([sys.executable, "-m", "rrbot_workshop.cli", "grade", "1", "--json"],
                            cwd=target, env=env, capture_output=True, text=True)
    data = json.loads(graded.stdout)
    assert data["score"] < data["max_score"], "the untouched exercise of the copy got full marks"
    _share_venv(target)  # the course's environment, already set up
    # task 1, the one solved in the instructor's tree (CI runs a whole copy's test command: .ci/run)
    tests = subprocess.run([sys.executable, "workshop.py", "test", "-q", "-p", "no:cacheprovider",
                            "tests/unit/test_graders.py::test_untouched_exercise_does_not_get_full_marks[1]",
                            "tests/unit/test_tracks.py"],
                           cwd=target, env=env, capture_output=True, text=True)
    assert tests.returncode == 0, tests.stdout[-3000:]
