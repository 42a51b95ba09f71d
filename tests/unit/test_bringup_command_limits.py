"""``rrbot-workshop bringup`` reads only regular files (a FIFO or a device as the description, the controllers or an
include is one line and exit 2, never a hang) and runs a bounded amount of work (``--seconds`` and the control cycles
it makes have a stated limit)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from workspace_helpers import no_hang, tree

from rrbot_workshop.cli import main
from rrbot_workshop.course import tracks
from rrbot_workshop.tools.commands import BRINGUP_MAX_CYCLES, BRINGUP_MAX_SECONDS

COURSE = tracks.course_root()
XACRO = str(COURSE / "descriptions" / "rrbot" / "urdf" / "rrbot.urdf.xacro")
YAML = str(COURSE / "descriptions" / "rrbot" / "config" / "rrbot_controllers.yaml")
_URDF = """<robot name="one">
  <link name="base"/><link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="one" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="j"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
</robot>
"""


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    lines = [line for line in err.strip().splitlines() if not line.startswith(("INFO ", "WARNING "))]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def _fifo(path: Path) -> Path:
    os.mkfifo(path)
    return path


def _release(path: Path) -> None:
    """Unblock a reader stuck on the FIFO (so a failing test ends)."""
    try:
        os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
    except OSError:
        pass


@pytest.mark.parametrize("name", ["robot.urdf", "robot.urdf.xacro", "robot"])
def test_a_fifo_as_the_description_is_one_line_not_a_hang(name: str, tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    fifo = _fifo(tmp_path / name)
    code = no_hang(main, ["bringup", str(fifo)], release=lambda: _release(fifo))
    assert code == 2
    line = _one_line(capsys)
    assert str(fifo) in line and ("FIFO" in line or "not a regular file" in line or "not found" in line), line


def test_a_fifo_as_the_controllers_is_one_line_not_a_hang(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fifo = _fifo(tmp_path / "controllers.yaml")
    code = no_hang(main, ["bringup", XACRO, "--controllers", str(fifo)], release=lambda: _release(fifo))
    assert code == 2 and "FIFO" in _one_line(capsys)


def test_a_link_to_a_device_as_the_controllers_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "zero.yaml").symlink_to("/dev/zero")
    assert no_hang(main, ["bringup", XACRO, "--controllers", str(tmp_path / "zero.yaml")]) == 2
    assert "a device" in _one_line(capsys)


def test_a_fifo_reached_through_a_package_is_refused_by_the_reader(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """package://pkg/... is resolved inside bringup: the reader itself opens only regular files."""
    pkg = tmp_path / "src" / "one_robot"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "config").mkdir()
    (pkg / "package.xml").write_text("<package format='3'><name>one_robot</name></package>")
    (pkg / "urdf" / "one.urdf").write_text(_URDF)
    fifo = _fifo(pkg / "config" / "controllers.yaml")
    before = tree(tmp_path / "src")
    code = no_hang(main, ["bringup", "package://one_robot/urdf/one.urdf", "--controllers",
                          "package://one_robot/config/controllers.yaml", "--package-path", str(tmp_path / "src")],
                   release=lambda: _release(fifo))
    assert code == 2 and "not a regular file" in _one_line(capsys)
    assert tree(tmp_path / "src") == before


def test_a_xacro_include_of_a_fifo_is_refused_not_a_hang(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fifo = _fifo(tmp_path / "part.xacro")
    (tmp_path / "robot.urdf.xacro").write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="part.xacro"/></robot>')
    code = no_hang(main, ["bringup", str(tmp_path / "robot.urdf.xacro")], release=lambda: _release(fifo))
    assert code == 2 and "not a regular file" in _one_line(capsys)


@pytest.mark.parametrize("seconds", ["1e6", str(BRINGUP_MAX_SECONDS + 1), "inf", "nan", "-1"])
def test_seconds_beyond_the_limit_are_refused_with_one_line_before_anything_runs(
        seconds: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bringup", XACRO, "--controllers", YAML, "--seconds", seconds]) == 2
    line = _one_line(capsys)
    assert "--seconds" in line and capsys.readouterr().out == ""


def test_the_limit_is_stated_in_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bringup", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"at most {BRINGUP_MAX_SECONDS:g}" in text and f"{BRINGUP_MAX_CYCLES:,} control cycles" in text


def test_an_update_rate_that_would_run_too_many_cycles_is_refused_before_spinning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "robot.urdf").write_text(_URDF)
    (tmp_path / "fast.yaml").write_text("controller_manager:\n  ros__parameters:\n    update_rate: 1000000\n")
    code = no_hang(main, ["bringup", str(tmp_path / "robot.urdf"), "--controllers", str(tmp_path / "fast.yaml"),
                          "--seconds", "60"])
    assert code == 2
    line = _one_line(capsys)
    assert "control cycles" in line and f"{BRINGUP_MAX_CYCLES:,}" in line


def test_seconds_within_the_limit_still_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "robot.urdf").write_text(_URDF)
    assert main(["bringup", str(tmp_path / "robot.urdf"), "--seconds", "2.5"]) == 0
    assert "at t = 2.500 s" in capsys.readouterr().out
