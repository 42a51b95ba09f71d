"""Grader of task 1: the RRBot description (xacro macros and the ``<ros2_control>`` tag).

The specification (from the ROSCon 2022 workshop, task 1):

* 2 DoF on a pedestal, a box 0.3 m x 0.3 m x 0.3 m standing on the ground;
* joint1 0.3 m above the ground, turning about the vertical axis, limits +-380 deg, 180 deg/s;
* link1 a cylinder 0.5 m long, 0.1 m radius; joint2 at its top, turning about an axis orthogonal to it,
  limits -60 deg to 240 deg, 180 deg/s; link2 0.6 m long, 0.1 m x 0.1 m cross-section; tool0 at its tip.
  At zero, link2 is horizontal; a positive joint2 angle lifts it (at +90 deg it points straight up);
* tool0 is turned as in the original workshop (``link2-tool0`` rpy ``0 -pi -pi/2``): its z axis points back along
  link2 towards joint2, its x axis along joint2's axis. It is the force-torque sensor's frame, so this fixes what
  fx ... tz mean. Two more frames, as in the original: ``base`` on base_link and ``flange`` on tool0;
* every link with a body has an inertial at the body's centre, with the masses the TODO states (pedestal 5.0 kg,
  link1 1.0 kg, link2 0.5 kg) and the inertia of a solid box or cylinder of its size; every joint limit has
  effort 1000;
* ``<ros2_control>``: joint1 and joint2 with a position command interface and position, velocity and
  acceleration state interfaces; sensor ``tcp_fts_sensor`` with fx, fy, fz, tx, ty, tz and ``frame_id`` tool0;
  GPIO ``flange_gpios`` with inputs digital_in_1/2 and outputs digital_out_1/2 that can be read back;
* the ``prefix`` argument prefixes every name: links, joints, the sensor's frame, and in ``<ros2_control>`` the
  tag's own name (the hardware component), the joints, the sensor and the GPIO. The original workshop prefixed only
  links and joints, so two robots collided; the course requires the full prefix.

The checks look at behaviour (forward kinematics, parsed interfaces), not at how the files are written. Every
number is compared at the tolerance the exercise states: 1 mm for lengths and origins, 1 mrad for angles and
limits, 1 g for masses, 1 % for inertias. Forward kinematics is also tried at generated joint angles within the
limits (Hypothesis), against the formula notebook 01 writes out from the specification.
"""

from __future__ import annotations

import io
import math
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yourdfpy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.errors import HypothesisException

from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.description.info import ComponentInfo, HardwareInfo

TASK = 1
MAIN_FILE = "rrbot_description/urdf/rrbot.urdf.xacro"
MACRO_FILE = "rrbot_description/urdf/rrbot/rrbot_macro.xacro"
ROS2_CONTROL_FILE = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
TOL = 1e-3  # [m], [rad] and [kg], as the exercise states: learners may type 6.6323 instead of radians(380)
INERTIA_RTOL = 0.01  # the inertias to 1 %, as the exercise states
EFFORT = 1000.0  # [N m], every joint's <limit effort>
#: Masses [kg] and where the inertial's origin sits in the link's frame [m]: at the centre of the body.
MASSES = {"base_link": 5.0, "link1": 1.0, "link2": 0.5}
CENTRES = {"base_link": (0.0, 0.0, 0.15), "link1": (0.0, 0.0, 0.25), "link2": (0.0, 0.0, 0.3)}
#: Prefixes tried: a hard-coded "left_" passes the first, not the second.
PREFIXES = ("left_", "r2_")
#: The <ros2_control> macro instantiated with another name and prefix than rrbot.urdf.xacro gives it.
OTHER_NAME, OTHER_PREFIX = "cell_bot", "arm_"


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, MAIN_FILE)


@pytest.fixture(scope="module")
def urdf(description_file: Path) -> str:
    return process_xacro(description_file)


