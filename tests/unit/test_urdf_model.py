"""The small URDF model: what ros2_control reads from a URDF, and urdfdom's rejections."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from rrbot_workshop.description.urdf_model import parse_urdf_model
from rrbot_workshop.exceptions import DescriptionError

_URDF = """<robot name="r">
  <link name="world"/><link name="a"/><link name="b"/>
  <joint name="fix" type="fixed"><parent link="world"/><child link="a"/></joint>
  <joint name="slide" type="prismatic">
    <parent link="a"/><child link="b"/>
    <limit upper="0.4" effort="5" velocity="0.1"/>
    <safety_controller k_velocity="3"/>
    <mimic joint="fix"/>
  </joint>
</robot>"""


def test_model_holds_links_joints_root_and_defaults() -> None:
    """Links in order, joints by name, the root link; omitted limit/safety/mimic values take urdfdom defaults."""
    model = parse_urdf_model(ET.fromstring(_URDF))
    assert model.name == "r" and model.links == ["world", "a", "b"] and model.root_link == "world"
    slide = model.joints["slide"]
    assert (slide.type, slide.parent, slide.child) == ("prismatic", "a", "b")
    assert slide.limit is not None and (slide.limit.lower, slide.limit.upper) == (0.0, 0.4)
    assert slide.safety is not None and (slide.safety.soft_lower_limit, slide.safety.k_velocity) == (0.0, 3.0)
    assert slide.mimic is not None and (slide.mimic.multiplier, slide.mimic.offset) == (1.0, 0.0)


@pytest.mark.parametrize("old, new, expected", [
    ('k_velocity="3"', "", "no 'k_velocity'"),
    ('<mimic joint="fix"/>', "<mimic/>", "<mimic> of joint 'slide' has no 'joint'"),
    ('upper="0.4"', 'upper="far"', "is not a number"),
    ('<joint name="fix"', '<joint name="slide"', "joint 'slide' is declared twice"),
    ('<link name="a"/>', "<link/>", "a <link> has no 'name'"),
])
def test_invalid_model_is_rejected(old: str, new: str, expected: str) -> None:
    """Each urdfdom rejection is a DescriptionError starting with 'Failed to parse URDF'."""
    with pytest.raises(DescriptionError, match="Failed to parse URDF") as info:
        parse_urdf_model(ET.fromstring(_URDF.replace(old, new, 1)), source="x.urdf")
    assert expected in str(info.value) and info.value.source == "x.urdf"


_PHYSICAL = """<robot name="p">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="0 0 0.5" rpy="0 0 0"/><mass value="1.0"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.01"/></inertial>
    <visual><origin xyz="0 0 0.5"/><geometry><box size="0.1 0.1 1"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><origin xyz="0 0 1" rpy="0 0 0"/>
    <parent link="base"/><child link="arm"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>"""


def test_physical_description_is_accepted() -> None:
    """A positive mass, a positive-definite inertia, finite origins and lower <= upper pass."""
    model = parse_urdf_model(ET.fromstring(_PHYSICAL), source="arm.urdf")
    assert model.joints["j"].limit is not None and model.joints["j"].limit.lower == -1.0


@pytest.mark.parametrize("old, new, expected", [
    ('<mass value="1.0"/>', '<mass value="0"/>', "<mass value='0'> of link 'arm' must be positive"),
    ('<mass value="1.0"/>', '<mass value="-2"/>', "<mass value='-2'> of link 'arm' must be positive"),
    ('izz="0.01"', 'izz="-0.01"', "of link 'arm' is not positive definite"),
    ('ixy="0"', 'ixy="0.5"', "of link 'arm' is not positive definite"),
    ('ixx="0.1"', 'ixx="0"', "of link 'arm' is not positive definite"),
    ('<origin xyz="0 0 1"', '<origin xyz="0 nan 1"', "<origin xyz='0 nan 1'> of joint 'j' must be three finite numbers"),
    ('<origin xyz="0 0 0.5" rpy="0 0 0"/>', '<origin xyz="0 0 inf"/>', "of <inertial> of link 'arm' must be three"),
    ('<origin xyz="0 0 0.5"/>', '<origin xyz="0 0"/>', "of <visual> of link 'arm' must be three finite numbers"),
    ('lower="-1" upper="1"', 'lower="1" upper="-1"', "has lower above upper (valid: lower <= upper)"),
    ('effort="10"', 'effort="nan"', "<limit effort='nan'> of joint 'j' must be a finite number"),
    ('<box size="0.1 0.1 1"/>', '<box size="0.1 0.1"/>', "<box size='0.1 0.1'> of <visual> of link 'arm' must be 3 positive"),
    ('<box size="0.1 0.1 1"/>', '<box size="0.1 -0.1 1"/>', "must be 3 positive numbers [m]"),
    ('<box size="0.1 0.1 1"/>', '<cylinder radius="0.1"/>', "<cylinder> of <visual> of link 'arm' has no 'length'"),
    ('<box size="0.1 0.1 1"/>', '<sphere radius="abc"/>', "<sphere radius='abc'> of <visual> of link 'arm' must be 1"),
    ('<box size="0.1 0.1 1"/>', '<mesh/>', "<mesh> of <visual> of link 'arm' has no 'filename'"),
])
def test_unphysical_description_is_rejected_naming_the_element(old: str, new: str, expected: str) -> None:
    """NaN/inf numbers, lower > upper, non-positive masses and inertias are rejected with the file and element."""
    text = _PHYSICAL.replace(old, new, 1)
    assert text != _PHYSICAL
    with pytest.raises(DescriptionError, match="arm.urdf: Failed to parse URDF") as info:
        parse_urdf_model(ET.fromstring(text), source="arm.urdf")
    assert expected in str(info.value)
