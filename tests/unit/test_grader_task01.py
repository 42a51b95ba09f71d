"""The task-1 grader: wrong descriptions, written as learners get them wrong, lose points; right ones written
differently from solutions/ get full marks.

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

URDF = "rrbot_description/urdf"
MACRO = f"{URDF}/rrbot/rrbot_macro.xacro"
TAG = f"{URDF}/rrbot/rrbot_macro.ros2_control.xacro"
MAIN = f"{URDF}/rrbot.urdf.xacro"

LINK1_COLLISION = """      <collision>
        <origin xyz="0 0 ${link1_length / 2}" rpy="0 0 0" />
        <geometry>
          <cylinder length="${link1_length}" radius="${link1_radius}" />
        </geometry>
      </collision>
"""
FLANGE = """    <joint name="${prefix}tool0-flange_joint" type="fixed">
      <parent link="${prefix}tool0" />
      <child link="${prefix}flange" />
      <origin xyz="0 0 0" rpy="0 0 0" />
    </joint>
    <link name="${prefix}flange" />
"""
LINK2_VISUAL_ORIGIN = """        <origin xyz="0 0 ${link2_length / 2}" rpy="0 0 0" />
        <geometry>
          <box size="${link2_width} ${link2_width} ${link2_length}" />
        </geometry>
        <material name="rrbot_light_grey" />"""
JOINT1_STATES = """      <joint name="${prefix}joint1">
        <command_interface name="position" />
        <state_interface name="position" />
        <state_interface name="velocity" />
        <state_interface name="acceleration" />"""

WRONG = [
    # --- kept from test_graders.py (there as regex mutations)
    Variant("link1_of_0_4_m", {MACRO: [('name="link1_length" value="0.5"', 'name="link1_length" value="0.4"')]},
            fails={"link1_shape", "joint2_placement", "tool0_everywhere_in_the_workspace"},
            says={"joint2_placement": "0.5"}),
    Variant("missing_gpio_output", {TAG: [('        <command_interface name="digital_out_2" />\n'
                                           '        <state_interface name="digital_out_2" />\n', "")]},
            fails={"gpio_outputs", "gpio_output_readback"}, only=True),
    Variant("unprefixed_frame_id", {TAG: [('<param name="frame_id">${prefix}tool0</param>',
                                           '<param name="frame_id">tool0</param>')]}, fails={"prefix"}, only=True),
    Variant("joint2_limits_in_degrees", {MACRO: [('lower="${radians(-60)}" upper="${radians(240)}"',
                                                  'lower="-60" upper="240"')]}, fails={"joint2_limits"}, only=True),
    Variant("unprefixed_ros2_control_name", {TAG: [('<ros2_control name="${prefix}${name}"', '<ros2_control name="${name}"')]},
            fails={"prefix", "ros2_control_macro_name"}),
    Variant("unprefixed_sensor_and_gpio", {TAG: [('<sensor name="${prefix}tcp_fts_sensor">', '<sensor name="tcp_fts_sensor">'),
                                                 ('<gpio name="${prefix}flange_gpios">', '<gpio name="flange_gpios">')]},
            fails={"prefix"}, only=True),
    Variant("tool0_not_turned", {MACRO: [('rpy="0 ${-pi} ${-pi / 2}"', 'rpy="0 0 0"')]},
            fails={"tool0_orientation", "tool0_everywhere_in_the_workspace"}),
    Variant("missing_flange_frame", {MACRO: [(FLANGE, "")]}, fails={"links_and_joints", "tool0_orientation"}),
    Variant("link2_box_lying_along_x", {MACRO: [(LINK2_VISUAL_ORIGIN, LINK2_VISUAL_ORIGIN.replace(
        "${link2_width} ${link2_width} ${link2_length}", "${link2_length} ${link2_width} ${link2_width}"))]},
            fails={"link2_shape"}, only=True),
    Variant("link2_box_centred_on_joint2", {MACRO: [(LINK2_VISUAL_ORIGIN, LINK2_VISUAL_ORIGIN.replace(
        'xyz="0 0 ${link2_length / 2}"', 'xyz="0 0 0"'))]}, fails={"link2_shape"}, only=True),
    Variant("link1_without_collision", {MACRO: [(LINK1_COLLISION, "")]}, fails={"link1_shape"}, only=True),
    # --- masses and inertial origins as the TODO states them, not merely positive
    Variant("link2_mass_of_the_library_robot", {MACRO: [('name="link2_mass" value="0.5"', 'name="link2_mass" value="1.0"')]},
            fails={"masses"}, only=True),
    Variant("link1_mass_in_grams", {MACRO: [('name="link1_mass" value="1.0"', 'name="link1_mass" value="1000"')]},
            fails={"masses"}, only=True, says={"masses": "1000"}),
    Variant("link1_inertial_at_the_joint", {MACRO: [(
        '<xacro:cylinder_inertial mass="${link1_mass}" radius="${link1_radius}" length="${link1_length}">\n'
        '        <origin xyz="0 0 ${link1_length / 2}" rpy="0 0 0" />',
        '<xacro:cylinder_inertial mass="${link1_mass}" radius="${link1_radius}" length="${link1_length}">\n'
        '        <origin xyz="0 0 0" rpy="0 0 0" />')]}, fails={"inertial_origins"}, only=True),
    Variant("link2_inertia_with_sizes_swapped", {MACRO: [(
        'x="${link2_width}" y="${link2_width}" z="${link2_length}"',
        'x="${link2_length}" y="${link2_width}" z="${link2_width}"')]}, fails={"inertias"}, only=True),
    # --- each bound, each direction
    Variant("joint1_turning_clockwise", {MACRO: [('<axis xyz="0 0 1" />', '<axis xyz="0 0 -1" />')]},
            fails={"joint1_placement", "tool0_everywhere_in_the_workspace"}),
    Variant("joint2_lowering_for_positive_angles", {MACRO: [('<axis xyz="0 1 0" />', '<axis xyz="0 -1 0" />')]},
            fails={"tool0_at_tip", "tool0_everywhere_in_the_workspace"}),
    Variant("joint1_lower_limit_of_half_a_turn", {MACRO: [('lower="${radians(-380)}"', 'lower="${radians(-180)}"')]},
            fails={"joint1_limits"}, only=True),
    Variant("joint2_lower_limit_with_the_wrong_sign", {MACRO: [('lower="${radians(-60)}"', 'lower="${radians(60)}"')]},
            fails={"joint2_limits"}, only=True),
    Variant("joint1_effort_of_100", {MACRO: [(
        'upper="${radians(380)}" effort="1000.0"', 'upper="${radians(380)}" effort="100.0"')]}, fails={"joint1_limits"}, only=True),
    # --- names the task states as parameters, tried with other values
    Variant("hard_coded_component_name", {TAG: [('<ros2_control name="${prefix}${name}"', '<ros2_control name="${prefix}rrbot"')]},
            fails={"ros2_control_macro_name"}, only=True),
    Variant("hard_coded_left_prefix_in_the_tag", {TAG: [('<gpio name="${prefix}flange_gpios">', '<gpio name="left_flange_gpios">')]},
            fails={"prefix"}, only=True, says={"prefix": "left_flange_gpios"}),
    # --- the <ros2_control> tag
    Variant("two_plugins_in_hardware", {TAG: [(
        "<plugin>mock_components/GenericSystem</plugin>",
        "<plugin>mock_components/GenericSystem</plugin>\n"
        "        <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>")]}, fails={"ros2_control_tag"}, only=True),
    Variant("position_twice_instead_of_acceleration", {TAG: [(JOINT1_STATES, JOINT1_STATES.replace(
        '<state_interface name="acceleration" />', '<state_interface name="position" />'))]},
            fails={"joint_interfaces"}),
    Variant("input_as_command_too", {TAG: [('        <state_interface name="digital_in_1" />\n',
                                            '        <command_interface name="digital_in_1" />\n'
                                            '        <state_interface name="digital_in_1" />\n')]},
            fails={"gpio_inputs"}, only=True),
    Variant("fts_as_gpio", {TAG: [('<sensor name="${prefix}tcp_fts_sensor">', '<gpio name="${prefix}tcp_fts_sensor">'),
                                  ('<param name="frame_id">${prefix}tool0</param>\n      </sensor>',
                                   '<param name="frame_id">${prefix}tool0</param>\n      </gpio>')]},
            fails={"fts_sensor"}),
    Variant("ros2_control_macro_not_instantiated", {MAIN: [(
        '  <xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix)" />\n', "")]},
            fails={"ros2_control_tag", "joint_interfaces", "prefix", "fts_sensor", "gpio_inputs", "gpio_outputs",
                   "gpio_output_readback"}, says={"ros2_control_tag": "0 <ros2_control> tags"}),
    # --- one slip, one rule: the others judged with the learner's value taken as given
    Variant("joint1_at_half_the_pedestal", {MACRO: [('<origin xyz="0 0 ${pedestal_size}" rpy="0 0 0" />',
                                                      '<origin xyz="0 0 ${pedestal_size / 2}" rpy="0 0 0" />')]},
            fails={"joint1_placement", "tool0_everywhere_in_the_workspace"}, says={"joint1_placement": "[0, 0, 0.3]"}),
    Variant("link1_radius_as_the_diameter", {MACRO: [('<xacro:property name="link1_radius" value="0.1" />',
                                                       '<xacro:property name="link1_radius" value="0.2" />')]},
            fails={"link1_shape"}, only=True, says={"link1_shape": "radius of 0.2"}),
    Variant("second_input_left_out", {TAG: [('        <state_interface name="digital_in_2" />\n', "")]},
            fails={"gpio_inputs"}, only=True, says={"gpio_inputs": "digital_in_2"}),
    Variant("frame_id_misspelled", {TAG: [('<param name="frame_id">${prefix}tool0</param>',
                                           '<param name="frame_id">${prefix}tool_0</param>')]},
            fails={"fts_sensor"}, only=True, says={"fts_sensor": "tool_0"}),
]

#: Numbers written out instead of properties and expressions, bodies before joints, inertials typed in by hand
#: (rounded to 5 decimals), 1.5707963 for pi/2.
INLINE_MACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="rrbot" params="prefix parent *origin">
    <link name="${prefix}base_link">
      <inertial>
        <origin xyz="0 0 0.15"/>
        <mass value="5"/>
        <inertia ixx="0.075" ixy="0" ixz="0" iyy="0.075" iyz="0" izz="0.075"/>
      </inertial>
      <visual><origin xyz="0 0 0.15"/><geometry><box size="0.3 0.3 0.3"/></geometry></visual>
      <collision><origin xyz="0 0 0.15"/><geometry><box size="0.3 0.3 0.3"/></geometry></collision>
    </link>
    <link name="${prefix}link1">
      <collision><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.1" length="0.5"/></geometry></collision>
      <visual><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.1" length="0.5"/></geometry></visual>
      <inertial>
        <origin xyz="0 0 0.25"/>
        <mass value="1"/>
        <inertia ixx="0.02333" ixy="0" ixz="0" iyy="0.02333" iyz="0" izz="0.005"/>
      </inertial>
    </link>
    <link name="${prefix}link2">
      <visual><origin xyz="0 0 0.3"/><geometry><box size="0.1 0.1 0.6"/></geometry></visual>
      <collision><origin xyz="0 0 0.3"/><geometry><box size="0.1 0.1 0.6"/></geometry></collision>
      <inertial>
        <origin xyz="0 0 0.3"/>
        <mass value="0.5"/>
        <inertia ixx="0.01542" ixy="0" ixz="0" iyy="0.01542" iyz="0" izz="0.00083"/>
      </inertial>
    </link>
    <link name="${prefix}tool0"/>
    <link name="${prefix}base"/>
    <link name="${prefix}flange"/>
    <joint name="${prefix}base_joint" type="fixed">
      <xacro:insert_block name="origin"/>
      <parent link="${parent}"/>
      <child link="${prefix}base_link"/>
    </joint>
    <joint name="${prefix}joint1" type="revolute">
      <origin xyz="0 0 0.3"/>
      <axis xyz="0 0 1"/>
      <parent link="${prefix}base_link"/>
      <child link="${prefix}link1"/>
      <limit lower="-6.6323" upper="6.6323" velocity="3.1416" effort="1000"/>
    </joint>
    <joint name="${prefix}joint2" type="revolute">
      <origin xyz="0 0 0.5" rpy="0 -1.5707963 0"/>
      <axis xyz="0 1 0"/>
      <parent link="${prefix}link1"/>
      <child link="${prefix}link2"/>
      <limit lower="-1.0472" upper="4.1888" velocity="3.1416" effort="1000"/>
    </joint>
    <joint name="${prefix}link2-tool0" type="fixed">
      <origin xyz="0 0 0.6" rpy="0 -3.1415927 -1.5707963"/>
      <parent link="${prefix}link2"/>
      <child link="${prefix}tool0"/>
    </joint>
    <joint name="${prefix}base_link-base_joint" type="fixed">
      <parent link="${prefix}base_link"/>
      <child link="${prefix}base"/>
    </joint>
    <joint name="${prefix}tool0-flange_joint" type="fixed">
      <parent link="${prefix}tool0"/>
      <child link="${prefix}flange"/>
    </joint>
  </xacro:macro>
</robot>
"""