@pytest.fixture(scope="module")
def model(urdf: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(
        io.StringIO(urdf), build_scene_graph=True, build_collision_scene_graph=False, load_meshes=False,
        load_collision_meshes=False,
    )


@pytest.fixture(scope="module")
def hardware(urdf: str) -> HardwareInfo:
    return _one_tag(urdf, "rrbot.urdf.xacro")


@pytest.fixture(scope="module")
def prefixed_urdfs(description_file: Path) -> dict[str, str]:
    return {prefix: process_xacro(description_file, prefix=prefix) for prefix in PREFIXES}


#: A robot of its own that includes the learner's two macro files and instantiates them with other arguments than
#: rrbot.urdf.xacro does (the prefix is also given as a xacro argument, for a macro that reads $(arg prefix)).
_WRAPPER = """<?xml version="1.0"?>
<robot name="cell" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default="{prefix}"/>
  <xacro:include filename="{macro}"/>
  <xacro:include filename="{ros2_control}"/>
  <link name="world"/>
  <xacro:rrbot prefix="{prefix}" parent="world"><origin xyz="0 0 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot_ros2_control name="{name}" prefix="{prefix}"/>
</robot>
"""


@pytest.fixture(scope="module")
def renamed_urdf(task_file: Callable[[int, str], Path]) -> str:
    macro, ros2_control = task_file(TASK, MACRO_FILE), task_file(TASK, ROS2_CONTROL_FILE)
    with tempfile.TemporaryDirectory() as folder:
        wrapper = Path(folder) / "cell.urdf.xacro"
        wrapper.write_text(_WRAPPER.format(prefix=OTHER_PREFIX, name=OTHER_NAME, macro=macro, ros2_control=ros2_control))
        return process_xacro(wrapper)


# --------------------------------------------------------------------------------------------- helpers


def _link(model: yourdfpy.URDF, name: str) -> Any:
    assert name in model.link_map, (
        f"the robot of rrbot.urdf.xacro has no link '{name}' (its links: {sorted(model.link_map)}); the macro in "
        "rrbot_macro.xacro must add it (TODO 1.1)"
    )
    return model.link_map[name]


def _joint(model: yourdfpy.URDF, name: str) -> Any:
    assert name in model.joint_map, (
        f"the robot of rrbot.urdf.xacro has no joint '{name}' (its joints: {sorted(model.joint_map)}); the macro in "
        "rrbot_macro.xacro must add it (TODO 1.1)"
    )
    return model.joint_map[name]


def _frame(model: yourdfpy.URDF, link: str, q1: float = 0.0, q2: float = 0.0) -> np.ndarray:
    """World pose (4x4) of ``link`` at joint angles ``q1``, ``q2`` in [rad]."""
    _link(model, link)
    wanted = {"joint1": q1, "joint2": q2}
    for joint, angle in wanted.items():
        if angle != 0.0:
            assert _joint(model, joint).type == "revolute", f"joint '{joint}' must be revolute"
    if model.actuated_joint_names:
        model.update_cfg({name: wanted.get(name, 0.0) for name in model.actuated_joint_names})
    root = model.scene.graph.base_frame
    return np.asarray(model.get_transform(link, root))


def _joint_world(model: yourdfpy.URDF, name: str) -> tuple[np.ndarray, np.ndarray]:
    """World position [m] and unit axis of a joint at the zero configuration."""
    joint = _joint(model, name)
    pose = _frame(model, joint.child)
    axis = np.asarray(joint.axis if joint.axis is not None else [1.0, 0.0, 0.0], dtype=float)
    axis = pose[:3, :3] @ (axis / np.linalg.norm(axis))
    return pose[:3, 3], axis


def _visual_geometry(model: yourdfpy.URDF, link: str, kind: str, element: str = "visual") -> tuple[Any, np.ndarray]:
    for item in getattr(_link(model, link), f"{element}s"):
        geometry = getattr(item.geometry, kind, None)
        if geometry is not None:
            origin = item.origin if item.origin is not None else np.eye(4)
            return geometry, np.asarray(origin)
    raise AssertionError(f"in rrbot_macro.xacro link '{link}' has no <{element}> with a <{kind}> geometry")


def _box_extent(box: Any, origin: np.ndarray) -> np.ndarray:
    """The box's extent along the link frame's x, y and z [m]: where it points, not only its sorted sizes."""
    return np.abs(origin[:3, :3]) @ np.asarray(box.size, dtype=float)


def _component(items: list[ComponentInfo], name: str, what: str) -> ComponentInfo:
    """The <sensor> or <gpio> named ``name``, or ending in it (a prefix is test_prefix's rule, taken as given here)."""
    names = [c.name for c in items]
    found = [c for c in items if c.name == name] or [c for c in items if c.name.endswith(name)]
    assert found, (
        f"rrbot_macro.ros2_control.xacro makes no <{what} name='{name}'> in <ros2_control> (its {what}s: {names})"
    )
    return found[0]


def _names(interfaces: list[Any]) -> list[str]:
    return [i.name for i in interfaces]


def _close(actual: Any, expected: Any, tol: float = TOL) -> bool:
    return bool(np.allclose(np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), atol=tol))

def _r(values: Any) -> list[Any]:
    """Rounded to the millimetre (or mrad) for a message, without -0.0."""
    return (np.round(np.asarray(values, dtype=float), 3) + 0.0).tolist()


def _one_tag(urdf: str, how: str) -> HardwareInfo:
    """The one <ros2_control> tag of ``urdf`` (made by ``how``), parsed; fails clearly when there is none."""
    count = len(ET.fromstring(urdf.lstrip()).findall("ros2_control"))
    assert count == 1, (
        f"the robot of {how} has {count} <ros2_control> tags; it needs one: include "
        "rrbot/rrbot_macro.ros2_control.xacro in rrbot.urdf.xacro and instantiate its macro (TODO 1.2)"
    )
    return parse_ros2_control(urdf)[0]


def _plugins(urdf: str) -> list[str]:
    """The text of every <plugin> in the <hardware> of every <ros2_control> tag."""
    root = ET.fromstring(urdf.lstrip())
    return [(p.text or "").strip() for tag in root.findall("ros2_control") for hw in tag.findall("hardware")
            for p in hw.findall("plugin")]


# --------------------------------------------------------------------------------------------- kinematics


@graded(given=True, points=2, hint=(
    "rrbot.urdf.xacro must expand with xacro, with no arguments, into a URDF.",
    "Check the XML (every tag closed), the xacro:include paths (relative to the including file) and that every "
    "${...} names a property or macro parameter that exists.",
    "The error above names the file and the line; run rw.description.process_xacro(path) in the notebook to see it.",
))
def test_description_processes(model: yourdfpy.URDF) -> None:
    assert model.robot.links, "the URDF of rrbot.urdf.xacro has no links"


