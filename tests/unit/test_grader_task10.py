"""The task-10 grader: wrong solutions, written as learners would, lose points; correct ones written differently get
full marks. Each is a copy of ``solutions/`` with exact changes (see ``grader_variants``)."""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants, reason_problems

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
XACRO = "rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro"
YAML = "rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml"
ANSWERS = "answers.py"
BASE_TAG = ('  <xacro:diffbot_ros2_control name="DiffBot" prefix="$(arg base_prefix)" '
            'use_mock_hardware="$(arg use_mock_hardware)"/>\n')
ARM_TAG = ('  <xacro:rrbot_ros2_control name="RRBot" prefix="$(arg arm_prefix)" '
           'use_mock_hardware="$(arg use_mock_hardware)"/>\n')
RUNNING = {"base_and_arm_move_together", "base_and_arm_are_independent"}
MANAGER_TYPES = ("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n\n"
                 "    diffbot_base_controller:\n      type: diff_drive_controller/DiffDriveController\n\n"
                 "    joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n")
BASE_SECTION = "diffbot_base_controller:\n  ros__parameters:\n"
ARM_SECTION = "joint_trajectory_controller:\n  ros__parameters:\n"

WRONG = [
    Variant("arm_on_the_base_link", {XACRO: [('parent="$(arg base_prefix)top_plate"', 'parent="$(arg base_prefix)base_link"')]},
            fails={"both_robots_in_one_tree", "description_matches_the_task_for_any_arguments"}),
    Variant("arm_at_the_plate_centre", {XACRO: [('<origin xyz="0.1 0 0" rpy="0 0 0"/>', '<origin xyz="0 0 0" rpy="0 0 0"/>')]},
            fails={"both_robots_in_one_tree", "description_matches_the_task_for_any_arguments"}),
    Variant("arm_towards_the_back", {XACRO: [('<origin xyz="0.1 0 0" rpy="0 0 0"/>', '<origin xyz="-0.1 0 0" rpy="0 0 0"/>')]},
            fails={"both_robots_in_one_tree"}),
    Variant("arm_parent_written_out", {XACRO: [('parent="$(arg base_prefix)top_plate"', 'parent="base_top_plate"')]},
            fails={"both_robots_in_one_tree", "prefix_arguments_rename_everything"}),
    Variant("base_prefix_written_out", {XACRO: [('<xacro:diffbot prefix="$(arg base_prefix)"/>', '<xacro:diffbot prefix="base_"/>')]},
            fails={"prefix_arguments_rename_everything", "description_matches_the_task_for_any_arguments"}),
    Variant("arm_component_with_the_base_prefix", {XACRO: [(ARM_TAG, ARM_TAG.replace("$(arg arm_prefix)", "$(arg base_prefix)"))]},
            fails={"prefix_arguments_rename_everything", "two_hardware_components"}),
    Variant("one_ros2_control_tag_for_both_robots", {XACRO: [(BASE_TAG, "")]},
            fails={"two_hardware_components", "use_mock_hardware_reaches_both_components"},
            says={"two_hardware_components": "1 hardware components"}),
    Variant("use_mock_hardware_left_to_the_macro_default", {XACRO: [(ARM_TAG, ARM_TAG.replace(
        ' use_mock_hardware="$(arg use_mock_hardware)"', ""))]},
            fails={"use_mock_hardware_reaches_both_components", "description_matches_the_task_for_any_arguments"}),
    Variant("use_mock_hardware_written_as_true", {XACRO: [
        (ARM_TAG, ARM_TAG.replace("$(arg use_mock_hardware)", "true")),
        (BASE_TAG, BASE_TAG.replace("$(arg use_mock_hardware)", "true"))]},
            fails={"use_mock_hardware_reaches_both_components"}),
    Variant("world_link_added_as_root", {XACRO: [('  <xacro:diffbot prefix="$(arg base_prefix)"/>\n',
        '  <link name="world"/>\n  <joint name="world_joint" type="fixed">\n    <parent link="world"/>\n'
        '    <child link="$(arg base_prefix)base_link"/>\n  </joint>\n  <xacro:diffbot prefix="$(arg base_prefix)"/>\n')]},
            fails={"both_robots_in_one_tree", "description_matches_the_task_for_any_arguments"}),
    Variant("wrong_wheel_separation", {YAML: [("wheel_separation: 0.55", "wheel_separation: 0.5")]},
            fails={"controllers_yaml"}, only=True),
    Variant("wheel_diameter_for_radius", {YAML: [("wheel_radius: 0.1 ", "wheel_radius: 0.2 ")]},
            fails={"controllers_yaml"}, only=True),
    Variant("arm_controller_on_unprefixed_joints", {YAML: [("joints: [arm_joint1, arm_joint2]", "joints: [joint1, joint2]")]},
            fails={"controllers_yaml"}, only=True),
    Variant("base_controller_on_unprefixed_wheels", {YAML: [
        ("left_wheel_names: [base_left_wheel_joint]", "left_wheel_names: [left_wheel_joint]"),
        ("right_wheel_names: [base_right_wheel_joint]", "right_wheel_names: [right_wheel_joint]")]},
            fails={"controllers_yaml"}, only=True),
    Variant("arm_controller_commands_velocity", {YAML: [("    command_interfaces: [position]",
                                                         "    command_interfaces: [velocity]")]},
            fails={"controllers_yaml"}, only=True),
    Variant("wheels_swapped", {YAML: [
        ("left_wheel_names: [base_left_wheel_joint]", "left_wheel_names: [base_right_wheel_joint]"),
        ("right_wheel_names: [base_right_wheel_joint]", "right_wheel_names: [base_left_wheel_joint]")]},
            fails={"controllers_yaml"}, only=True),
    Variant("one_component_counted", {ANSWERS: [("HARDWARE_COMPONENTS = 2", "HARDWARE_COMPONENTS = 1")]},
            fails={"answer_hardware_components"}, only=True),
    Variant("two_plugins_per_tag", {ANSWERS: [("PLUGINS_PER_ROS2_CONTROL_TAG = 1", "PLUGINS_PER_ROS2_CONTROL_TAG = 2")]},
            fails={"answer_plugins_per_tag"}, only=True),
    Variant("a_controller_manager_per_robot", {ANSWERS: [("CONTROLLER_MANAGERS = 1", "CONTROLLER_MANAGERS = 2")]},
            fails={"answer_controller_managers"}, only=True),
    Variant("base_type_only_in_its_section_misspelt", {YAML: [
        ("    diffbot_base_controller:\n      type: diff_drive_controller/DiffDriveController\n", ""),
        (BASE_SECTION, BASE_SECTION + "    type: diff_drive_controller/DiffDrive\n")]},
            fails={"controllers_yaml"}, only=True, says={"controllers_yaml": "diff_drive_controller/DiffDrive'"}),
    Variant("arm_type_left_out", {YAML: [
        ("    joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n", "")]},
            fails={"controllers_yaml"}, only=True, says={"controllers_yaml": "no type"}),
    Variant("description_and_yaml_both_wrong", {XACRO: [(BASE_TAG, "")],
                                                YAML: [("wheel_separation: 0.55", "wheel_separation: 0.5")]},
            fails={"two_hardware_components", "controllers_yaml"} | RUNNING,
            says={"base_and_arm_move_together": "fails because"}),
    Variant("answer_as_a_string", {ANSWERS: [("HARDWARE_COMPONENTS = 2", 'HARDWARE_COMPONENTS = "2"')]},
            fails={"answer_hardware_components"}, only=True),
]

