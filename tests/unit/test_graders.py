"""Every grader in tests/tasks/ gives full marks to solutions/, and can fail: untouched exercises and wrong answers.

Each grading runs in a subprocess, as a learner's would. A grader added as tests/tasks/test_taskNN_*.py is picked
up here without any registration.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade, graded_tasks

GRADED = graded_tasks()
HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
needs_solutions = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


def _report(rubric: Rubric) -> str:
    return rubric.format()


@needs_solutions
@pytest.mark.parametrize("task", GRADED)
def test_solution_gets_full_marks(task: int) -> None:
    rubric = grade(task, track="solutions")
    assert rubric.max_score > 0
    assert rubric.score == rubric.max_score, _report(rubric)


@pytest.mark.parametrize("task", GRADED)
def test_untouched_exercise_does_not_get_full_marks(task: int) -> None:
    rubric = grade(task, track="exercises")
    assert rubric.score == 0 < rubric.max_score, _report(rubric)  # free checks are marked given, not scored


# ------------------------------------------------------------------------------------------- task 1 mutations


def _mutated_task01(tmp_path: Path, file: str, pattern: str, replacement: str) -> Path:
    """A copy of the task-1 solution with one regex substitution in one file; returns the task root."""
    source = tracks.task_dir(1, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy)
    path = copy / "rrbot_description" / "urdf" / file
    text, count = re.subn(pattern, replacement, path.read_text(), flags=re.DOTALL)
    assert count == 1, f"mutation {pattern!r} did not apply to {path}"
    path.write_text(text)
    return tmp_path


@needs_solutions
def test_task01_link1_of_0_4_m_fails_the_kinematics_checks(tmp_path: Path) -> None:
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'<xacro:property name="link1_length" value="0.5" />', '<xacro:property name="link1_length" value="0.4" />',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"link1_shape", "joint2_placement", "tool0_at_tip"}, _report(rubric)


@needs_solutions
def test_task01_missing_gpio_output_fails_the_gpio_output_checks(tmp_path: Path) -> None:
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.ros2_control.xacro",
        r'\s*<command_interface name="digital_out_2" />\s*<state_interface name="digital_out_2" />', "",
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"gpio_outputs", "gpio_output_readback"}, _report(rubric)


@needs_solutions
def test_task01_unprefixed_frame_id_fails_only_the_prefix_check(tmp_path: Path) -> None:
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.ros2_control.xacro",
        r'<param name="frame_id">\$\{prefix\}tool0</param>', '<param name="frame_id">tool0</param>',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"prefix"}, _report(rubric)


@needs_solutions
def test_task01_joint2_limits_in_degrees_fail_the_limit_check(tmp_path: Path) -> None:
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'lower="\$\{radians\(-60\)\}" upper="\$\{radians\(240\)\}"', 'lower="-60" upper="240"',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"joint2_limits"}, _report(rubric)


@needs_solutions
def test_task01_unprefixed_ros2_control_name_fails_only_the_prefix_check(tmp_path: Path) -> None:
    """The original workshop's tag name: 'rrbot' whatever the prefix, so two robots collide."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.ros2_control.xacro",
        r'<ros2_control name="\$\{prefix\}\$\{name\}"', '<ros2_control name="${name}"',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"prefix"}, _report(rubric)


@needs_solutions
def test_task01_unprefixed_sensor_and_gpio_names_fail_only_the_prefix_check(tmp_path: Path) -> None:
    """The original workshop's sensor and GPIO names: no prefix, so two robots export the same interfaces."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.ros2_control.xacro",
        r'<sensor name="\$\{prefix\}tcp_fts_sensor">(.*)<gpio name="\$\{prefix\}flange_gpios">',
        r'<sensor name="tcp_fts_sensor">\1<gpio name="flange_gpios">',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"prefix"}, _report(rubric)


@needs_solutions
def test_task01_tool0_without_the_original_rotation_fails_only_the_orientation_check(tmp_path: Path) -> None:
    """tool0 in the same place but not turned (rpy 0 0 0): the positions pass, the orientation does not."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'rpy="0 \$\{-pi\} \$\{-pi / 2\}"', 'rpy="0 0 0"',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"tool0_orientation"}, _report(rubric)


@needs_solutions
def test_task01_missing_flange_frame_fails_the_frame_checks(tmp_path: Path) -> None:
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'\s*<joint name="\$\{prefix\}tool0-flange_joint".*?<link name="\$\{prefix\}flange" />', "",
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"links_and_joints", "tool0_orientation"}, _report(rubric)


@needs_solutions
def test_task01_link2_box_lying_along_x_fails_the_link2_shape_check(tmp_path: Path) -> None:
    """The right sizes in the wrong order: the box lies across the link instead of along it."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'(<visual>\s*<origin xyz="0 0 \$\{link2_length / 2\}" rpy="0 0 0" />\s*<geometry>\s*)'
        r'<box size="\$\{link2_width\} \$\{link2_width\} \$\{link2_length\}" />',
        r'\1<box size="${link2_length} ${link2_width} ${link2_width}" />',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"link2_shape"}, _report(rubric)


@needs_solutions
def test_task01_link2_box_centred_on_joint2_fails_the_link2_shape_check(tmp_path: Path) -> None:
    """A box of the right size centred on the joint instead of reaching from the joint to the tip."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'(<link name="\$\{prefix\}link2">\s*<visual>\s*)<origin xyz="0 0 \$\{link2_length / 2\}" rpy="0 0 0" />',
        r'\1<origin xyz="0 0 0" rpy="0 0 0" />',
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"link2_shape"}, _report(rubric)


@needs_solutions
def test_task01_link1_without_collision_fails_the_link1_shape_check(tmp_path: Path) -> None:
    """A link you can see but not touch: the collision element was left out."""
    root = _mutated_task01(
        tmp_path, "rrbot/rrbot_macro.xacro",
        r'(<link name="\$\{prefix\}link1">.*?</visual>)\s*<collision>.*?</collision>', r"\1",
    )
    rubric = grade(1, task_root=root)
    assert _failed(rubric) == {"link1_shape"}, _report(rubric)