@graded(after=("test_description_processes",), points=2, hint=(
    "The chain is base_link -joint1-> link1 -joint2-> link2 -> tool0; joint1 and joint2 are revolute, tool0 hangs on "
    "link2 by a fixed joint. Two more frames hang by fixed joints: base on base_link and flange on tool0.",
    "A <joint> names its <parent link> and <child link>; an empty <link name='...'/> is a frame.",
    "<joint name='${prefix}link2-tool0' type='fixed'><parent link='${prefix}link2'/><child link='${prefix}tool0'/>"
    "...</joint> <link name='${prefix}tool0'/>, and the same for base and flange.",
))
def test_links_and_joints(model: yourdfpy.URDF) -> None:
    for link in ("base_link", "link1", "link2", "tool0", "base", "flange"):
        _link(model, link)
    chain = {j.child: j for j in model.robot.joints}
    expected = [("tool0", "link2", "fixed"), ("link2", "link1", "revolute"), ("link1", "base_link", "revolute"),
                ("base", "base_link", "fixed"), ("flange", "tool0", "fixed")]
    for child, parent, kind in expected:
        assert child in chain, f"in rrbot_macro.xacro no joint has '{child}' as its child"
        assert chain[child].parent == parent, (
            f"in rrbot_macro.xacro '{child}' hangs on '{chain[child].parent}'; the task says on '{parent}'"
        )
        assert chain[child].type == kind, (
            f"in rrbot_macro.xacro the joint above '{child}' is {chain[child].type}; the task says {kind}"
        )


@graded(after=("test_description_processes",), given=True, points=1, hint=(
    "The pedestal (base_link) is a box 0.3 x 0.3 x 0.3 m standing on the ground.",
    "Its visual's origin is half its height above the base_link frame.",
    "<origin xyz='0 0 ${pedestal_size / 2}'/> <box size='${pedestal_size} ${pedestal_size} ${pedestal_size}'/>",
))
def test_pedestal(model: yourdfpy.URDF) -> None:
    box, origin = _visual_geometry(model, "base_link", "box")
    assert _close(box.size, [0.3, 0.3, 0.3]), f"the pedestal box's size is {list(box.size)}, expected 0.3 0.3 0.3"
    pose = _frame(model, "base_link") @ origin
    assert _close(pose[2, 3], 0.15), f"the pedestal's centre is {pose[2, 3]:.3f} m above the ground, expected 0.15"


@graded(after=("test_links_and_joints",), points=2, hint=(
    "joint1 sits on top of the pedestal, 0.3 m above the ground, and turns about the vertical axis; a positive angle "
    "turns the arm counter-clockwise seen from above.",
    "A joint's <origin xyz> places it in its parent's frame; <axis xyz> is the direction it turns about (right-hand "
    "rule), in the joint's own frame.",
    "joint1: <origin xyz='0 0 ${pedestal_size}' rpy='0 0 0'/> <axis xyz='0 0 1'/>.",
))
def test_joint1_placement(model: yourdfpy.URDF) -> None:
    position, axis = _joint_world(model, "joint1")
    assert _close(position, [0, 0, 0.3]), (
        f"in rrbot_macro.xacro joint1 is at {_r(position)} m in the world; the task says [0, 0, 0.3] (top of the pedestal)"
    )
    assert _close(axis, [0, 0, 1]), (
        f"in rrbot_macro.xacro joint1 turns about {_r(axis)} in the world; the task says about the vertical axis, "
        "positive angles counter-clockwise seen from above: [0, 0, 1]"
    )


@graded(after=("test_links_and_joints",), points=1, hint=(
    "link1 is a cylinder 0.5 m long with a 0.1 m radius (0.2 m diameter), reaching from joint1 up to joint2.",
    "A <cylinder> stands along its frame's z axis and is centred on its <origin>: visual and collision both need "
    "the origin at half the length.",
    "<origin xyz='0 0 ${link1_length / 2}'/> <cylinder length='${link1_length}' radius='${link1_radius}'/>, in "
    "<visual> and in <collision>.",
))
def test_link1_shape(model: yourdfpy.URDF) -> None:
    for element in ("visual", "collision"):
        cylinder, origin = _visual_geometry(model, "link1", "cylinder", element)
        assert _close(cylinder.length, 0.5), (
            f"link1's {element} cylinder in rrbot_macro.xacro is {cylinder.length:g} m long; the task says 0.5"
        )
        assert _close(cylinder.radius, 0.1), (
            f"link1's {element} cylinder in rrbot_macro.xacro has a radius of {cylinder.radius:g} m; the task says 0.1"
        )
        assert _close(origin[:3, 3], [0, 0, 0.25]), (
            f"link1's {element} origin in rrbot_macro.xacro is at {_r(origin[:3, 3])}; it must be [0, 0, 0.25] so the "
            "cylinder spans from joint1 (z=0) to joint2 (z=0.5)"
        )
        assert _close(abs(origin[2, 2]), 1.0), f"link1's {element} cylinder must stand along the link's z axis"