#: A macro per joint, called twice; the GPIO's interfaces in another order; the sensor's param first; the tag's
#: name built through a property.
LOOPED_TAG = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="position_joint" params="joint_name">
    <joint name="${joint_name}">
      <command_interface name="position"/>
      <state_interface name="position"/>
      <state_interface name="velocity"/>
      <state_interface name="acceleration"/>
    </joint>
  </xacro:macro>
  <xacro:macro name="rrbot_ros2_control" params="name prefix">
    <xacro:property name="component" value="${prefix + name}"/>
    <ros2_control name="${component}" type="system">
      <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
      <xacro:position_joint joint_name="${prefix}joint1"/>
      <xacro:position_joint joint_name="${prefix}joint2"/>
      <gpio name="${prefix}flange_gpios">
        <state_interface name="digital_in_1"/>
        <state_interface name="digital_in_2"/>
        <state_interface name="digital_out_1"/>
        <state_interface name="digital_out_2"/>
        <command_interface name="digital_out_1"/>
        <command_interface name="digital_out_2"/>
      </gpio>
      <sensor name="${prefix}tcp_fts_sensor">
        <param name="frame_id">${prefix}tool0</param>
        <state_interface name="tx"/>
        <state_interface name="ty"/>
        <state_interface name="tz"/>
        <state_interface name="fx"/>
        <state_interface name="fy"/>
        <state_interface name="fz"/>
      </sensor>
    </ros2_control>
  </xacro:macro>
