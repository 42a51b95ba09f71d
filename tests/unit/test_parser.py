"""The <ros2_control> parser: fields, defaults, limits, and one test per documented rejection."""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.description.parser import parse_bool
from rrbot_workshop.exceptions import DescriptionError

_LINKS_AND_JOINTS = """
  <link name="world"/>
  <link name="base_link"/>
  <link name="link1"/>
  <link name="link2"/>
  <link name="tool"/>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <limit lower="-2" upper="2" velocity="1.5" effort="-20"/>
  </joint>
  <joint name="joint2" type="continuous">
    <parent link="link1"/><child link="link2"/>
    <limit velocity="3" effort="10"/>
    <safety_controller soft_lower_limit="-5" soft_upper_limit="5" k_position="1" k_velocity="2"/>
  </joint>
  <joint name="tool_joint" type="fixed"><parent link="link2"/><child link="tool"/></joint>
"""

_JOINTS = """
    <joint name="joint1">
      <command_interface name="position"><param name="min">-1</param><param name="max">3</param></command_interface>
      <command_interface name="velocity"><param name="min">-0.5</param><param name="max">2</param></command_interface>
      <state_interface name="position"><param name="initial_value">0.25</param></state_interface>
    </joint>
    <joint name="joint2">
      <command_interface name="position"/>
      <state_interface name="position"/>
    </joint>
"""


def _urdf(ros2_control: str, links_and_joints: str = _LINKS_AND_JOINTS, robot_attrs: str = 'name="bot"') -> str:
    return f'\n  <?xml version="1.0"?>\n<robot {robot_attrs}>{links_and_joints}{ros2_control}</robot>\n'


def _system(body: str = _JOINTS, attrs: str = 'name="sys" type="system"', hardware: str | None = None) -> str:
    if hardware is None:
        hardware = "<hardware><plugin>mock_components/GenericSystem</plugin><param name='a'> 1 </param></hardware>"
    return f"<ros2_control {attrs}>{hardware}{body}</ros2_control>"


def _reject(urdf: str, *patterns: str) -> DescriptionError:
    with pytest.raises(DescriptionError) as info:
        parse_ros2_control(urdf, source="test.urdf")
    for pattern in patterns:
        assert pattern in str(info.value), f"'{pattern}' not in: {info.value}"
    assert str(info.value).startswith("test.urdf: ")
    return info.value


# ---------------------------------------------------------------- accepted input


def test_valid_system_is_parsed_with_fields_and_defaults() -> None:
    """Name, type, plugin, stripped params, interfaces, min/max/initial_value, data_type/size defaults."""
    (info,) = parse_ros2_control(_urdf(_system()))
    assert (info.name, info.type, info.hardware_plugin_name) == ("sys", "system", "mock_components/GenericSystem")
    assert info.hardware_parameters == {"a": "1"}
    assert (info.rw_rate, info.is_async, info.group) == (0, False, "")
    assert [j.name for j in info.joints] == ["joint1", "joint2"]
    position = info.joints[0].command_interfaces[0]
    assert (position.min, position.max, position.data_type, position.size) == ("-1", "3", "double", 1)
    assert position.parameters == {"min": "-1", "max": "3"}
    assert info.joints[0].state_interfaces[0].initial_value == "0.25"
    assert info.joints[0].is_mimic == ""
    assert info.original_xml.startswith("<ros2_control")


def test_each_component_keeps_the_whole_urdf_as_robot_description() -> None:
    """``robot_description`` is the text that was parsed (simulated hardware builds its model from it)."""
    urdf = _urdf(_system() + _system(attrs='name="other" type="system"', body=""))
    infos = parse_ros2_control(urdf)
    assert [i.name for i in infos] == ["sys", "other"]
    assert all(i.robot_description == urdf for i in infos)


