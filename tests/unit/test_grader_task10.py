"""The task-10 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
XACRO = "rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro"
YAML = "rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml"


def _failed_with(tmp_path: Path, file: str, old: str, new: str) -> set[str]:
    source = tracks.task_dir(10, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times to {path}"
    path.write_text(text.replace(old, new))
    return {c.name for c in grade(10, task_root=tmp_path).checks if not c.passed}


def test_arm_on_the_base_link_instead_of_the_top_plate(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, XACRO, 'parent="$(arg base_prefix)top_plate"', 'parent="$(arg base_prefix)base_link"')
    assert failed == {"both_robots_in_one_tree"}


def test_arm_at_the_plate_centre(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, XACRO, '<origin xyz="0.1 0 0" rpy="0 0 0"/>', '<origin xyz="0 0 0" rpy="0 0 0"/>')
    assert failed == {"both_robots_in_one_tree"}


def test_prefix_written_out_instead_of_the_argument(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, XACRO, '<xacro:diffbot prefix="$(arg base_prefix)"/>', '<xacro:diffbot prefix="base_"/>')
    assert "prefix_arguments_rename_everything" in failed


def test_one_ros2_control_tag_for_both_robots(tmp_path: Path) -> None:
    failed = _failed_with(
        tmp_path, XACRO,
        '  <xacro:diffbot_ros2_control name="DiffBot" prefix="$(arg base_prefix)" use_mock_hardware="$(arg use_mock_hardware)"/>\n',
        "")
    assert {"two_hardware_components", "base_and_arm_move_together", "base_and_arm_are_independent"} <= failed


def test_wrong_wheel_separation(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, YAML, "wheel_separation: 0.55", "wheel_separation: 0.5")
    assert failed == {"controllers_yaml"}


def test_arm_controller_on_unprefixed_joints(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, YAML, "joints: [arm_joint1, arm_joint2]", "joints: [joint1, joint2]")
    assert {"controllers_yaml", "base_and_arm_move_together"} <= failed


def test_one_component_counted(tmp_path: Path) -> None:
    assert _failed_with(tmp_path, "answers.py", "HARDWARE_COMPONENTS = 2", "HARDWARE_COMPONENTS = 1") == {"answers"}
