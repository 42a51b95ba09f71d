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