def test_limits_merge_urdf_and_interface_min_max() -> None:
    """Position is intersected; velocity takes min(|min|, max); effort is the absolute URDF value."""
    (info,) = parse_ros2_control(_urdf(_system()))
    j1 = info.limits["joint1"]
    assert j1.has_position_limits and (j1.min_position, j1.max_position) == (-1.0, 2.0)
    assert j1.has_velocity_limits and j1.max_velocity == 0.5
    assert j1.has_effort_limits and j1.max_effort == 20.0
    assert not j1.angle_wraparound


def test_continuous_joint_wraps_around_and_keeps_soft_limits() -> None:
    """A continuous joint has angle_wraparound; its soft limits come from <safety_controller>."""
    (info,) = parse_ros2_control(_urdf(_system()))
    j2 = info.limits["joint2"]
    assert j2.angle_wraparound and not j2.has_position_limits
    assert (j2.max_velocity, j2.max_effort) == (3.0, 10.0)
    soft = info.soft_limits["joint2"]
    assert (soft.min_position, soft.max_position, soft.k_position, soft.k_velocity) == (-5.0, 5.0, 1.0, 2.0)
    assert "joint1" not in info.soft_limits


def test_limits_disabled_on_a_joint_switch_every_interface_off() -> None:
    """``<limits enable="false"/>`` on a joint disables the limits of all its interfaces."""
    body = _JOINTS.replace('<joint name="joint1">', '<joint name="joint1"><limits enable="False"/>')
    (info,) = parse_ros2_control(_urdf(_system(body)))
    assert not info.joints[0].enable_limits
    assert all(not i.enable_limits for i in info.joints[0].command_interfaces)
    j1 = info.limits["joint1"]
    assert not (j1.has_position_limits or j1.has_velocity_limits)
    assert j1.min_position == -math.inf or j1.min_position < -1e300


def test_namespaces_comments_and_leading_whitespace_are_accepted() -> None:
    """A default xmlns, comments and whitespace before ``<?xml`` do not matter (as with tinyxml2)."""
    urdf = _urdf("<!-- c -->" + _system(), robot_attrs='name="bot" xmlns="http://www.ros.org"')
    (info,) = parse_ros2_control(urdf)
    assert [j.name for j in info.joints] == ["joint1", "joint2"]


def test_sensor_gpio_and_properties() -> None:
    """Sensors and GPIOs with data_type/size; ``<properties><async>`` with lower-cased policy; async priority."""
    body = _JOINTS + """
      <sensor name="fts"><state_interface name="fx"/><param name="frame_id">tool</param></sensor>
      <gpio name="io"><command_interface name="out" data_type="bool" size="2"/><state_interface name="in"/></gpio>
      <properties><async scheduling_policy="DETACHED" affinity="1,2"/></properties>"""
    (info,) = parse_ros2_control(_urdf(_system(body, attrs='name="s" type="system" is_async="TRUE"')))
    assert info.sensors[0].parameters == {"frame_id": "tool"} and info.sensors[0].type == "sensor"
    out = info.gpios[0].command_interfaces[0]
    assert (out.data_type, out.size) == ("bool", 2)
    assert info.async_params == {"scheduling_policy": "detached", "affinity": "1,2", "print_warnings": "true"}
    assert info.is_async and info.thread_priority == 50


def test_no_hardware_tag_leaves_the_plugin_empty() -> None:
    """``<hardware>`` is optional; the plugin name is then empty."""
    (info,) = parse_ros2_control(_urdf(_system(hardware="")))
    assert info.hardware_plugin_name == ""


def test_actuator_transmission_is_filled_from_the_joint() -> None:
    """Transmission joints copy the component's interface names; an actuator gets ``actuator1``."""
    body = """
      <joint name="joint1"><command_interface name="velocity"/><state_interface name="position"/></joint>
      <transmission name="t1"><plugin>transmission_interface/SimpleTransmission</plugin>
        <joint name="joint1" role="joint1"><mechanical_reduction>4.0</mechanical_reduction></joint>
      </transmission>"""
    (info,) = parse_ros2_control(_urdf(_system(body, attrs='name="a" type="actuator"')))
    (transmission,) = info.transmissions
    assert transmission.plugin == "transmission_interface/SimpleTransmission"
    assert transmission.joints[0].mechanical_reduction == 4.0 and transmission.joints[0].offset == 0.0
    assert transmission.joints[0].command_interfaces == ["velocity"]
    assert [a.name for a in transmission.actuators] == ["actuator1"]


