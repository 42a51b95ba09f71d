"""The task-5 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
MACRO = "rrbot_description/urdf/rrbot/rrbot_macro.xacro"
CONTROL = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
TOP = "rrbot_description/urdf/rrbot.urdf.xacro"
BRINGUP = "rrbot_bringup/bringup.py"


def _failed_with(tmp_path: Path, file: str, *changes: tuple[str, str]) -> set[str]:
    source = tracks.task_dir(5, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    for old, new in changes:
        assert text.count(old) >= 1, f"mutation {old!r} does not apply"
        text = text.replace(old, new)
    path.write_text(text)
    return {c.name for c in grade(5, task_root=tmp_path).checks if not c.passed}


def test_motors_too_weak_to_hold_the_arm(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, MACRO, ('effort="1000.0"', 'effort="1.0"'))
    assert "goals_reached_in_physics" in failed and "plugin_switch" not in failed


def test_mock_wins_over_the_simulator(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, CONTROL, ('<xacro:if value="${sim_mujoco}">', '<xacro:if value="${sim_mujoco and not use_mock_hardware}">'),
                          ('<xacro:unless value="${sim_mujoco}">', '<xacro:unless value="${sim_mujoco and not use_mock_hardware}">'))
    assert failed == {"plugin_switch"}


def test_argument_not_passed_to_the_macro(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, TOP, ('    sim_mujoco="$(arg sim_mujoco)"\n', ""))
    assert {"plugin_switch", "bringup", "goals_reached_in_physics"} <= failed


def test_bringup_on_the_mock(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, ('xacro_args={"sim_mujoco": True}', 'xacro_args={"use_mock_hardware": True}'))
    assert failed == {"bringup"}


def test_robot_controller_before_the_broadcaster(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, ('spawn=["joint_state_broadcaster"])', "spawn=[])"),
                          ('        other = next(', '        cm.load_controller("joint_state_broadcaster")\n'
                           '        cm.configure_controller("joint_state_broadcaster")\n'
                           '        cm.switch_controllers(activate=["joint_state_broadcaster"], strictness="strict")\n'
                           '        other = next('))
    assert failed == {"bringup"}


def test_other_controller_not_loaded(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, ("        cm.load_controller(other)\n        cm.configure_controller(other)\n",
                                              ""))
    assert failed == {"bringup"}
