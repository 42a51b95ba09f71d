"""The task-11 grader: wrong solutions, written as learners would, lose points; correct ones written differently get
full marks. Each is a copy of ``solutions/`` with exact changes (see ``grader_variants``)."""

from __future__ import annotations

import pytest
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
XACRO = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
YAML = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"
ROBOT_1 = '<origin xyz="0 ${$(arg spacing) / 2} 0" rpy="0 0 0"/>'
ROBOT_2 = '<origin xyz="0 ${-$(arg spacing) / 2} 0" rpy="0 0 0"/>'
TAG_2 = '<xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix_2)" use_mock_hardware="$(arg use_mock_hardware)"/>'
TAG_1 = '<xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix_1)" use_mock_hardware="$(arg use_mock_hardware)"/>'


def _section(prefix: str, kind: str) -> str:
    return f"{prefix}{kind}:\n  ros__parameters:\n    joints: [{prefix}joint1, {prefix}joint2]\n"


WRONG = [
    Variant("spacing_written_as_a_number", {XACRO: [(ROBOT_1, '<origin xyz="0 0.75 0" rpy="0 0 0"/>')]},
            fails={"side_by_side", "description_matches_the_task_for_any_arguments"}),
    Variant("both_robots_on_the_same_side", {XACRO: [(ROBOT_2, '<origin xyz="0 ${$(arg spacing)} 0" rpy="0 0 0"/>')]},
            fails={"side_by_side", "description_matches_the_task_for_any_arguments"}),
    Variant("robots_on_swapped_sides", {XACRO: [(ROBOT_1, "ONE"), (ROBOT_2, ROBOT_1), ("ONE", ROBOT_2)]},
            fails={"side_by_side", "description_matches_the_task_for_any_arguments"}),
    Variant("whole_spacing_on_each_side", {XACRO: [(ROBOT_1, '<origin xyz="0 $(arg spacing) 0" rpy="0 0 0"/>'),
                                                  (ROBOT_2, '<origin xyz="0 -$(arg spacing) 0" rpy="0 0 0"/>')]},
            fails={"side_by_side"}),
    Variant("robot_2_stands_on_robot_1", {XACRO: [
        ('<xacro:rrbot prefix="$(arg prefix_2)" parent="world">\n    ' + ROBOT_2,
         '<xacro:rrbot prefix="$(arg prefix_2)" parent="$(arg prefix_1)base_link">\n'
         '    <origin xyz="0 ${-$(arg spacing)} 0" rpy="0 0 0"/>')]},
            fails={"side_by_side", "description_matches_the_task_for_any_arguments"}),
    Variant("second_component_with_the_first_prefix", {XACRO: [(TAG_2, TAG_1.replace('name="rrbot"', 'name="rrbot2"'))]},
            fails={"two_prefixed_robots", "independent_control", "one_robot_stops_alone"}),
    Variant("use_mock_hardware_left_to_the_macro_default", {XACRO: [(TAG_2, TAG_2.replace(
        ' use_mock_hardware="$(arg use_mock_hardware)"', ""))]},
            fails={"use_mock_hardware_reaches_both_robots", "description_matches_the_task_for_any_arguments"}),
    Variant("use_mock_hardware_written_as_true", {XACRO: [
        (TAG_1, TAG_1.replace("$(arg use_mock_hardware)", "true")),
        (TAG_2, TAG_2.replace("$(arg use_mock_hardware)", "true"))]},
            fails={"use_mock_hardware_reaches_both_robots"}),
    Variant("robot_2_prefix_written_out", {XACRO: [
        ('<xacro:rrbot prefix="$(arg prefix_2)"', '<xacro:rrbot prefix="r2_"'), (TAG_2, TAG_2.replace("$(arg prefix_2)", "r2_"))]},
            fails={"two_prefixed_robots", "same_prefix_twice_is_a_clear_error",
                   "description_matches_the_task_for_any_arguments"}),
    Variant("robot_1_prefix_written_out_example_name", {XACRO: [
        ('<xacro:rrbot prefix="$(arg prefix_1)"', '<xacro:rrbot prefix="r1_"'), (TAG_1, TAG_1.replace("$(arg prefix_1)", "r1_"))]},
            fails={"two_prefixed_robots", "description_matches_the_task_for_any_arguments"}),
    Variant("second_forward_controller_on_the_first_robot", {YAML: [
        (_section("r2_", "forward_position_controller"),
         "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r1_joint1, r1_joint2]\n")]},
            fails={"controllers_yaml", "one_robot_stops_alone"}),
    Variant("unprefixed_trajectory_controller_name", {YAML: [
        ("    r1_joint_trajectory_controller:\n      type:", "    joint_trajectory_controller:\n      type:"),
        ("\nr1_joint_trajectory_controller:\n", "\njoint_trajectory_controller:\n")]},
            fails={"controllers_yaml", "independent_control"}),
    Variant("robot_1_trajectory_on_robot_2_joints", {YAML: [
        (_section("r1_", "joint_trajectory_controller"),
         "r1_joint_trajectory_controller:\n  ros__parameters:\n    joints: [r2_joint1, r2_joint2]\n")]},
            fails={"controllers_yaml", "independent_control"}),
    Variant("robot_1_trajectory_commands_velocity", {YAML: [
        (_section("r1_", "joint_trajectory_controller") + "    command_interfaces: [position]",
         _section("r1_", "joint_trajectory_controller") + "    command_interfaces: [velocity]\n    gains:\n"
         "      r1_joint1: {p: 5.0}\n      r1_joint2: {p: 5.0}")]},
            fails={"controllers_yaml"}),
    Variant("robot_2_forward_controller_on_velocity", {YAML: [
        (_section("r2_", "forward_position_controller") + "    interface_name: position",
         _section("r2_", "forward_position_controller") + "    interface_name: velocity")]},
            fails={"controllers_yaml", "one_robot_stops_alone"}),
    Variant("one_broadcaster_per_robot", {YAML: [
        ("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n",
         "    r1_joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n"
         "    r2_joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n")]},
            fails={"controllers_yaml", "independent_control", "one_robot_stops_alone"}),
]