def test_mimic_joint_is_recorded() -> None:
    """A URDF ``<mimic>`` joint without command interfaces becomes a MimicJoint."""
    links = _LINKS_AND_JOINTS.replace(
        '<child link="link2"/>', '<child link="link2"/><mimic joint="joint1" multiplier="-2" offset="0.5"/>'
    )
    body = _JOINTS.replace('<command_interface name="position"/>\n      <state_interface name="position"/>',
                           '<state_interface name="position"/>')
    (info,) = parse_ros2_control(_urdf(_system(body), links))
    (mimic,) = info.mimic_joints
    assert (mimic.joint_index, mimic.mimicked_joint_index, mimic.multiplier, mimic.offset) == (1, 0, -2.0, 0.5)


def test_parse_bool_accepts_any_case_and_rejects_others() -> None:
    """``parse_bool`` reads true/false in any case and raises ValueError otherwise."""
    assert parse_bool("TRUE") and not parse_bool("False")
    with pytest.raises(ValueError):
        parse_bool("yes")


# ---------------------------------------------------------------- rejections (one per documented Raises)


def test_empty_text_is_rejected() -> None:
    """An empty or blank string."""
    _reject("  \n", "empty URDF")


def test_malformed_xml_is_rejected() -> None:
    """Not well-formed XML."""
    _reject("<robot><link></robot>", "malformed XML")


def test_sdf_is_rejected_as_not_supported() -> None:
    """SDF input says that SDF is not supported."""
    _reject('<sdf version="1.7"><model name="m"/></sdf>', "SDF is not supported")


def test_root_other_than_robot_is_rejected() -> None:
    """The root element must be <robot>."""
    _reject("<ros2_control name='x' type='system'/>", "root element is <ros2_control>", "expected <robot>")


def test_missing_ros2_control_tag_is_rejected() -> None:
    """A URDF without any <ros2_control> tag."""
    _reject(_urdf(""), "no 'ros2_control' tag")


@pytest.mark.parametrize("attrs, missing", [('type="system"', "name"), ('name="x"', "type")])
def test_ros2_control_without_name_or_type_is_rejected(attrs: str, missing: str) -> None:
    """``name`` and ``type`` are required on <ros2_control>."""
    err = _reject(_urdf(_system(attrs=attrs)), f"missing attribute '{missing}'", "required: name, type")
    assert err.attribute == missing


def test_unknown_child_is_rejected_with_the_valid_ones() -> None:
    """An unknown child of <ros2_control> lists the valid children."""
    _reject(_urdf(_system(_JOINTS + "<hardwarert/>")),
            "invalid tag name 'hardwarert' in <ros2_control name='sys'>",
            "(valid: hardware, properties, joint, sensor, gpio, transmission)")


def test_hardware_without_plugin_is_rejected() -> None:
    """<hardware> needs a <plugin>; the message names the component."""
    _reject(_urdf(_system(hardware="<hardware><param name='a'>1</param></hardware>")),
            "Missing <plugin> tag of <hardware> element for 'sys'")


def test_param_without_name_is_rejected_with_its_owner() -> None:
    """A <param> without name names the joint it belongs to."""
    body = _JOINTS.replace('<param name="min">-1</param>', "<param>-1</param>")
    _reject(_urdf(_system(body)), "no parameter name attribute set in param tag for 'joint1'",
            "<command_interface name='position'> of <joint name='joint1'>")


def test_interface_without_name_is_rejected() -> None:
    """A <state_interface> needs a name."""
    body = _JOINTS.replace('<state_interface name="position"/>', "<state_interface/>")
    _reject(_urdf(_system(body)), "missing attribute 'name' in <state_interface> of <joint name='joint2'>")