</robot>
"""

RIGHT = [
    Variant("numbers_inline_bodies_first", {MACRO: INLINE_MACRO}),
    Variant("joint_macro_and_other_order", {TAG: LOOPED_TAG}),
    Variant("other_property_names_and_pi_forms", {MACRO: [
        ('<xacro:property name="link1_mass" value="1.0" />',
         '<xacro:property name="link1_mass" value="${2 * link2_mass}" />\n  <xacro:property name="upper_arm" value="0.5" />'),
        ('<origin xyz="0 0 ${link1_length}" rpy="0 ${-pi / 2} 0" />', '<origin xyz="0 0 ${upper_arm}" rpy="0 -${pi/2} 0" />'),
        ('rpy="0 ${-pi} ${-pi / 2}"', 'rpy="0 ${-radians(180)} ${-0.5 * pi}"'),
        ('upper="${radians(380)}" effort="1000.0" velocity="${radians(180)}"', 'upper="${380 * pi / 180}" effort="1e3" velocity="${pi}"'),
    ]}),
    Variant("tag_instantiated_first_with_a_prefix_property", {MAIN: [
        ('  <xacro:include filename="rrbot/rrbot_macro.xacro" />\n'
         '  <xacro:include filename="rrbot/rrbot_macro.ros2_control.xacro" />\n',
         '  <xacro:include filename="rrbot/rrbot_macro.ros2_control.xacro" />\n'
         '  <xacro:include filename="rrbot/rrbot_macro.xacro" />\n'
         '  <xacro:property name="p" value="$(arg prefix)" />\n'
         '  <xacro:rrbot_ros2_control prefix="${p}" name="rrbot" />\n'),
        ('  <xacro:rrbot_ros2_control name="rrbot" prefix="$(arg prefix)" />\n', ""),
    ]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(1, WRONG + RIGHT, tmp_path_factory.mktemp("task01"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


#: Variants with several slips at once.
MANY_SLIPS: set[str] = set()


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name not in MANY_SLIPS], ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(1), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(1))


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


def test_variant_changes_name_existing_files() -> None:
    root = tracks.task_dir(1, "solutions")
    for variant in WRONG + RIGHT:
        for rel, change in variant.changes.items():
            assert change is None or isinstance(change, str) or (root / rel).is_file(), (variant.name, rel)