@graded(after=("test_joint1_placement", "test_link1_shape"), points=2, hint=(
    "joint2 sits at the top of link1 (0.5 m above joint1, so 0.8 m above the ground) and turns about a horizontal "
    "axis, orthogonal to link1.",
    "joint2's <origin xyz> is in link1's frame; its <axis> is in joint2's own frame, after the origin's rpy.",
    "joint2: <origin xyz='0 0 ${link1_length}' rpy='0 ${-pi / 2} 0'/> <axis xyz='0 1 0'/>.",
))
def test_joint2_placement(model: yourdfpy.URDF) -> None:
    position, axis = _joint_world(model, "joint2")
    below, _ = _joint_world(model, "joint1")  # judged from joint1 as it is: joint1's own place is joint1_placement's
    assert _close(position - below, [0, 0, 0.5]), (
        f"in rrbot_macro.xacro joint2 is {_r(position - below)} m from joint1; the task says [0, 0, 0.5] (the top of "
        "link1, 0.5 m above joint1)"
    )
    assert abs(axis[2]) < TOL, f"in rrbot_macro.xacro joint2 turns about {_r(axis)} in the world, not a horizontal axis"


@graded(after=("test_links_and_joints",), points=1, hint=(
    "link2 is a box 0.6 m long with a 0.1 x 0.1 m cross-section, along its frame's z axis from joint2 (z=0) to "
    "tool0 (z=0.6): visual and collision alike.",
    "A <box size='x y z'> is centred on its <origin>: the long side goes third to lie along z, and the origin sits "
    "at half the length.",
    "<origin xyz='0 0 ${link2_length / 2}'/> <box size='${link2_width} ${link2_width} ${link2_length}'/>, in "
    "<visual> and in <collision>.",
))
def test_link2_shape(model: yourdfpy.URDF) -> None:
    for element in ("visual", "collision"):
        box, origin = _visual_geometry(model, "link2", "box", element)
        extent = _box_extent(box, origin)
        assert _close(extent, [0.1, 0.1, 0.6]), (
            f"link2's {element} box in rrbot_macro.xacro reaches {_r(extent)} m along the link's x, y, z; the task "
            "says 0.1 0.1 0.6"
        )
        assert _close(origin[:3, 3], [0, 0, 0.3]), (
            f"link2's {element} origin in rrbot_macro.xacro is at {_r(origin[:3, 3])}; it must be [0, 0, 0.3] so the "
            "box spans from joint2 (z=0) to its tip (z=0.6)"
        )


@graded(after=("test_joint2_placement", "test_link2_shape"), points=3, hint=(
    "tool0 is at the tip of link2, 0.6 m from joint2. At zero link2 is horizontal (tool0 0.8 m high, 0.6 m from the "
    "vertical axis); at joint2=+90 deg it points straight up (tool0 at 0 0 1.4); joint1 swings it around the vertical "
    "axis.",
    "A joint's <origin rpy> turns the child frame before the joint moves it; link2's box runs along its own z axis, so "
    "joint2's origin must turn z from vertical to horizontal (a pitch) and joint2 must turn about the axis that lifts "
    "it (y after that turn).",
    "joint2: <origin xyz='0 0 ${link1_length}' rpy='0 ${-pi / 2} 0'/> <axis xyz='0 1 0'/>; the link2-tool0 joint: "
    "<origin xyz='0 0 ${link2_length}' .../>.",
))
def test_tool0_at_tip(model: yourdfpy.URDF) -> None:
    # Judged from joint2 as it is (joint2's own place is joint2_placement's rule): link2 reaches 0.6 m from it.
    joint2, _ = _joint_world(model, "joint2")
    home = _frame(model, "tool0")[:3, 3] - joint2
    assert _close(home[2], 0.0), (
        f"at zero tool0 is {home[2]:.3f} m above joint2; the task says level with it (link2 horizontal)"
    )
    assert _close(math.hypot(home[0], home[1]), 0.6), (
        f"at zero tool0 is {math.hypot(home[0], home[1]):.3f} m from joint2; the task says 0.6 (link2's length)"
    )
    up = _frame(model, "tool0", 0.0, math.pi / 2)[:3, 3] - joint2
    assert _close(up, [0, 0, 0.6]), (
        f"at joint2=+90 deg tool0 is at {_r(up)} from joint2; the task says [0, 0, 0.6] (link2 straight up)"
    )
    down = _frame(model, "tool0", 0.0, -math.pi / 2)[:3, 3] - joint2
    assert _close(down, [0, 0, -0.6]), (
        f"at joint2=-90 deg tool0 is at {_r(down)} from joint2; expected [0, 0, -0.6] (link2 hanging straight down)"
    )
    turned = _frame(model, "tool0", math.pi / 2, 0.0)[:3, 3] - joint2
    assert _close(turned[2], 0.0) and _close(float(np.dot(turned[:2], home[:2])), 0.0), (
        f"at joint1=+90 deg tool0 is at {_r(turned)} from joint2's place at zero: joint1 must swing it about the "
        "vertical axis"
    )


