"""The task-2 grader fails wrong solutions: each mutation of the solution fails exactly the checks it should.

Full marks on solutions/ and less on the untouched exercises are checked for every grader in test_graders.py.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

CONTROLLERS = "rrbot_bringup/config/rrbot_controllers.yaml"
ROS2_CONTROL = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
BRINGUP = "rrbot_bringup/bringup.py"


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


def _mutated(tmp_path: Path, file: str, *substitutions: tuple[str, str]) -> Path:
    """A copy of the task-2 solution with regex substitutions in one file, each applying once; the task root."""
    source = tracks.task_dir(2, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    for pattern, replacement in substitutions:
        text, count = re.subn(pattern, replacement, text, flags=re.DOTALL)
        assert count == 1, f"mutation {pattern!r} did not apply to {path}"
    path.write_text(text)
    return tmp_path


def test_yaml_without_the_trajectory_controller_fails_its_checks(tmp_path: Path) -> None:
    """No joint_trajectory_controller: its YAML checks fail, and the bringup (which loads it) cannot start."""
    root = _mutated(
        tmp_path, CONTROLLERS,
        (r"\n    # Interpolates trajectories.*?JointTrajectoryController\n", "\n"),
        (r"\njoint_trajectory_controller:\n.*", "\n"),
    )
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {
        "controller_types", "joint_trajectory_controller_interfaces", "joint_trajectory_controller_constraints",
        "start_rrbot_activates_controllers", "other_controller_loaded_inactive",
        "start_rrbot_passes_mock_sensor_commands", "forward_command_reaches_the_joints",
        "joint_trajectory_controller_reaches_the_goals",
    }, rubric.format()


def test_state_publish_rate_fails_only_the_jazzy_check(tmp_path: Path) -> None:
    root = _mutated(
        tmp_path, CONTROLLERS,
        (r"    action_monitor_rate: 20\.0", "    state_publish_rate: 50.0\n    action_monitor_rate: 20.0"),
    )
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {"parameters_valid_in_jazzy"}, rubric.format()


def test_hard_coded_mock_sensor_commands_fails_the_sensor_checks(tmp_path: Path) -> None:
    root = _mutated(
        tmp_path, ROS2_CONTROL,
        (r'<param name="mock_sensor_commands">\$\{mock_sensor_commands\}</param>',
         '<param name="mock_sensor_commands">false</param>'),
    )
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {
        "mock_sensor_commands_reaches_the_mock", "start_rrbot_passes_mock_sensor_commands",
    }, rubric.format()


def test_mock_without_a_real_hardware_branch_fails_the_switch_check(tmp_path: Path) -> None:
    root = _mutated(
        tmp_path, ROS2_CONTROL,
        (r"<plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>",
         "<plugin>mock_components/GenericSystem</plugin>"),
    )
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {"use_mock_hardware_switch"}, rubric.format()


def test_bringup_without_the_inactive_controller_fails_only_that_check(tmp_path: Path) -> None:
    root = _mutated(
        tmp_path, BRINGUP, (r"        cm\.load_controller\(other\)\n        cm\.configure_controller\(other\)\n", "")
    )
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {"other_controller_loaded_inactive"}, rubric.format()


def test_forward_controller_on_velocity_fails_its_checks(tmp_path: Path) -> None:
    """interface_name velocity: RRBot has no velocity command interface, so the controller cannot be activated."""
    root = _mutated(tmp_path, CONTROLLERS, (r"interface_name: position", "interface_name: velocity"))
    rubric = grade(2, task_root=root)
    assert _failed(rubric) == {
        "forward_position_controller_parameters", "start_rrbot_activates_controllers",
        "other_controller_loaded_inactive", "start_rrbot_passes_mock_sensor_commands",
        "forward_command_reaches_the_joints",
    }, rubric.format()


def test_bringup_ignoring_robot_controller_fails_the_choice_check(tmp_path: Path) -> None:
    """start_rrbot always activates the forward controller, whatever robot_controller says."""
    root = _mutated(tmp_path, BRINGUP, (r"cm\.load_controller\(robot_controller\)\n(\s*)cm\.configure_controller\(robot_controller\)"
                                        r"\n(\s*)cm\.switch_controllers\(activate=\[robot_controller\]",
                                        "cm.load_controller('forward_position_controller')\\n\\1cm.configure_controller("
                                        "'forward_position_controller')\\n\\2cm.switch_controllers(activate=['forward_position_controller']"))
    failed = _failed(grade(2, task_root=root))
    assert "other_controller_loaded_inactive" in failed and "start_rrbot_activates_controllers" not in failed


def test_update_rate_of_10_hz_fails_the_rate_check(tmp_path: Path) -> None:
    root = _mutated(tmp_path, CONTROLLERS, (r"update_rate: 100", "update_rate: 10"))
    assert "update_rate" in _failed(grade(2, task_root=root))


def test_trajectory_controller_writing_velocity_too_fails_its_interface_check(tmp_path: Path) -> None:
    """The mock also has velocity command interfaces; the task's trajectory controller commands positions only."""
    root = _mutated(tmp_path, CONTROLLERS, (r"command_interfaces:  # what it writes\n      - position",
                                            "command_interfaces:  # what it writes\n      - position\n      - velocity"))
    assert "joint_trajectory_controller_interfaces" in _failed(grade(2, task_root=root))


def test_partial_goals_allowed_fails_the_constraints_check(tmp_path: Path) -> None:
    root = _mutated(tmp_path, CONTROLLERS, (r"allow_partial_joints_goal: false", "allow_partial_joints_goal: true"))
    assert "joint_trajectory_controller_constraints" in _failed(grade(2, task_root=root))