RIGHT_XACRO = """<?xml version="1.0"?>
<robot name="mobile_manipulator" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="use_mock_hardware" default="true"/>
  <xacro:arg name="arm_prefix" default="arm_"/>
  <xacro:arg name="base_prefix" default="base_"/>

  <xacro:include filename="$(find diffbot)/urdf/diffbot/diffbot_macro.xacro"/>
  <xacro:include filename="$(find diffbot)/urdf/diffbot/diffbot_macro.ros2_control.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>

  <xacro:property name="mount_x" value="${0.2 / 2}"/>
  <xacro:property name="mock" value="$(arg use_mock_hardware)"/>

  <xacro:rrbot_ros2_control name="arm" prefix="$(arg arm_prefix)" use_mock_hardware="${mock}"/>
  <xacro:diffbot_ros2_control name="base" prefix="$(arg base_prefix)" use_mock_hardware="${mock}"/>

  <xacro:rrbot prefix="$(arg arm_prefix)" parent="$(arg base_prefix)top_plate">
    <origin xyz="${mount_x} 0.0 0.0" rpy="0.0 0.0 0.0"/>
  </xacro:rrbot>
  <xacro:diffbot prefix="$(arg base_prefix)"/>
</robot>
"""

RIGHT_YAML = """controller_manager:
  ros__parameters:
    update_rate: 100
    joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    diffbot_base_controller: {type: diff_drive_controller/DiffDriveController}
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}

joint_trajectory_controller:
  ros__parameters:
    joints: [arm_joint1, arm_joint2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]

diffbot_base_controller:
  ros__parameters:
    left_wheel_names: [base_left_wheel_joint]
    right_wheel_names: [base_right_wheel_joint]
    wheel_separation: 0.550
    wheel_radius: 1.0e-1
    base_frame_id: base_base_link
"""

