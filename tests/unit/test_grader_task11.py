"""The task-11 grader: wrong solutions, written as learners would, lose points; correct ones written differently get
full marks. Each is a copy of ``solutions/`` with exact changes (see ``grader_variants``).

Full marks on solutions/ and 0 on the untouched exercise are checked for every grader in test_graders.py.
"""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
XACRO = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
YAML = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"
ROBOT_1 = '<origin xyz="0 ${$(arg spacing) / 2} 0" rpy="0 0 0"/>'
ROBOT_2 = '<origin xyz="0 ${-$(arg spacing) / 2} 0" rpy="0 0 0"/>'
TAG_2 = '<xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix_2)" use_mock_hardware="$(arg use_mock_hardware)"/>'
TAG_1 = '<xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix_1)" use_mock_hardware="$(arg use_mock_hardware)"/>'
SUMMARY = "description_matches_the_task_for_any_arguments"


def _section(prefix: str, kind: str) -> str:
    return f"{prefix}{kind}:\n  ros__parameters:\n    joints: [{prefix}joint1, {prefix}joint2]\n"


def _declared(name: str, kind: str) -> str:
    return f"    {name}:\n      type: {kind}\n"


FCC = "forward_command_controller/ForwardCommandController"
JTC = "joint_trajectory_controller/JointTrajectoryController"
JSB = "joint_state_broadcaster/JointStateBroadcaster"

#: Every type moved from the controller manager into the controller's own section (Jazzy's spawner reads it there).
TYPES_IN_OWN_SECTIONS = [
    (_declared("joint_state_broadcaster", JSB) + "\n" + _declared("r1_forward_position_controller", FCC) + "\n"
     + _declared("r2_forward_position_controller", FCC) + "\n" + _declared("r1_joint_trajectory_controller", JTC) + "\n"
     + _declared("r2_joint_trajectory_controller", JTC), ""),
    ("\n\nr1_forward_position_controller:\n  ros__parameters:\n",
     "\njoint_state_broadcaster:\n  ros__parameters:\n    type: " + JSB + "\n\n"
     "r1_forward_position_controller:\n  ros__parameters:\n    type: " + FCC + "\n"),
    ("\nr2_forward_position_controller:\n  ros__parameters:\n",
     "\nr2_forward_position_controller:\n  ros__parameters:\n    type: " + FCC + "\n"),
    ("\nr1_joint_trajectory_controller:\n  ros__parameters:\n",
     "\nr1_joint_trajectory_controller:\n  ros__parameters:\n    type: " + JTC + "\n"),
    ("\nr2_joint_trajectory_controller:\n  ros__parameters:\n",
     "\nr2_joint_trajectory_controller:\n  ros__parameters:\n    type: " + JTC + "\n"),
]


def wrong(name: str, fails: set[str], changes: dict, says: dict[str, str] | None = None, names_file: str = "",
          only: bool = True) -> Variant:
    """A slip of one rule unless ``only`` is False: only the checks in ``fails`` lose points."""
    return Variant(name, changes, fails=fails, says=says or {}, names_file=names_file, only=only)