@pytest.mark.parametrize("size", ["-4", "ILLEGAL", "0", "1.5"])
def test_bad_size_is_rejected(size: str) -> None:
    """``size`` must be a positive integer."""
    body = _JOINTS + f'<gpio name="io"><state_interface name="in" size="{size}"/></gpio>'
    _reject(_urdf(_system(body)), f"invalid size='{size}'", "positive integer")


@pytest.mark.parametrize("rate", ["-50", "d 50", "12345678901"])
def test_bad_rw_rate_is_rejected(rate: str) -> None:
    """``rw_rate`` must be a non-negative integer that fits an int."""
    _reject(_urdf(_system(attrs=f'name="s" type="system" rw_rate="{rate}"')), f"invalid rw_rate='{rate}'")


def test_rw_rate_reads_a_leading_integer() -> None:
    """Like std::stoi, ``rw_rate="50 Hz"`` reads 50."""
    (info,) = parse_ros2_control(_urdf(_system(attrs='name="s" type="system" rw_rate="50 Hz"')))
    assert info.rw_rate == 50


def test_bad_thread_priority_of_async_component_is_rejected() -> None:
    """An async component's thread_priority must be a positive integer."""
    attrs = 'name="s" type="system" is_async="true" thread_priority="-30"'
    _reject(_urdf(_system(attrs=attrs)), "invalid thread_priority='-30'")


def test_bad_is_async_is_rejected() -> None:
    """``is_async`` must be true or false."""
    _reject(_urdf(_system(attrs='name="s" type="system" is_async="maybe"')), "invalid is_async='maybe'",
            "(valid: true, false)")


def test_bad_mimic_value_is_rejected() -> None:
    """``mimic`` must be true or false."""
    body = _JOINTS.replace('<joint name="joint2">', '<joint name="joint2" mimic="sometimes">')
    _reject(_urdf(_system(body)), "invalid mimic='sometimes'")


def test_limits_without_enable_is_rejected() -> None:
    """<limits> needs its ``enable`` attribute."""
    body = _JOINTS.replace('<joint name="joint2">', '<joint name="joint2"><limits/>')
    _reject(_urdf(_system(body)), "missing attribute 'enable' in <limits> of <joint name='joint2'>")


def test_transmission_joint_not_in_component_is_rejected() -> None:
    """Every transmission joint must be a joint of the same tag."""
    body = _JOINTS + '<transmission name="t"><plugin>p</plugin><joint name="joint9" role="j"/></transmission>'
    _reject(_urdf(_system(body)), "declares joint 'joint9'", "(valid: joint1, joint2)")


def test_transmission_without_plugin_is_rejected() -> None:
    """A transmission needs a <plugin>."""
    body = _JOINTS + '<transmission name="t"><joint name="joint1" role="j"/></transmission>'
    _reject(_urdf(_system(body)), "missing <plugin> in <transmission name='t'>")


def test_actuator_transmission_with_two_joints_is_rejected() -> None:
    """An actuator's transmission has exactly one joint."""
    body = _JOINTS + ('<transmission name="t"><plugin>p</plugin><joint name="joint1" role="a"/>'
                      '<joint name="joint2" role="b"/></transmission>')
    _reject(_urdf(_system(body, attrs='name="a" type="actuator"')), "has 2 joints", "exactly one")


@pytest.mark.parametrize("edit, expected", [
    (('name="bot"', ""), "<robot> has no 'name'"),
    (("<limit lower=\"-2\" upper=\"2\" velocity=\"1.5\" effort=\"-20\"/>", ""), "is revolute but has no <limit>"),
    (('velocity="1.5" effort="-20"', 'velocity="1.5"'), "no 'effort' attribute"),
    (('type="revolute"', 'type="hinge"'), "has type 'hinge'"),
    (('<parent link="base_link"/>', '<parent link="ghost"/>'), "parent link 'ghost'"),
    (('<link name="tool"/>', '<link name="tool"/><link name="orphan"/>'), "exactly one root link"),
    (('<link name="tool"/>', '<link name="tool"/><link name="tool"/>'), "link 'tool' is declared twice"),
    (('<child link="tool"/>', '<child link="link2"/>'), "child of two joints"),
])
def test_invalid_urdf_is_rejected(edit: tuple[str, str], expected: str) -> None:
    """The URDF itself is checked as urdfdom does ("Failed to parse URDF")."""
    urdf = _urdf(_system()).replace(*edit, 1)
    _reject(urdf, "Failed to parse URDF", expected)


