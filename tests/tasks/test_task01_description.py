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
* every link with a body has an inertia;
* ``<ros2_control>``: joint1 and joint2 with a position command interface and position, velocity and
  acceleration state interfaces; sensor ``tcp_fts_sensor`` with fx, fy, fz, tx, ty, tz and ``frame_id`` tool0;
  GPIO ``flange_gpios`` with inputs digital_in_1/2 and outputs digital_out_1/2 that can be read back;
* the ``prefix`` argument prefixes every name: links, joints, the sensor's frame, and in ``<ros2_control>`` the
  tag's own name (the hardware component), the joints, the sensor and the GPIO. The original workshop prefixed only
  links and joints, so two robots collided; the course requires the full prefix.

The checks look at behaviour (forward kinematics, parsed interfaces), not at how the files are written.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yourdfpy

from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.description.info import ComponentInfo, HardwareInfo

TASK = 1
MAIN_FILE = "rrbot_description/urdf/rrbot.urdf.xacro"
TOL = 1e-3  # [m] and [rad]: learners may type 6.6323 instead of radians(380)


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
    infos = parse_ros2_control(urdf)
    assert len(infos) == 1, f"expected one <ros2_control> tag, found {len(infos)}"
    return infos[0]


@pytest.fixture(scope="module")
def prefixed_urdf(description_file: Path) -> str:
    return process_xacro(description_file, prefix="left_")


# --------------------------------------------------------------------------------------------- helpers


def _link(model: yourdfpy.URDF, name: str) -> Any:
    assert name in model.link_map, f"no link '{name}' (links: {sorted(model.link_map)})"
    return model.link_map[name]


def _joint(model: yourdfpy.URDF, name: str) -> Any:
    assert name in model.joint_map, f"no joint '{name}' (joints: {sorted(model.joint_map)})"
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
    raise AssertionError(f"link '{link}' has no <{element}> with a <{kind}> geometry")


def _box_extent(box: Any, origin: np.ndarray) -> np.ndarray:
    """The box's extent along the link frame's x, y and z [m]: where it points, not only its sorted sizes."""
    return np.abs(origin[:3, :3]) @ np.asarray(box.size, dtype=float)


def _component(items: list[ComponentInfo], name: str, what: str) -> ComponentInfo:
    names = [c.name for c in items]
    assert name in names, f"no <{what} name='{name}'> in <ros2_control> (found: {names})"
    return items[names.index(name)]


def _names(interfaces: list[Any]) -> list[str]:
    return [i.name for i in interfaces]


def _close(actual: Any, expected: Any, tol: float = TOL) -> bool:
    return bool(np.allclose(np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), atol=tol))


# --------------------------------------------------------------------------------------------- kinematics


@graded(given=True, points=2, hint="rrbot.urdf.xacro must expand with xacro, with no arguments, into a URDF: check the XML, "
        "the xacro:include paths (relative to the including file) and that the macros are instantiated.")
def test_description_processes(model: yourdfpy.URDF) -> None:
    assert model.robot.links, "the URDF has no links"


@graded(points=2, hint="The chain is base_link -joint1-> link1 -joint2-> link2 -> tool0; joint1 and joint2 are "
        "revolute, tool0 hangs on link2 by a fixed joint. Two more frames hang by fixed joints: base on base_link "
        "and flange on tool0.")
def test_links_and_joints(model: yourdfpy.URDF) -> None:
    for link in ("base_link", "link1", "link2", "tool0", "base", "flange"):
        _link(model, link)
    chain = {j.child: j for j in model.robot.joints}
    expected = [("tool0", "link2", "fixed"), ("link2", "link1", "revolute"), ("link1", "base_link", "revolute"),
                ("base", "base_link", "fixed"), ("flange", "tool0", "fixed")]
    for child, parent, kind in expected:
        assert child in chain, f"no joint has '{child}' as its child"
        assert chain[child].parent == parent, f"'{child}' must hang on '{parent}', not '{chain[child].parent}'"
        assert chain[child].type == kind, f"the joint above '{child}' must be {kind}, not {chain[child].type}"


@graded(given=True, points=1, hint="The pedestal (base_link) is a box 0.3 x 0.3 x 0.3 m standing on the ground: its visual's "
        "origin is half its height (0.15 m) above the base_link frame.")
def test_pedestal(model: yourdfpy.URDF) -> None:
    box, origin = _visual_geometry(model, "base_link", "box")
    assert _close(box.size, [0.3, 0.3, 0.3]), f"pedestal box size is {list(box.size)}, expected 0.3 0.3 0.3"
    pose = _frame(model, "base_link") @ origin
    assert _close(pose[2, 3], 0.15), f"the pedestal's centre is {pose[2, 3]:.3f} m above the ground, expected 0.15"