RIGHT_FLOW_YAML = """controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster}}
diffbot_base_controller: {ros__parameters: {type: diff_drive_controller/DiffDriveController,
  left_wheel_names: [base_left_wheel_joint], right_wheel_names: [base_right_wheel_joint],
  wheel_separation: 0.55, wheel_radius: 0.1, base_frame_id: base_base_link}}
joint_trajectory_controller: {ros__parameters: {type: joint_trajectory_controller/JointTrajectoryController,
  joints: [arm_joint1, arm_joint2], command_interfaces: [position], state_interfaces: [position, velocity]}}
"""

RIGHT = [
    Variant("arm_joints_listed_in_another_order", {YAML: [("joints: [arm_joint1, arm_joint2]", "joints: [arm_joint2, arm_joint1]")]}),
    Variant("types_in_the_controllers_own_sections", {YAML: [
        (MANAGER_TYPES, ""),
        (BASE_SECTION, BASE_SECTION + "    type: diff_drive_controller/DiffDriveController\n"),
        (ARM_SECTION, ARM_SECTION + "    type: joint_trajectory_controller/JointTrajectoryController\n"),
        ("\n\n\ndiffbot_base_controller:", "\n\njoint_state_broadcaster:\n  ros__parameters:\n"
         "    type: joint_state_broadcaster/JointStateBroadcaster\n\ndiffbot_base_controller:")]}),
    Variant("types_in_own_sections_flow_style", {YAML: RIGHT_FLOW_YAML}),
    Variant("other_order_properties_other_component_names", {XACRO: RIGHT_XACRO}),
    Variant("flow_yaml_defaults_left_out", {YAML: RIGHT_YAML}),
    Variant("arm_turned_sideways", {XACRO: [('<origin xyz="0.1 0 0" rpy="0 0 0"/>', '<origin xyz="0.1 0 0" rpy="0 0 ${pi/2}"/>')]}),
    Variant("answers_computed", {ANSWERS: (
        '"""Task 10 answers."""\n\nTAGS = ["DiffBot", "RRBot"]\nHARDWARE_COMPONENTS = len(TAGS)\n'
        'PLUGINS_PER_ROS2_CONTROL_TAG = 1\nCONTROLLER_MANAGERS = int(1.0)\n')}),
    Variant("block_lists_and_explicit_constraints", {YAML: [
        ("    joints: [arm_joint1, arm_joint2]\n", "    joints:\n      - arm_joint1\n      - arm_joint2\n"),
        ("    state_interfaces: [position, velocity]\n", "    state_interfaces: [velocity, position]\n")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(10, WRONG + RIGHT, tmp_path_factory.mktemp("task10"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name != "description_and_yaml_both_wrong"], ids=str)
def test_one_slip_shows_hints_at_one_check(rubrics: dict, variant: Variant) -> None:
    """The checks a single slip fails build on one of them (graded(after=...)): only that one is a cause."""
    assert_one_cause(rubrics[variant.name], check_specs(10), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(10))


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_the_exercise_as_handed_out_gets_a_clear_reason() -> None:
    """Untouched, the task scores 0; a check failing on its own names the learner's file or answer, the others say
    which check they wait for, and only the first cause shows a hint."""
    rubric = grade(10, track="exercises", record=False)
    assert rubric.score == 0 < rubric.max_score, rubric.format()
    assert not reason_problems(rubric), rubric.format()
    for check in rubric.failed():
        assert check.reason.startswith(("your ", "the <ros2_control> tags of your ", "fails because")), rubric.format()
    assert [c.name for c in rubric.checks if c.hint] == ["both_robots_in_one_tree"], rubric.format()