@graded(after=("test_links_and_joints", "test_tool0_at_tip"), points=2, hint=(
    "tool0 is turned as in the original workshop: its z axis points back along link2 towards joint2 and its x axis "
    "along joint2's axis; the force-torque sensor reports along these axes.",
    "Only the link2-tool0 joint's <origin rpy> turns tool0 (roll, pitch, yaw about x, y, z, in radians). Starting "
    "from link2's frame (z out along the link), z must flip to point back (a half turn) and x must end on joint2's "
    "axis (a quarter turn about the new z).",
    "link2-tool0: <origin xyz='0 0 0.6' rpy='0 ${-pi} ${-pi / 2}'/>; flange and base hang on tool0 and base_link with "
    "a zero origin.",
))
def test_tool0_orientation(model: yourdfpy.URDF) -> None:
    tool0 = _frame(model, "tool0")
    joint2, _ = _joint_world(model, "joint2")
    along = tool0[:3, 3] - joint2
    assert np.linalg.norm(along) > TOL, "tool0 must be at the tip of link2, away from joint2"
    along /= np.linalg.norm(along)                      # from joint2 out to the tip, at zero: horizontal
    lift_axis = np.cross(along, [0.0, 0.0, 1.0])        # the joint2 axis about which a positive angle lifts link2
    x_axis, z_axis = tool0[:3, 0], tool0[:3, 2]
    assert _close(z_axis, -along), (
        f"at zero tool0's z axis is {_r(z_axis)} in the world; the task says {_r(-along)} (back along link2, towards "
        "joint2)"
    )
    assert _close(x_axis, lift_axis), (
        f"at zero tool0's x axis is {_r(x_axis)} in the world; the task says {_r(lift_axis)} (along joint2's axis)"
    )
    for frame, on in (("flange", "tool0"), ("base", "base_link")):
        assert _close(_frame(model, frame), _frame(model, on)), (
            f"in rrbot_macro.xacro {frame} does not coincide with {on}: its fixed joint needs a zero origin"
        )


def _by_hand(q1: float, q2: float) -> np.ndarray:
    """tool0's world pose from the specification, as notebook 01 writes it out."""

    def trans(z: float) -> np.ndarray:
        out = np.eye(4)
        out[2, 3] = z
        return out

    def rot_y(a: float) -> np.ndarray:
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])

    def rot_z(a: float) -> np.ndarray:
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])

    return (trans(0.3) @ rot_z(q1) @ trans(0.5) @ rot_y(-math.pi / 2) @ rot_y(q2)
            @ trans(0.6) @ rot_z(-math.pi / 2) @ rot_y(-math.pi))


@graded(after=(
    "test_joint1_placement", "test_joint2_placement", "test_tool0_at_tip", "test_tool0_orientation",
), points=1, hint=(
    "For every pair of joint angles within the limits, tool0 must be where (and turned as) the specification puts "
    "it: the formula of notebook 01's forward-kinematics cell.",
    "Compare your URDF's tool0 with the notebook's tool0_by_hand(q1, q2) at the angles this check names; the "
    "joint origins, axes and the link2-tool0 rpy decide it.",
    "joint1: origin 0 0 0.3, axis 0 0 1; joint2: origin 0 0 0.5 rpy 0 -pi/2 0, axis 0 1 0; link2-tool0: origin "
    "0 0 0.6 rpy 0 -pi -pi/2.",
))
def test_tool0_everywhere_in_the_workspace(model: yourdfpy.URDF) -> None:
    _joint(model, "joint1"), _joint(model, "joint2"), _link(model, "tool0")
    found: list[str] = []

    @settings(derandomize=True, database=None, deadline=None, max_examples=25,
              suppress_health_check=list(HealthCheck))
    @given(q1=st.floats(math.radians(-380), math.radians(380)), q2=st.floats(math.radians(-60), math.radians(240)))
    def same_pose(q1: float, q2: float) -> None:
        mine, spec = _frame(model, "tool0", q1, q2), _by_hand(q1, q2)
        if not np.allclose(mine[:3, 3], spec[:3, 3], atol=TOL):
            found[:] = [f"at joint1={math.degrees(q1):.1f} deg, joint2={math.degrees(q2):.1f} deg your tool0 is at "
                        f"{_r(mine[:3, 3])} m; the specification puts it at {_r(spec[:3, 3])} m"]
            raise AssertionError(found[0])
        if not np.allclose(mine[:3, :3], spec[:3, :3], atol=TOL):
            found[:] = [f"at joint1={math.degrees(q1):.1f} deg, joint2={math.degrees(q2):.1f} deg your tool0 is in "
                        f"place but turned differently: its x, y, z axes are {_r(mine[:3, :3].T)} in the world; the "
                        f"specification's are {_r(spec[:3, :3].T)}"]
            raise AssertionError(found[0])

    try:
        same_pose()
    except (AssertionError, HypothesisException):
        raise AssertionError(found[0] if found else "tool0's pose could not be computed at generated joint angles") from None


# --------------------------------------------------------------------------------------------- limits, inertia


def _check_limits(model: yourdfpy.URDF, name: str, lower_deg: float, upper_deg: float) -> None:
    limit = _joint(model, name).limit
    assert limit is not None, f"in rrbot_macro.xacro joint '{name}' has no <limit>"
    for what, value, deg in (("lower", limit.lower, lower_deg), ("upper", limit.upper, upper_deg)):
        assert value is not None and _close(value, math.radians(deg)), (
            f"in rrbot_macro.xacro {name}'s {what} limit is {value} rad; the task says radians({deg:g}) = "
            f"{math.radians(deg):.4f} rad (to 1 mrad)"
        )
    assert limit.velocity is not None and _close(limit.velocity, math.radians(180)), (
        f"in rrbot_macro.xacro {name}'s velocity limit is {limit.velocity} rad/s; the task says radians(180) = "
        f"{math.pi:.4f} rad/s"
    )
    assert limit.effort is not None and _close(limit.effort, EFFORT), (
        f"in rrbot_macro.xacro {name}'s effort limit is {limit.effort}; the task says {EFFORT:g}"
    )


