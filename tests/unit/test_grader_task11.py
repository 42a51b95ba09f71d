"""The task-11 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
XACRO = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
YAML = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"


def _failed_with(tmp_path: Path, file: str, old: str, new: str) -> set[str]:
    source = tracks.task_dir(11, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times to {path}"
    path.write_text(text.replace(old, new))
    return {c.name for c in grade(11, task_root=tmp_path).checks if not c.passed}


def test_spacing_written_as_a_number(tmp_path: Path) -> None:
    assert _failed_with(tmp_path, XACRO, '<origin xyz="0 ${$(arg spacing) / 2} 0" rpy="0 0 0"/>',
                        '<origin xyz="0 0.75 0" rpy="0 0 0"/>') == {"side_by_side"}


def test_both_robots_on_the_same_side(tmp_path: Path) -> None:
    assert _failed_with(tmp_path, XACRO, '<origin xyz="0 ${-$(arg spacing) / 2} 0" rpy="0 0 0"/>',
                        '<origin xyz="0 ${$(arg spacing)} 0" rpy="0 0 0"/>') == {"side_by_side"}


def test_second_component_copied_with_the_first_prefix(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, XACRO, 'name="rrbot" prefix="$(arg prefix_2)"', 'name="rrbot" prefix="$(arg prefix_1)"')
    assert {"two_prefixed_robots", "independent_control", "one_robot_stops_alone"} <= failed


def test_second_forward_controller_on_the_first_robot(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, YAML, "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r2_joint1, r2_joint2]",
                          "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r1_joint1, r1_joint2]")
    assert {"controllers_yaml", "one_robot_stops_alone"} <= failed


def test_unprefixed_controller_names(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, YAML, "    r1_joint_trajectory_controller:\n      type:",
                          "    joint_trajectory_controller:\n      type:")
    assert "controllers_yaml" in failed