def test_urdf_without_links_is_rejected() -> None:
    """A robot with no <link> is not a URDF."""
    _reject(_urdf(_system(), links_and_joints=""), "Failed to parse URDF", "has no <link>")


def test_joint_missing_from_urdf_is_rejected() -> None:
    """Each <ros2_control> joint must be a URDF joint; the message lists the URDF joints."""
    body = _JOINTS.replace('<joint name="joint2">', '<joint name="joint7">')
    _reject(_urdf(_system(body)), "Joint 'joint7'", "not found in URDF", "joint1, joint2")


def test_fixed_joint_is_rejected() -> None:
    """Fixed joints cannot be in <ros2_control>."""
    body = _JOINTS + '<joint name="tool_joint"><state_interface name="position"/></joint>'
    _reject(_urdf(_system(body)), "Joint 'tool_joint' is of type 'fixed'")


def test_mimic_true_without_urdf_mimic_is_rejected() -> None:
    """mimic="true" needs a URDF <mimic>."""
    body = _JOINTS.replace('<joint name="joint2">', '<joint name="joint2" mimic="true">')
    _reject(_urdf(_system(body)), "Joint 'joint2' has mimic='true'", "no <mimic> in the URDF")


def test_active_mimic_joint_with_command_interface_is_rejected() -> None:
    """A joint that mimics another in the URDF may not have command interfaces unless mimic="false"."""
    links = _LINKS_AND_JOINTS.replace('<child link="link2"/>', '<child link="link2"/><mimic joint="joint1"/>')
    _reject(_urdf(_system(), links), "cannot have command interfaces", "found: position")
    body = _JOINTS.replace('<joint name="joint2">', '<joint name="joint2" mimic="false">')
    (info,) = parse_ros2_control(_urdf(_system(body), links))
    assert info.mimic_joints == []


def test_mimicked_joint_outside_the_tag_is_rejected() -> None:
    """The followed joint must be in the same <ros2_control> tag."""
    links = _LINKS_AND_JOINTS.replace('<child link="link2"/>', '<child link="link2"/><mimic joint="joint1"/>')
    body = '<joint name="joint2"><state_interface name="position"/></joint>'
    _reject(_urdf(_system(body), links), "Mimic joint 'joint1'", "not found in <ros2_control name='sys'>")


def test_a_joint_listed_twice_in_one_block_is_rejected_naming_it() -> None:
    twice = _JOINTS + '<joint name="joint1"><state_interface name="velocity"/></joint>'
    err = _reject(_urdf(_system(twice)), "<joint name='joint1'> appears twice in <ros2_control name='sys'>",
                  "list each joint once")
    assert err.element is not None and "joint1" in err.element


@pytest.mark.parametrize("kind", ["command_interface", "state_interface"])
def test_an_interface_declared_twice_is_rejected_naming_it(kind: str) -> None:
    body = f'<joint name="joint1"><{kind} name="position"/><{kind} name="position"/></joint>'
    _reject(_urdf(_system(body)), f"<{kind} name='position'> appears 2 times in <joint name='joint1'>",
            f"declare each {kind} once")


def test_the_same_gpio_twice_is_rejected() -> None:
    body = _JOINTS + '<gpio name="io"><state_interface name="a"/></gpio><gpio name="io"><state_interface name="b"/></gpio>'
    _reject(_urdf(_system(body)), "<gpio name='io'> appears twice")