@graded(after=("test_links_and_joints",), points=2, hint=(
    "joint1 turns from -380 to +380 degrees at up to 180 deg/s, effort 1000 (the workshop's RRBot).",
    "A revolute joint's range goes in its <limit lower upper velocity effort> tag, in rad and rad/s; xacro can "
    "convert with ${radians(...)}.",
    "joint1: <limit lower='${radians(-380)}' upper='${radians(380)}' velocity='${radians(180)}' effort='1000.0'/>.",
))
def test_joint1_limits(model: yourdfpy.URDF) -> None:
    _check_limits(model, "joint1", -380, 380)


@graded(after=("test_links_and_joints",), points=2, hint=(
    "joint2 turns from -60 to +240 degrees at up to 180 deg/s, effort 1000.",
    "As for joint1: a <limit> tag in rad and rad/s; ${radians(...)} converts degrees.",
    "joint2: <limit lower='${radians(-60)}' upper='${radians(240)}' velocity='${radians(180)}' effort='1000.0'/>.",
))
def test_joint2_limits(model: yourdfpy.URDF) -> None:
    _check_limits(model, "joint2", -60, 240)


def _inertial(model: yourdfpy.URDF, name: str) -> Any:
    inertial = _link(model, name).inertial
    assert inertial is not None, f"in rrbot_macro.xacro link '{name}' has no <inertial>"
    return inertial


@graded(after=("test_links_and_joints",), points=2, hint=(
    "The masses the task states: pedestal (base_link) 5.0 kg, link1 1.0 kg, link2 0.5 kg.",
    "A link's mass is <inertial><mass value='...'/>; keep each number in one xacro:property.",
    "<xacro:property name='link1_mass' value='1.0'/> <xacro:property name='link2_mass' value='0.5'/>, passed as "
    "mass='${link1_mass}' to cylinder_inertial and mass='${link2_mass}' to box_inertial.",
))
def test_masses(model: yourdfpy.URDF) -> None:
    for name, expected in MASSES.items():
        mass = _inertial(model, name).mass
        assert mass is not None and _close(mass, expected), (
            f"in rrbot_macro.xacro {name}'s mass is {mass} kg; the task says {expected:g} kg (to 1 g)"
        )


@graded(after=("test_links_and_joints",), points=1, hint=(
    "A body's inertial sits at its centre of mass: the middle of the box or cylinder, where its visual's origin is.",
    "The <inertial>'s <origin> is relative to the link's frame, like the visual's; the inertial macros insert the "
    "<origin> block you pass them.",
    "<xacro:cylinder_inertial ...><origin xyz='0 0 ${link1_length / 2}' rpy='0 0 0'/></xacro:cylinder_inertial>, "
    "and z='${link2_length / 2}' for link2's box_inertial.",
))
def test_inertial_origins(model: yourdfpy.URDF) -> None:
    for name, stated in CENTRES.items():
        origin = _inertial(model, name).origin
        origin = np.eye(4) if origin is None else np.asarray(origin)
        centre = stated
        try:  # the body's centre is where its visual is (the visual's own place is the shape checks' rule)
            _, visual = _visual_geometry(model, name, "box" if name != "link1" else "cylinder")
            centre = tuple(visual[:3, 3])
        except AssertionError:
            pass
        assert _close(origin[:3, 3], centre) or _close(origin[:3, 3], stated), (
            f"in rrbot_macro.xacro {name}'s <inertial> origin is at {_r(origin[:3, 3])} m in its frame; its body's "
            f"centre (its visual's origin) is at {_r(centre)} (to 1 mm)"
        )


def _solid(model: yourdfpy.URDF, name: str, as_stated: bool = False) -> tuple[np.ndarray, str]:
    """The inertia [kg m^2] of a solid body of the link's shape, about its centre, in the link's axes; and the body in
    words. Its size and mass are the learner's own (the visual's geometry, the inertial's mass), taken as given: the
    shape and mass checks judge those. ``as_stated``: the size the task states, with the learner's mass."""
    mass = _inertial(model, name).mass
    m = float(mass) if mass is not None else MASSES[name]
    if name == "link1":
        try:
            if as_stated:
                raise AssertionError
            cylinder, _ = _visual_geometry(model, name, "cylinder")
            r, h = float(cylinder.radius), float(cylinder.length)
        except AssertionError:
            r, h = 0.1, 0.5
        side = m / 12.0 * (3 * r * r + h * h)
        return np.diag([side, side, m / 2.0 * r * r]), f"a cylinder of {m:g} kg, {r:g} m radius and {h:g} m long"
    try:
        if as_stated:
            raise AssertionError
        box, origin = _visual_geometry(model, name, "box")
        x, y, z = _box_extent(box, origin)
    except AssertionError:
        x, y, z = (0.3, 0.3, 0.3) if name == "base_link" else (0.1, 0.1, 0.6)
    inertia = np.diag([m / 12.0 * (y * y + z * z), m / 12.0 * (x * x + z * z), m / 12.0 * (x * x + y * y)])
    return inertia, f"a box of {m:g} kg, {x:g} x {y:g} x {z:g} m along the link's x, y, z"


