"""Tests of rrbot_workshop.hardware.mujoco_urdf: URDF text made loadable by MuJoCo, frames found again."""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_urdf import effort_limits, frame_in_body, prepare_urdf

_INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'

# world -> base_link -> joint2 (moving) -> link2 -> tool0 (fixed, 0.5 m out, z turned onto x).
_ARM = f"""<?xml version="1.0"?>
<robot name="arm">
  <link name="world"/>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <link name="base_link">{_INERTIAL}</link>
  <joint name="joint2" type="revolute"><parent link="base_link"/><child link="link2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="2" effort="30"/></joint>
  <link name="link2">{_INERTIAL}
    <visual><geometry><mesh filename="package://rrbot/meshes/link2.dae"/></geometry></visual></link>
  <joint name="tool_joint" type="fixed"><parent link="link2"/><child link="tool0"/>
    <origin xyz="0.5 0 0" rpy="0 1.5707963267948966 0"/></joint>
  <link name="tool0"/>
  <ros2_control name="arm" type="system"><hardware><plugin>rrbot_workshop/MujocoSystem</plugin></hardware></ros2_control>
</robot>
"""


def test_prepare_urdf_resolves_package_uris_and_keeps_frames() -> None:
    """package:// meshes become absolute paths under descriptions/; compiler keeps visuals and fixed frames."""
    urdf = _ARM.replace("link2.dae", "link2.stl")
    text, _ = prepare_urdf(urdf)
    root = ET.fromstring(text)
    filename = root.find("link[@name='link2']/visual/geometry/mesh").get("filename")  # type: ignore[union-attr]
    assert filename.endswith("descriptions/rrbot/meshes/link2.stl") and filename.startswith("/")
    compiler = root.find("mujoco/compiler")
    assert compiler is not None and compiler.get("fusestatic") == "false" and compiler.get("discardvisual") == "false"
    assert root.find("ros2_control") is None


def test_prepare_urdf_drops_meshes_mujoco_cannot_read(caplog: pytest.LogCaptureFixture) -> None:
    """A .dae visual is removed with a warning naming the link."""
    with caplog.at_level(logging.WARNING):
        text, _ = prepare_urdf(_ARM)
    assert ET.fromstring(text).find("link[@name='link2']/visual") is None
    assert "link2" in caplog.text


@pytest.mark.parametrize("text", ["<robot", "<sdf/>"])
def test_prepare_urdf_rejects_what_is_not_a_urdf(text: str) -> None:
    """Malformed XML and a root other than <robot> raise DescriptionError."""
    with pytest.raises(DescriptionError):
        prepare_urdf(text)


def test_merged_frame_is_placed_with_the_fixed_joint_offset() -> None:
    """If tool0 were merged into link2, the site goes on link2 with the fixed joint's offset and rotation."""
    root = ET.fromstring(_ARM)
    body, pos, rot = frame_in_body("tool0", root, {"world", "base_link", "link2"})
    assert body == "link2" and np.allclose(pos, [0.5, 0, 0])
    assert np.allclose(rot @ [0, 0, 1], [1, 0, 0], atol=1e-9)


def test_merged_frame_behind_a_moving_joint_is_rejected() -> None:
    """A frame reachable only through a moving joint cannot carry a site."""
    with pytest.raises(DescriptionError, match="merged"):
        frame_in_body("link2", ET.fromstring(_ARM), {"world", "base_link"})


def test_prepare_urdf_rejects_an_unknown_package() -> None:
    """A package:// URI naming no folder of descriptions/ raises DescriptionError."""
    with pytest.raises(DescriptionError, match="nosuchpackage"):
        prepare_urdf(_ARM.replace("package://rrbot/", "package://nosuchpackage/"))



def test_effort_limits_are_read_from_the_urdf() -> None:
    """effort_limits gives joint2's <limit effort> and nothing for fixed joints."""
    assert effort_limits(ET.fromstring(_ARM)) == {"joint2": 30.0}