WRONG = [
    # --- the description: each rule with its own check
    wrong("spacing_written_as_a_number", {"side_by_side", SUMMARY}, {XACRO: [(ROBOT_1, '<origin xyz="0 0.75 0" rpy="0 0 0"/>')]},
          says={"side_by_side": "spacing:=3"}, names_file="multi_rrbot.urdf.xacro, line"),
    wrong("both_robots_on_the_same_side", {"side_by_side", SUMMARY},
          {XACRO: [(ROBOT_2, '<origin xyz="0 ${$(arg spacing)} 0" rpy="0 0 0"/>')]}, says={"side_by_side": "robot 2"}),
    wrong("robots_on_swapped_sides", {"side_by_side", SUMMARY}, {XACRO: [(ROBOT_1, "ONE"), (ROBOT_2, ROBOT_1), ("ONE", ROBOT_2)]},
          says={"side_by_side": "+y side"}),
    wrong("whole_spacing_on_each_side", {"side_by_side", SUMMARY},
          {XACRO: [(ROBOT_1, '<origin xyz="0 $(arg spacing) 0" rpy="0 0 0"/>'),
                   (ROBOT_2, '<origin xyz="0 -$(arg spacing) 0" rpy="0 0 0"/>')]}, says={"side_by_side": "spacing/2"}),
    wrong("spacing_halved_outside_the_expression", {"side_by_side", SUMMARY},
          {XACRO: [(ROBOT_1, '<origin xyz="0 $(arg spacing)/2 0" rpy="0 0 0"/>')]}, says={"side_by_side": "three numbers"}),
    wrong("robot_2_stands_on_robot_1", {"side_by_side", SUMMARY}, {XACRO: [
        ('<xacro:rrbot prefix="$(arg prefix_2)" parent="world">\n    ' + ROBOT_2,
         '<xacro:rrbot prefix="$(arg prefix_2)" parent="$(arg prefix_1)base_link">\n'
         '    <origin xyz="0 ${-$(arg spacing)} 0" rpy="0 0 0"/>')]}, says={"side_by_side": "hangs from 'r1_base_link'"}),
    wrong("second_component_with_the_first_prefix", {"two_prefixed_robots", SUMMARY},
          {XACRO: [(TAG_2, TAG_1.replace('name="rrbot"', 'name="rrbot2"'))]},
          says={"two_prefixed_robots": "2 hardware components' names start with 'r1_'"}),
    wrong("use_mock_hardware_left_to_the_macro_default", {"use_mock_hardware_reaches_both_robots", SUMMARY},
          {XACRO: [(TAG_2, TAG_2.replace(' use_mock_hardware="$(arg use_mock_hardware)"', ""))]},
          says={"use_mock_hardware_reaches_both_robots": "r2_rrbot"}, names_file="multi_rrbot.urdf.xacro, line"),
    wrong("use_mock_hardware_written_as_true", {"use_mock_hardware_reaches_both_robots", SUMMARY}, {XACRO: [
        (TAG_1, TAG_1.replace("$(arg use_mock_hardware)", "true")),
        (TAG_2, TAG_2.replace("$(arg use_mock_hardware)", "true"))]},
          says={"use_mock_hardware_reaches_both_robots": "use_mock_hardware:=false"}),
    wrong("robot_2_prefix_written_out", {"two_prefixed_robots", "same_prefix_twice_is_a_clear_error", SUMMARY}, {XACRO: [
        ('<xacro:rrbot prefix="$(arg prefix_2)"', '<xacro:rrbot prefix="r2_"'), (TAG_2, TAG_2.replace("$(arg prefix_2)", "r2_"))]},
          says={"two_prefixed_robots": "prefix_2:=right_"}),
    wrong("robot_1_prefix_written_out_example_name", {"two_prefixed_robots", "same_prefix_twice_is_a_clear_error", SUMMARY},
          {XACRO: [('<xacro:rrbot prefix="$(arg prefix_1)"', '<xacro:rrbot prefix="r1_"'),
                   (TAG_1, TAG_1.replace("$(arg prefix_1)", "r1_"))]}),
    wrong("component_names_written_out", {"two_prefixed_robots", SUMMARY}, {XACRO: [
        (TAG_1, TAG_1.replace('name="rrbot" prefix="$(arg prefix_1)"', 'name="rrbot_1" prefix=""')),
        (TAG_2, TAG_2.replace('name="rrbot" prefix="$(arg prefix_2)"', 'name="rrbot_2" prefix=""'))]},
          says={"two_prefixed_robots": "joint 'joint1' of <ros2_control name='rrbot_1'> not found"}, only=False),
    # --- the YAML: each rule, either layout
    wrong("second_forward_controller_on_the_first_robot", {"controllers_on_their_robots"}, {YAML: [
        (_section("r2_", "forward_position_controller"),
         "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r1_joint1, r1_joint2]\n")]},
          says={"controllers_on_their_robots": "r2_joint1"}, names_file="multi_rrbot_controllers.yaml, line"),
    wrong("forward_joints_in_reverse_order", {"controllers_on_their_robots"}, {YAML: [
        (_section("r1_", "forward_position_controller"),
         "r1_forward_position_controller:\n  ros__parameters:\n    joints: [r1_joint2, r1_joint1]\n")]},
          says={"controllers_on_their_robots": "in that order"}),
    wrong("joints_without_their_prefix", {"controllers_on_their_robots"}, {YAML: [
        (_section("r2_", "joint_trajectory_controller"),
         "r2_joint_trajectory_controller:\n  ros__parameters:\n    joints: [joint1, joint2]\n")]},
          says={"controllers_on_their_robots": "'r2_joint_trajectory_controller' has the joints ['joint1', 'joint2']"}),
    wrong("unprefixed_trajectory_controller_name", {"controllers_declared", "controllers_on_their_robots"}, {YAML: [
        ("    r1_joint_trajectory_controller:\n      type:", "    joint_trajectory_controller:\n      type:"),
        ("\nr1_joint_trajectory_controller:\n", "\njoint_trajectory_controller:\n")]},
          says={"controllers_declared": "declares no 'r1_joint_trajectory_controller'"}),
    wrong("robot_1_trajectory_on_robot_2_joints", {"controllers_on_their_robots"}, {YAML: [
        (_section("r1_", "joint_trajectory_controller"),
         "r1_joint_trajectory_controller:\n  ros__parameters:\n    joints: [r2_joint1, r2_joint2]\n")]}),
    wrong("robot_1_trajectory_commands_velocity", {"controllers_on_their_robots"}, {YAML: [
        (_section("r1_", "joint_trajectory_controller") + "    command_interfaces: [position]",
         _section("r1_", "joint_trajectory_controller") + "    command_interfaces: [velocity]\n    gains:\n"
         "      r1_joint1: {p: 5.0}\n      r1_joint2: {p: 5.0}")]}, says={"controllers_on_their_robots": "command_interfaces"}),
    wrong("trajectory_reads_position_only", {"controllers_on_their_robots"}, {YAML: [
        (_section("r2_", "joint_trajectory_controller") + "    command_interfaces: [position]\n"
         "    state_interfaces: [position, velocity]",
         _section("r2_", "joint_trajectory_controller") + "    command_interfaces: [position]\n"
         "    state_interfaces: [position]")]}, says={"controllers_on_their_robots": "state_interfaces"}),
    wrong("robot_2_forward_controller_on_velocity", {"controllers_on_their_robots"}, {YAML: [
        (_section("r2_", "forward_position_controller") + "    interface_name: position",
         _section("r2_", "forward_position_controller") + "    interface_name: velocity")]},
          says={"controllers_on_their_robots": "'velocity'"}),
    wrong("one_broadcaster_per_robot", {"controllers_declared"}, {YAML: [
        ("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n",
         "    r1_joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n"
         "    r2_joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n")]},
          says={"controllers_declared": "r1_joint_state_broadcaster"}),
    wrong("forward_controller_with_the_trajectory_type", {"controllers_declared"}, {YAML: [
        ("    r2_forward_position_controller:\n      type: forward_command_controller/ForwardCommandController\n",
         "    r2_forward_position_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n")]},
          says={"controllers_declared": "line"}),
    wrong("own_sections_with_a_misspelled_type", {"controllers_declared"}, {YAML: [*TYPES_IN_OWN_SECTIONS,
        ("\nr2_joint_trajectory_controller:\n  ros__parameters:\n    type: " + JTC + "\n",
         "\nr2_joint_trajectory_controller:\n  ros__parameters:\n    type: " + JTC.replace("Trajectory", "Trajectroy", 1) + "\n")]},
          says={"controllers_declared": "JointTrajectroyController"}, names_file="multi_rrbot_controllers.yaml, line"),
    wrong("task2_state_publish_rate_kept", {"parameters_valid_in_jazzy"}, {YAML: [
        (_section("r1_", "joint_trajectory_controller"),
         _section("r1_", "joint_trajectory_controller") + "    state_publish_rate: 50.0\n")]},
          says={"parameters_valid_in_jazzy": "state_publish_rate"}, names_file="multi_rrbot_controllers.yaml, line"),
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

#: The robot-placing macro in a helper file of its own, included by a relative path (the TODO leaves that open).
HELPER_FILE = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>
  <xacro:macro name="rrbot_at" params="prefix y use_mock_hardware">
    <xacro:rrbot prefix="${prefix}" parent="world">
      <origin xyz="0 ${y} 0" rpy="0 0 0"/>
    </xacro:rrbot>
    <xacro:rrbot_ros2_control name="rrbot" prefix="${prefix}" use_mock_hardware="${use_mock_hardware}"/>
  </xacro:macro>
</robot>
"""
HELPER_MAIN = """<?xml version="1.0"?>
<robot name="multi_rrbot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix_1" default="r1_"/>
  <xacro:arg name="prefix_2" default="r2_"/>
  <xacro:arg name="spacing" default="1.5"/>
  <xacro:arg name="use_mock_hardware" default="true"/>
  <xacro:include filename="rrbot_at.xacro"/>
  <link name="world"/>
  <xacro:rrbot_at prefix="$(arg prefix_1)" y="${$(arg spacing) / 2}" use_mock_hardware="$(arg use_mock_hardware)"/>
  <xacro:rrbot_at prefix="$(arg prefix_2)" y="${-$(arg spacing) / 2}" use_mock_hardware="$(arg use_mock_hardware)"/>
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

#: Flow style, every type in the controller's own section, the manager written as '/**/controller_manager'.
RIGHT_YAML_FLOW_OWN_SECTIONS = """/**/controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster}}
r1_forward_position_controller: {ros__parameters: {type: forward_command_controller/ForwardCommandController,
  joints: [r1_joint1, r1_joint2], interface_name: position}}
r2_forward_position_controller: {ros__parameters: {type: forward_command_controller/ForwardCommandController,
  joints: [r2_joint1, r2_joint2], interface_name: position}}
r1_joint_trajectory_controller: {ros__parameters: {type: joint_trajectory_controller/JointTrajectoryController,
  joints: [r1_joint1, r1_joint2], command_interfaces: [position], state_interfaces: [velocity, position]}}
r2_joint_trajectory_controller: {ros__parameters: {type: joint_trajectory_controller/JointTrajectoryController,
  joints: [r2_joint1, r2_joint2], command_interfaces: [position], state_interfaces: [position, velocity]}}
"""

RIGHT = [
    Variant("properties_other_order_other_component_name", {XACRO: RIGHT_XACRO_PROPERTIES}),
    Variant("own_macro_placing_each_robot", {XACRO: RIGHT_XACRO_OWN_MACRO}),
    Variant("helper_macro_in_a_file_of_its_own", {XACRO: HELPER_MAIN,
                                                  "multi_rrbot_description/urdf/rrbot_at.xacro": HELPER_FILE}),
    Variant("flow_yaml_other_order", {YAML: RIGHT_YAML_FLOW}),
    Variant("types_in_their_own_sections", {YAML: TYPES_IN_OWN_SECTIONS}),
    Variant("flow_yaml_types_in_their_own_sections", {YAML: RIGHT_YAML_FLOW_OWN_SECTIONS}),
    Variant("robot_2_turned_to_face_robot_1", {XACRO: [(ROBOT_2, '<origin xyz="0 ${-$(arg spacing) / 2} 0" rpy="0 0 ${pi}"/>')]}),
    Variant("task2_extras_and_block_lists", {YAML: [
        (_section("r1_", "joint_trajectory_controller") + "    command_interfaces: [position]",
         "r1_joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - r1_joint1\n      - r1_joint2\n"
         "    action_monitor_rate: 20.0\n    command_interfaces:\n      - position"),
        (_section("r2_", "forward_position_controller"),
         "r2_forward_position_controller:\n  ros__parameters:\n    joints:\n      - r2_joint1\n      - r2_joint2\n")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(11, WRONG + RIGHT, tmp_path_factory.mktemp("task11"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(11), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(11))


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3