@graded(after=("test_masses", "test_link1_shape", "test_link2_shape", "test_pedestal"), points=1, hint=(
    "Each link's inertia is that of a solid body of its shape, size and mass: a box for base_link and link2, a "
    "cylinder for link1.",
    "Use the given macros: box_inertial(mass, x, y, z) and cylinder_inertial(mass, radius, length), with the sizes "
    "of the link's visual, in the same axes (link2's long side along z).",
    "<xacro:box_inertial mass='${link2_mass}' x='${link2_width}' y='${link2_width}' z='${link2_length}'>"
    "<origin .../></xacro:box_inertial>.",
))
def test_inertias(model: yourdfpy.URDF) -> None:
    for name in MASSES:
        inertial = _inertial(model, name)
        origin = np.eye(4) if inertial.origin is None else np.asarray(inertial.origin)
        inertia = origin[:3, :3] @ np.asarray(inertial.inertia, dtype=float) @ origin[:3, :3].T  # in the link's axes
        expected, body = _solid(model, name)
        stated, _ = _solid(model, name, as_stated=True)  # a visual of the wrong size or turn is the shape's rule
        assert any(np.allclose(inertia, e, rtol=INERTIA_RTOL, atol=INERTIA_RTOL * float(np.max(e)))
                   for e in (expected, stated)), (
            f"in rrbot_macro.xacro {name}'s inertia diagonal is {np.round(np.diag(inertia), 5).tolist()} kg m^2; "
            f"{body} (its visual and its mass) has {np.round(np.diag(expected), 5).tolist()} (to 1 %)"
        )


# --------------------------------------------------------------------------------------------- <ros2_control>


@graded(after=("test_description_processes",), points=1, hint=(
    "rrbot.urdf.xacro instantiates the macro of rrbot_macro.ros2_control.xacro, so the URDF has one "
    "<ros2_control name='rrbot' type='system'> tag with one <plugin> in its <hardware>.",
    "Include the macro file next to the other include, then call the macro with name='rrbot' and the prefix; a "
    "<hardware> block holds exactly one <plugin> (Jazzy's parser would silently take the first of several).",
    "<xacro:include filename='rrbot/rrbot_macro.ros2_control.xacro'/> ... "
    "<xacro:rrbot_ros2_control name='rrbot' prefix='$(arg prefix)'/>.",
))
def test_ros2_control_tag(urdf: str, hardware: HardwareInfo) -> None:
    assert hardware.name == "rrbot", f"the <ros2_control> tag is named '{hardware.name}'; the task says 'rrbot'"
    assert hardware.type == "system", f"the <ros2_control> type is '{hardware.type}'; the task says 'system'"
    plugins = _plugins(urdf)
    assert len(plugins) == 1, (
        f"<hardware> in rrbot_macro.ros2_control.xacro holds {len(plugins)} <plugin> tags ({', '.join(plugins)}); it "
        "takes exactly one (Jazzy's parser would silently use the first)"
    )


@graded(after=("test_ros2_control_tag", "test_prefix"), points=1, hint=(
    "The macro's name parameter names the hardware component, with the prefix in front: a macro instantiated "
    f"with name='{OTHER_NAME}' prefix='{OTHER_PREFIX}' makes <ros2_control name='{OTHER_PREFIX}{OTHER_NAME}'>.",
    "In rrbot_macro.ros2_control.xacro use the macro's parameters ${name} and ${prefix}, not fixed text.",
    "<ros2_control name='${prefix}${name}' type='system'>.",
))
def test_ros2_control_macro_name(renamed_urdf: str) -> None:
    hardware = _one_tag(renamed_urdf, f"<xacro:rrbot_ros2_control name='{OTHER_NAME}' prefix='{OTHER_PREFIX}'/>")
    assert hardware.name == OTHER_PREFIX + OTHER_NAME, (
        f"<xacro:rrbot_ros2_control name='{OTHER_NAME}' prefix='{OTHER_PREFIX}'/> makes a <ros2_control> tag named "
        f"'{hardware.name}'; expected '{OTHER_PREFIX}{OTHER_NAME}' (the prefix, then the macro's name parameter)"
    )


@graded(after=("test_ros2_control_tag",), points=3, hint=(
    "Each of joint1 and joint2 is commanded in position and reports position, velocity and acceleration.",
    "Under <ros2_control>, one <joint name='${prefix}jointN'> per joint, with one <command_interface> and three "
    "<state_interface> tags, each interface once.",
    "<joint name='${prefix}joint1'><command_interface name='position'/><state_interface name='position'/>"
    "<state_interface name='velocity'/><state_interface name='acceleration'/></joint>, and the same for joint2.",
))
def test_joint_interfaces(hardware: HardwareInfo) -> None:
    joints = [j.name for j in hardware.joints]
    assert joints == ["joint1", "joint2"], f"the <ros2_control> joints are {joints}; the task says ['joint1', 'joint2']"
    for joint in hardware.joints:
        assert _names(joint.command_interfaces) == ["position"], (
            f"{joint.name}'s command interfaces are {_names(joint.command_interfaces)}; the task says ['position']"
        )
        states = _names(joint.state_interfaces)
        assert sorted(states) == ["acceleration", "position", "velocity"], (
            f"{joint.name}'s state interfaces are {states}; the task says position, velocity and acceleration, once each"
        )