RIGHT_XACRO_PROPERTIES = """<?xml version="1.0"?>
<robot name="two_rrbots" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="use_mock_hardware" default="true"/>
  <xacro:arg name="spacing" default="1.5"/>
  <xacro:arg name="prefix_2" default="r2_"/>
  <xacro:arg name="prefix_1" default="r1_"/>

  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>

  <xacro:property name="half_spacing" value="${0.5 * $(arg spacing)}"/>

  <link name="world"/>

  <xacro:rrbot_ros2_control name="RRBot" prefix="$(arg prefix_2)" use_mock_hardware="$(arg use_mock_hardware)"/>
  <xacro:rrbot_ros2_control name="RRBot" prefix="$(arg prefix_1)" use_mock_hardware="$(arg use_mock_hardware)"/>

  <xacro:rrbot prefix="$(arg prefix_2)" parent="world">
    <origin xyz="0.0 ${-half_spacing} 0.0" rpy="0 0 0"/>
  </xacro:rrbot>
  <xacro:rrbot prefix="$(arg prefix_1)" parent="world">
    <origin xyz="0.0 ${half_spacing} 0.0" rpy="0 0 0"/>
  </xacro:rrbot>
</robot>
"""

RIGHT_XACRO_OWN_MACRO = """<?xml version="1.0"?>
<robot name="multi_rrbot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix_1" default="r1_"/>
  <xacro:arg name="prefix_2" default="r2_"/>
  <xacro:arg name="spacing" default="1.5"/>
  <xacro:arg name="use_mock_hardware" default="true"/>
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>

  <!-- One robot with its hardware, at y on the world. -->
  <xacro:macro name="placed_rrbot" params="prefix side mock">
    <xacro:rrbot prefix="${prefix}" parent="world">
      <origin xyz="0 ${side * float('$(arg spacing)') / 2.0} 0" rpy="0 0 0"/>
    </xacro:rrbot>
    <xacro:rrbot_ros2_control name="arm" prefix="${prefix}" use_mock_hardware="${mock}"/>
  </xacro:macro>

  <link name="world"/>
  <xacro:placed_rrbot prefix="$(arg prefix_1)" side="1" mock="$(arg use_mock_hardware)"/>
  <xacro:placed_rrbot prefix="$(arg prefix_2)" side="-1" mock="$(arg use_mock_hardware)"/>
</robot>
"""

RIGHT_YAML_FLOW = """controller_manager:
  ros__parameters:
    update_rate: 100
    r2_joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    r1_joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    r2_forward_position_controller: {type: forward_command_controller/ForwardCommandController}
    r1_forward_position_controller: {type: forward_command_controller/ForwardCommandController}

r2_joint_trajectory_controller:
  ros__parameters: {joints: [r2_joint1, r2_joint2], command_interfaces: [position],
                    state_interfaces: [position, velocity], allow_partial_joints_goal: false,
                    constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}}
r1_joint_trajectory_controller:
  ros__parameters: {joints: [r1_joint1, r1_joint2], command_interfaces: [position],
                    state_interfaces: [position, velocity], allow_partial_joints_goal: false,
                    constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}}
r2_forward_position_controller:
  ros__parameters: {joints: [r2_joint1, r2_joint2], interface_name: position}
r1_forward_position_controller:
  ros__parameters: {joints: [r1_joint1, r1_joint2], interface_name: position}
"""

RIGHT = [
    Variant("properties_other_order_other_component_name", {XACRO: RIGHT_XACRO_PROPERTIES}),
    Variant("own_macro_placing_each_robot", {XACRO: RIGHT_XACRO_OWN_MACRO}),
    Variant("flow_yaml_other_order", {YAML: RIGHT_YAML_FLOW}),
    Variant("robot_2_turned_to_face_robot_1", {XACRO: [(ROBOT_2, '<origin xyz="0 ${-$(arg spacing) / 2} 0" rpy="0 0 ${pi}"/>')]}),
    Variant("task2_extras_and_block_lists", {YAML: [
        (_section("r1_", "joint_trajectory_controller") + "    command_interfaces: [position]",
         "r1_joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - r1_joint1\n      - r1_joint2\n"
         "    action_monitor_rate: 20.0\n    command_interfaces:\n      - position"),
        (_section("r2_", "forward_position_controller"),
         "r2_forward_position_controller:\n  ros__parameters:\n    joints:\n      - r2_joint1\n      - r2_joint2\n")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(11, WRONG + RIGHT, tmp_path_factory.mktemp("task11"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])