@graded(points=2, hint="joint1 sits on top of the pedestal, 0.3 m above the ground, and turns about the vertical "
        "axis: origin xyz='0 0 0.3', axis xyz='0 0 1'.")
def test_joint1_placement(model: yourdfpy.URDF) -> None:
    position, axis = _joint_world(model, "joint1")
    assert _close(position, [0, 0, 0.3]), f"joint1 is at {np.round(position, 3).tolist()}, expected [0, 0, 0.3]"
    assert _close(abs(axis[2]), 1.0), f"joint1's axis is {np.round(axis, 3).tolist()} in the world, not vertical"


@graded(points=1, hint="link1 is a cylinder 0.5 m long with a 0.1 m radius (0.2 m diameter), reaching from joint1 "
        "up to joint2: its visual origin is at z=0.25.")
def test_link1_shape(model: yourdfpy.URDF) -> None:
    for element in ("visual", "collision"):
        cylinder, origin = _visual_geometry(model, "link1", "cylinder", element)
        assert _close(cylinder.length, 0.5), f"link1 {element} cylinder is {cylinder.length} m long, expected 0.5"
        assert _close(cylinder.radius, 0.1), f"link1 {element} cylinder radius is {cylinder.radius} m, expected 0.1"
        assert _close(origin[:3, 3], [0, 0, 0.25]), f"link1's {element} must span from joint1 (z=0) to joint2 (z=0.5)"
        assert _close(abs(origin[2, 2]), 1.0), f"link1's {element} cylinder must stand along the link's z axis"


@graded(points=2, hint="joint2 sits at the top of link1 (0.5 m above joint1, so 0.8 m above the ground) and turns "
        "about a horizontal axis, orthogonal to link1.")
def test_joint2_placement(model: yourdfpy.URDF) -> None:
    position, axis = _joint_world(model, "joint2")
    assert _close(position, [0, 0, 0.8]), f"joint2 is at {np.round(position, 3).tolist()}, expected [0, 0, 0.8]"
    assert abs(axis[2]) < TOL, f"joint2's axis is {np.round(axis, 3).tolist()} in the world, not horizontal"


@graded(points=1, hint="link2 is a box 0.6 m long with a 0.1 x 0.1 m cross-section, along its frame's z axis from "
        "joint2 (z=0) to tool0 (z=0.6): visual and collision alike.")
def test_link2_shape(model: yourdfpy.URDF) -> None:
    for element in ("visual", "collision"):
        box, origin = _visual_geometry(model, "link2", "box", element)
        extent = _box_extent(box, origin)
        assert _close(extent, [0.1, 0.1, 0.6]), (
            f"link2's {element} box reaches {np.round(extent, 3).tolist()} m along the link's x, y, z; expected 0.1 0.1 0.6"
        )
        assert _close(origin[:3, 3], [0, 0, 0.3]), f"link2's {element} box must span from joint2 (z=0) to its tip (z=0.6)"


@graded(points=3, hint=(
    "tool0 is at the tip of link2, 0.6 m from joint2. At zero link2 is horizontal (tool0 0.8 m high, 0.6 m from the "
    "vertical axis); at joint2=+90 deg it points straight up (tool0 at 0 0 1.4); joint1 swings it around the vertical "
    "axis.",
    "A joint's <origin rpy> turns the child frame before the joint moves it; link2's box runs along its own z axis, so "
    "joint2's origin must turn z from vertical to horizontal (a pitch) and joint2 must turn about the axis that lifts "
    "it (y after that turn).",
    "joint2: <origin xyz='0 0 ${link1_length}' rpy='0 ${-pi / 2} 0'/> <axis xyz='0 1 0'/>; the link2-tool0 joint: <origin "
    "xyz='0 0 0.6'/>.",
))
def test_tool0_at_tip(model: yourdfpy.URDF) -> None:
    home = _frame(model, "tool0")[:3, 3]
    assert _close(home[2], 0.8), f"at zero tool0 is {home[2]:.3f} m high, expected 0.8 (link2 horizontal)"
    assert _close(math.hypot(home[0], home[1]), 0.6), (
        f"at zero tool0 is {math.hypot(home[0], home[1]):.3f} m from the vertical axis, expected 0.6"
    )
    up = _frame(model, "tool0", 0.0, math.pi / 2)[:3, 3]
    assert _close(up, [0, 0, 1.4]), f"at joint2=+90 deg tool0 is at {np.round(up, 3).tolist()}, expected [0, 0, 1.4]"
    turned = _frame(model, "tool0", math.pi / 2, 0.0)[:3, 3]
    assert _close(turned[2], 0.8) and _close(float(np.dot(turned[:2], home[:2])), 0.0), (
        f"at joint1=+90 deg tool0 is at {np.round(turned, 3).tolist()}: joint1 must swing it about the vertical axis"
    )