@graded(after=("test_ros2_control_tag",), points=2, hint=(
    "The force-torque sensor tcp_fts_sensor reports six values, fx fy fz tx ty tz, in the frame tool0.",
    "A <sensor> has only state interfaces, and a <param name='frame_id'> naming the frame its values are in.",
    "<sensor name='${prefix}tcp_fts_sensor'><state_interface name='fx'/> ... <state_interface name='tz'/>"
    "<param name='frame_id'>${prefix}tool0</param></sensor>.",
))
def test_fts_sensor(hardware: HardwareInfo) -> None:
    sensor = _component(hardware.sensors, "tcp_fts_sensor", "sensor")
    states = _names(sensor.state_interfaces)
    assert sorted(states) == sorted(["fx", "fy", "fz", "tx", "ty", "tz"]), (
        f"tcp_fts_sensor's state interfaces are {states}; the task says fx fy fz tx ty tz, once each"
    )
    assert not sensor.command_interfaces, (
        f"tcp_fts_sensor has command interfaces {_names(sensor.command_interfaces)}; a sensor has none"
    )
    assert sensor.parameters.get("frame_id") == "tool0", (
        f"tcp_fts_sensor's frame_id is {sensor.parameters.get('frame_id')!r}; the task says 'tool0'"
    )


@graded(after=("test_ros2_control_tag",), points=1, hint=(
    "flange_gpios has two digital inputs, digital_in_1 and digital_in_2, which can only be read.",
    "An input is a <state_interface> of the <gpio>, with no <command_interface> of the same name.",
    "<gpio name='${prefix}flange_gpios'> ... <state_interface name='digital_in_1'/>"
    "<state_interface name='digital_in_2'/></gpio>.",
))
def test_gpio_inputs(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    states, commands = _names(gpio.state_interfaces), _names(gpio.command_interfaces)
    for name in ("digital_in_1", "digital_in_2"):
        assert states.count(name) == 1, f"flange_gpios must have one state interface '{name}' (it has: {states})"
        assert name not in commands, f"'{name}' of flange_gpios is an input: it must not be a command interface"


@graded(after=("test_ros2_control_tag",), points=2, hint=(
    "flange_gpios has two digital outputs, digital_out_1 and digital_out_2.",
    "An output is a <command_interface> of the <gpio>.",
    "<command_interface name='digital_out_1'/> and <command_interface name='digital_out_2'/> in "
    "<gpio name='${prefix}flange_gpios'>.",
))
def test_gpio_outputs(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    commands = [c for c in _names(gpio.command_interfaces) if not c.startswith("digital_in_")]  # gpio_inputs' rule
    assert sorted(commands) == ["digital_out_1", "digital_out_2"], (
        f"flange_gpios's command interfaces are {commands}; the task says digital_out_1 and digital_out_2, once each"
    )


@graded(after=("test_gpio_outputs",), points=1, hint=(
    "The outputs can be read back: a controller can see what the device really set.",
    "Next to each output's <command_interface>, give flange_gpios a <state_interface> of the same name.",
    "<command_interface name='digital_out_1'/><state_interface name='digital_out_1'/>, and the same for "
    "digital_out_2.",
))
def test_gpio_output_readback(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    states = _names(gpio.state_interfaces)
    for name in ("digital_out_1", "digital_out_2"):
        assert states.count(name) == 1, (
            f"flange_gpios must have one state interface '{name}' to read the output back (it has: {states})"
        )


@graded(after=("test_ros2_control_tag",), points=3, hint=(
    "With prefix:=left_ every name starts with left_: every link (except world) and joint; in <ros2_control> the "
    "tag itself (left_rrbot), the joints left_joint1 and left_joint2, the sensor left_tcp_fts_sensor with frame_id "
    "left_tool0, and the GPIO left_flange_gpios. Any other prefix works the same way.",
    "Put ${prefix} in front of every name attribute in both macros, and of the frame_id value.",
    "<ros2_control name='${prefix}${name}' ...>, <joint name='${prefix}joint1'>, <sensor "
    "name='${prefix}tcp_fts_sensor'>, <param name='frame_id'>${prefix}tool0</param>, <gpio "
    "name='${prefix}flange_gpios'>.",
))
def test_prefix(prefixed_urdfs: dict[str, str]) -> None:
    for prefix, urdf in prefixed_urdfs.items():
        _check_prefixed(prefix, urdf)


def _check_prefixed(prefix: str, urdf: str) -> None:
    model = yourdfpy.URDF.load(io.StringIO(urdf), build_scene_graph=False, load_meshes=False,
                               load_collision_meshes=False)
    links = [link.name for link in model.robot.links if link.name != "world"]
    joints = [joint.name for joint in model.robot.joints]
    unprefixed = [n for n in links + joints if not n.startswith(prefix)]
    assert links and not unprefixed, f"with prefix:={prefix} these links and joints do not start with it: {unprefixed}"
    hardware = _one_tag(urdf, f"rrbot.urdf.xacro with prefix:={prefix}")
    assert hardware.name == f"{prefix}rrbot", (
        f"with prefix:={prefix} the <ros2_control> tag is named {hardware.name!r}; expected '{prefix}rrbot': two "
        "robots in one system need two hardware component names"
    )
    # Every element the tag has must carry the prefix; which elements it has is the other checks' rule.
    for kind, items in (("joint", hardware.joints), ("sensor", hardware.sensors), ("gpio", hardware.gpios)):
        unprefixed = [i.name for i in items if not i.name.startswith(prefix)]
        assert not unprefixed, (
            f"with prefix:={prefix} the <{kind}> {unprefixed[0]!r} of <ros2_control> does not start with it: two robots "
            f"in one system would both export '{unprefixed[0]}/...'"
        )
    for sensor in hardware.sensors:
        frame = sensor.parameters.get("frame_id")
        assert frame is None or frame.startswith(prefix), (
            f"with prefix:={prefix} the frame_id of {sensor.name} is {frame!r}: the frame is '{prefix}tool0'"
        )