@graded(points=2, hint=(
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
        f"at zero tool0's z axis is {np.round(z_axis, 3).tolist()} in the world, expected "
        f"{np.round(-along, 3).tolist()} (back along link2, towards joint2)"
    )
    assert _close(x_axis, lift_axis), (
        f"at zero tool0's x axis is {np.round(x_axis, 3).tolist()} in the world, expected "
        f"{np.round(lift_axis, 3).tolist()} (along joint2's axis)"
    )
    for frame, on in (("flange", "tool0"), ("base", "base_link")):
        assert _close(_frame(model, frame), _frame(model, on)), f"{frame} must coincide with {on} (a zero origin)"


# --------------------------------------------------------------------------------------------- limits, inertia


def _check_limits(model: yourdfpy.URDF, name: str, lower_deg: float, upper_deg: float) -> None:
    limit = _joint(model, name).limit
    assert limit is not None, f"joint '{name}' has no <limit>"
    assert limit.lower is not None and _close(limit.lower, math.radians(lower_deg)), (
        f"{name} lower limit is {limit.lower} rad, expected radians({lower_deg:g}) = {math.radians(lower_deg):.4f}"
    )
    assert limit.upper is not None and _close(limit.upper, math.radians(upper_deg)), (
        f"{name} upper limit is {limit.upper} rad, expected radians({upper_deg:g}) = {math.radians(upper_deg):.4f}"
    )
    assert limit.velocity is not None and _close(limit.velocity, math.radians(180)), (
        f"{name} velocity limit is {limit.velocity} rad/s, expected radians(180) = {math.pi:.4f}"
    )


@graded(points=2, hint=(
    "joint1 turns from -380 to +380 degrees at up to 180 deg/s (the workshop's RRBot).",
    "A revolute joint's range goes in its <limit lower upper velocity effort> tag, in rad and rad/s; xacro can "
    "convert with ${radians(...)}.",
    "joint1: <limit lower='${radians(-380)}' upper='${radians(380)}' velocity='${radians(180)}' effort='...'/>.",
))
def test_joint1_limits(model: yourdfpy.URDF) -> None:
    _check_limits(model, "joint1", -380, 380)


@graded(points=2, hint=(
    "joint2 turns from -60 to +240 degrees at up to 180 deg/s.",
    "As for joint1: a <limit> tag in rad and rad/s; ${radians(...)} converts degrees.",
    "joint2: <limit lower='${radians(-60)}' upper='${radians(240)}' velocity='${radians(180)}' effort='...'/>.",
))
def test_joint2_limits(model: yourdfpy.URDF) -> None:
    _check_limits(model, "joint2", -60, 240)


@graded(points=2, hint="base_link, link1 and link2 each need an <inertial> with a positive mass and a positive "
        "definite inertia (simulators and dynamics need it); the solid box and cylinder formulas give one.")
def test_inertias(model: yourdfpy.URDF) -> None:
    for name in ("base_link", "link1", "link2"):
        inertial = _link(model, name).inertial
        assert inertial is not None, f"link '{name}' has no <inertial>"
        assert inertial.mass is not None and inertial.mass > 0, f"link '{name}' mass must be > 0"
        inertia = np.asarray(inertial.inertia, dtype=float)
        assert inertia.shape == (3, 3) and np.all(np.linalg.eigvalsh(inertia) > 0), (
            f"link '{name}' inertia {inertia.round(6).tolist()} is not positive definite"
        )


# --------------------------------------------------------------------------------------------- <ros2_control>


@graded(points=1, hint="Add one <ros2_control name='${prefix}${name}' type='system'> tag (instantiate the macro "
        "of rrbot_macro.ros2_control.xacro in rrbot.urdf.xacro with name='rrbot'; with no prefix it is 'rrbot').")
def test_ros2_control_tag(hardware: HardwareInfo) -> None:
    assert hardware.name == "rrbot", f"the <ros2_control> tag is named '{hardware.name}', expected 'rrbot'"
    assert hardware.type == "system", f"the <ros2_control> type is '{hardware.type}', expected 'system'"


@graded(points=3, hint="Each of joint1 and joint2 has <command_interface name='position'/> and the state "
        "interfaces position, velocity and acceleration.")
def test_joint_interfaces(hardware: HardwareInfo) -> None:
    assert [j.name for j in hardware.joints] == ["joint1", "joint2"], (
        f"<ros2_control> joints are {[j.name for j in hardware.joints]}, expected ['joint1', 'joint2']"
    )
    for joint in hardware.joints:
        assert _names(joint.command_interfaces) == ["position"], (
            f"{joint.name} command interfaces are {_names(joint.command_interfaces)}, expected ['position']"
        )
        states = _names(joint.state_interfaces)
        assert sorted(states) == ["acceleration", "position", "velocity"], (
            f"{joint.name} state interfaces are {states}, expected position, velocity, acceleration"
        )


@graded(points=2, hint="<sensor name='tcp_fts_sensor'> has the six state interfaces fx fy fz tx ty tz and "
        "<param name='frame_id'>tool0</param> (with the prefix: ${prefix}tool0).")
def test_fts_sensor(hardware: HardwareInfo) -> None:
    sensor = _component(hardware.sensors, "tcp_fts_sensor", "sensor")
    states = _names(sensor.state_interfaces)
    assert sorted(states) == sorted(["fx", "fy", "fz", "tx", "ty", "tz"]), (
        f"tcp_fts_sensor state interfaces are {states}, expected fx fy fz tx ty tz"
    )
    assert not sensor.command_interfaces, "a sensor has no command interfaces"
    assert sensor.parameters.get("frame_id") == "tool0", (
        f"tcp_fts_sensor frame_id is {sensor.parameters.get('frame_id')!r}, expected 'tool0'"
    )


@graded(points=1, hint="<gpio name='flange_gpios'> has two inputs: state interfaces digital_in_1 and digital_in_2 "
        "(inputs are read only: no command interface).")
def test_gpio_inputs(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    states, commands = _names(gpio.state_interfaces), _names(gpio.command_interfaces)
    for name in ("digital_in_1", "digital_in_2"):
        assert name in states, f"flange_gpios has no state interface '{name}' (state interfaces: {states})"
        assert name not in commands, f"'{name}' is an input: it must not be a command interface"


@graded(points=2, hint="flange_gpios has two outputs: command interfaces digital_out_1 and digital_out_2.")
def test_gpio_outputs(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    commands = _names(gpio.command_interfaces)
    assert sorted(commands) == ["digital_out_1", "digital_out_2"], (
        f"flange_gpios command interfaces are {commands}, expected digital_out_1 and digital_out_2"
    )


@graded(points=1, hint="Outputs can be read back: give flange_gpios a state interface of the same name next to "
        "each output's command interface (digital_out_1, digital_out_2).")
def test_gpio_output_readback(hardware: HardwareInfo) -> None:
    gpio = _component(hardware.gpios, "flange_gpios", "gpio")
    states = _names(gpio.state_interfaces)
    for name in ("digital_out_1", "digital_out_2"):
        assert name in states, f"flange_gpios has no state interface '{name}' to read the output back"


@graded(points=3, hint="With prefix:=left_ every name starts with left_: every link (except world) and joint; in "
        "<ros2_control> the tag itself (name='${prefix}${name}', so left_rrbot), the joints left_joint1 and "
        "left_joint2, the sensor left_tcp_fts_sensor with frame_id left_tool0, and the GPIO left_flange_gpios.")
def test_prefix(prefixed_urdf: str) -> None:
    model = yourdfpy.URDF.load(io.StringIO(prefixed_urdf), build_scene_graph=False, load_meshes=False,
                               load_collision_meshes=False)
    links = [link.name for link in model.robot.links if link.name != "world"]
    joints = [joint.name for joint in model.robot.joints]
    unprefixed = [n for n in links + joints if not n.startswith("left_")]
    assert links and not unprefixed, f"not prefixed with prefix:=left_: {unprefixed}"
    (hardware,) = parse_ros2_control(prefixed_urdf)
    assert hardware.name == "left_rrbot", (
        f"with prefix:=left_ the <ros2_control> tag is named {hardware.name!r}, expected 'left_rrbot': two robots in "
        "one system need two hardware component names"
    )
    assert [j.name for j in hardware.joints] == ["left_joint1", "left_joint2"], (
        f"<ros2_control> joints with prefix:=left_ are {[j.name for j in hardware.joints]}"
    )
    sensors = [s for s in hardware.sensors if s.name.endswith("tcp_fts_sensor")]
    assert sensors, "no tcp_fts_sensor with prefix:=left_"
    assert sensors[0].name == "left_tcp_fts_sensor", (
        f"with prefix:=left_ the sensor is named {sensors[0].name!r}, expected 'left_tcp_fts_sensor': otherwise two "
        "robots both export tcp_fts_sensor/fx"
    )
    gpios = [g.name for g in hardware.gpios if g.name.endswith("flange_gpios")]
    assert gpios == ["left_flange_gpios"], (
        f"with prefix:=left_ the GPIO block is named {gpios}, expected ['left_flange_gpios']"
    )
    assert sensors[0].parameters.get("frame_id") == "left_tool0", (
        f"with prefix:=left_ the FTS frame_id is {sensors[0].parameters.get('frame_id')!r}: the frame is 'left_tool0'"
    )
