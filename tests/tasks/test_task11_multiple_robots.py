"""Grader of task 11: two RRBots in one description, under one controller manager.

The specification (the exercise's xacro header, its TODOs and notebook 11):

* ``multi_rrbot_description/urdf/multi_rrbot.urdf.xacro`` takes ``prefix_1`` (``r1_``), ``prefix_2`` (``r2_``),
  ``spacing`` (1.5 m) and ``use_mock_hardware`` (true); it places two RRBots (the library's macros) on a ``world``
  link, robot 1 at ``y = +spacing/2`` and robot 2 at ``y = -spacing/2`` (to 1 µm, for any spacing); every link,
  joint, sensor, GPIO and hardware component carries its robot's prefix, whatever the prefixes, so the two never
  collide; ``use_mock_hardware`` chooses both robots' hardware;
* giving both robots the same prefix is refused with an error that names the duplicate;
* ``multi_rrbot_bringup/config/multi_rrbot_controllers.yaml``: one ``joint_state_broadcaster`` and, per robot,
  ``<prefix>forward_position_controller`` and ``<prefix>joint_trajectory_controller`` on that robot's joints,
  configured as in task 2 (position commands; position and velocity states); parameters Jazzy's controllers declare;
* running, each robot follows its own controllers (to 1 mrad), and stopping either robot's controllers leaves the
  other one running.

The library's ``descriptions/multi_rrbot/`` does what the description must do: a generated-scenario check runs the
learner's xacro and it side by side on arguments within what the task allows.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import description_compare
import pytest
import yaml
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import descriptions_root, parse_ros2_control, process_xacro
from rrbot_workshop.msgs import Float64MultiArray, JointTrajectory, JointTrajectoryPoint
from rrbot_workshop.tools.lint import lint_controllers

TASK = 11
DESCRIPTION = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
CONTROLLERS = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"
JSB = "joint_state_broadcaster"
PREFIXES = ("r1_", "r2_")
FPC, JTC = "forward_position_controller", "joint_trajectory_controller"
TYPES = {FPC: "forward_command_controller/ForwardCommandController",
         JTC: "joint_trajectory_controller/JointTrajectoryController"}
#: How far a joint may end from where its controller sent it [rad] (the task: "within 1 mrad").
POSITION_TOLERANCE = 1e-3
#: How far a pedestal may stand from +-spacing/2 [m] (the task: "to 1 µm").
PLACEMENT_TOLERANCE = 1e-6


def _reference() -> Path:
    return descriptions_root() / "multi_rrbot" / "urdf" / "multi_rrbot.urdf.xacro"


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


def _fail(message: str) -> None:
    pytest.fail(message, pytrace=False)


_args = description_compare.arguments
_clean = description_compare.as_shown


def _urdf(path: Path, **args: Any) -> str:
    try:
        return process_xacro(path, **args)
    except rw.RRBotWorkshopError as exc:
        _fail(f"your {path.name} does not process with {_args(**args)}: {_clean(str(exc), path)}")
    raise AssertionError("unreachable")


def _infos(urdf: str, path: Path, **args: Any) -> list[Any]:
    try:
        return parse_ros2_control(urdf)
    except rw.DescriptionError as exc:
        _fail(f"your {path.name} with {_args(**args)} is refused: {_clean(str(exc), path)}")
    raise AssertionError("unreachable")


def _names(robot: ET.Element, infos: list[Any]) -> list[str]:
    names = [str(e.get("name")) for e in (*robot.findall("link"), *robot.findall("joint"))]
    names += [info.name for info in infos] + [j.name for i in infos for j in i.joints]
    names += [s.name for i in infos for s in i.sensors] + [g.name for i in infos for g in i.gpios]
    return names


def _mount(robot: ET.Element, prefix: str) -> tuple[str, list[float]] | None:
    """(parent link, xyz) of the joint that holds ``<prefix>base_link``, or None."""
    for joint in robot.findall("joint"):
        child, parent = joint.find("child"), joint.find("parent")
        if child is not None and child.get("link") == f"{prefix}base_link" and parent is not None:
            origin = joint.find("origin")
            xyz = (origin.get("xyz") if origin is not None else None) or "0 0 0"
            return str(parent.get("link")), [float(v) for v in xyz.split()]
    return None


# --------------------------------------------------------------------------------------------- 11.1 the description


@graded(points=3, hint=(
    "Task 11.1: every name a robot brings (links, joints, the force-torque sensor, the GPIO block and its "
    "<ros2_control> component) must come from that robot's prefix argument, whatever prefixes are given.",
    "Instantiate the library's rrbot and rrbot_ros2_control macros twice, passing prefix=\"$(arg prefix_1)\" to one "
    "pair and prefix=\"$(arg prefix_2)\" to the other; the macros put the prefix before every name themselves.",
    "<xacro:rrbot prefix=\"$(arg prefix_1)\" parent=\"world\"> ... </xacro:rrbot>\n"
    "<xacro:rrbot_ros2_control name=\"rrbot\" prefix=\"$(arg prefix_1)\" use_mock_hardware=\"$(arg use_mock_hardware)\"/>"
    "\n(and the same for prefix_2)"))
def test_two_prefixed_robots(description_file: Path) -> None:
    for prefixes in (PREFIXES, ("left_", "right_"), ("r2_", "r1_"), ("a_", "b_")):
        args = {"prefix_1": prefixes[0], "prefix_2": prefixes[1]}
        urdf = _urdf(description_file, **args)
        infos = _infos(urdf, description_file, **args)
        where = f"your {description_file.name} with {_args(**args)}"
        assert len(infos) == 2, (
            f"{where} declares {len(infos)} hardware component(s) ({[i.name for i in infos]}); the task asks for two, "
            "one <ros2_control> tag per robot.")
        for prefix in prefixes:
            mine = [i for i in infos if i.name.startswith(prefix)]
            assert len(mine) == 1, (
                f"{where}: no hardware component's name starts with '{prefix}' (components: {[i.name for i in infos]}).")
            joints = sorted(j.name for j in mine[0].joints)
            assert joints == [f"{prefix}joint1", f"{prefix}joint2"], (
                f"{where}: component '{mine[0].name}' has the joints {joints}, expected {prefix}joint1 and {prefix}joint2.")
            sensors, gpios = [s.name for s in mine[0].sensors], [g.name for g in mine[0].gpios]
            assert sensors == [f"{prefix}tcp_fts_sensor"], (
                f"{where}: component '{mine[0].name}' has the sensors {sensors}, expected ['{prefix}tcp_fts_sensor'].")
            assert gpios == [f"{prefix}flange_gpios"], (
                f"{where}: component '{mine[0].name}' has the GPIOs {gpios}, expected ['{prefix}flange_gpios'].")
        stray = sorted(n for n in _names(ET.fromstring(urdf), infos) if n != "world" and not n.startswith(prefixes))
        assert not stray, f"{where} has names that do not start with either prefix: {stray}."


@graded(points=1, hint=(
    "Task 11.1: the pedestals stand `spacing` apart along y, centred on the world origin: robot 1 at +spacing/2, "
    "robot 2 at -spacing/2, for any spacing (checked to 1 µm).",
    "Compute the y of each robot's <origin> from the argument inside a xacro expression: ${...} can use $(arg spacing).",
    "<origin xyz=\"0 ${$(arg spacing) / 2} 0\" rpy=\"0 0 0\"/>   (robot 1)\n"
    "<origin xyz=\"0 ${-$(arg spacing) / 2} 0\" rpy=\"0 0 0\"/>  (robot 2)"))
def test_side_by_side(description_file: Path) -> None:
    for spacing, prefixes in ((1.5, PREFIXES), (3.0, PREFIXES), (0.8, ("left_", "right_"))):
        args = {"spacing": spacing, "prefix_1": prefixes[0], "prefix_2": prefixes[1]}
        robot = ET.fromstring(_urdf(description_file, **args))
        for prefix, sign, which in zip(prefixes, (1, -1), ("robot 1", "robot 2"), strict=True):
            mount = _mount(robot, prefix)
            where = f"your {description_file.name} with {_args(**args)}"
            assert mount is not None, f"{where}: no joint holds {prefix}base_link, so {which} stands nowhere."
            parent, xyz = mount
            assert parent == "world", f"{where}: {prefix}base_link hangs from '{parent}', the task says from 'world'."
            expected = [0.0, sign * spacing / 2, 0.0]
            assert len(xyz) == 3 and all(math.isclose(a, b, abs_tol=PLACEMENT_TOLERANCE)
                                         for a, b in zip(xyz, expected, strict=True)), (
                f"{where}: {which} stands at {xyz}, expected {expected} (spacing/2 = {spacing / 2:g} m on the "
                f"{'+' if sign > 0 else '-'}y side).")


@graded(points=1, hint=(
    "Task 11.1: use_mock_hardware chooses the hardware of BOTH robots: true gives mock_components/GenericSystem, "
    "false the RRBot macro's other plugin.",
    "Pass the file's argument on to each rrbot_ros2_control macro: use_mock_hardware=\"$(arg use_mock_hardware)\". "
    "Its own default is true, so leaving it out only looks right with the default.",
    "<xacro:rrbot_ros2_control name=\"rrbot\" prefix=\"$(arg prefix_2)\" use_mock_hardware=\"$(arg use_mock_hardware)\"/>"))
def test_use_mock_hardware_reaches_both_robots(description_file: Path) -> None:
    for mock in (True, False):
        expected = {i.name[:3]: i.hardware_plugin_name
                    for i in parse_ros2_control(process_xacro(_reference(), use_mock_hardware=mock))}
        urdf = _urdf(description_file, use_mock_hardware=mock)
        infos = _infos(urdf, description_file, use_mock_hardware=mock)
        for prefix in PREFIXES:
            got = [i.hardware_plugin_name for i in infos if i.name.startswith(prefix)]
            assert got == [expected[prefix]], (
                f"your {description_file.name} with use_mock_hardware:={str(mock).lower()} gives robot '{prefix}' the "
                f"plugin(s) {got}, expected ['{expected[prefix]}'].")


@graded(points=1, hint=(
    "Task 11.1: with the same prefix twice, the URDF must be refused with an error that names the duplicate name. "
    "That holds when every name comes from the prefix arguments and nothing is written out.",
    "Try it: rw.bringup(your_xacro, xacro_args={'prefix_1': 'r1_', 'prefix_2': 'r1_'}) must raise "
    "rw.DescriptionError ('... is declared twice').",
    "Do not give either robot a fixed name (name=\"rrbot_1\" prefix=\"r1_\"): write prefix=\"$(arg prefix_2)\" for robot 2."))
def test_same_prefix_twice_is_a_clear_error(description_file: Path) -> None:
    for prefix in ("r1_", "twin_"):
        args = {"prefix_1": prefix, "prefix_2": prefix}
        try:
            urdf = process_xacro(description_file, **args)
            parse_ros2_control(urdf)
        except rw.DescriptionError as exc:
            message = _clean(str(exc), description_file)
            assert "twice" in message and prefix in message, (
                f"your {description_file.name} with {_args(**args)} is refused, but not for a name given twice: "
                f"{message}")
        else:
            _fail(f"your {description_file.name} with {_args(**args)} is accepted; two robots with one prefix must be "
                  "refused, with an error naming the duplicate.")


@graded(points=2, hint=(
    "Task 11.1: for any prefixes, spacing and use_mock_hardware, your description must give the same links, joints, "
    "placements and hardware components as two RRBots placed as the task says.",
    "Every name from a prefix argument, every number from spacing, and use_mock_hardware passed on to both "
    "rrbot_ros2_control macros; the world link is the only name of your own.",
    "<link name=\"world\"/>\n<xacro:rrbot prefix=\"$(arg prefix_1)\" parent=\"world\">"
    "<origin xyz=\"0 ${$(arg spacing) / 2} 0\" rpy=\"0 0 0\"/></xacro:rrbot>\n(and robot 2 at -spacing/2, "
    "then one rrbot_ros2_control per robot)"))
def test_description_matches_the_task_for_any_arguments(description_file: Path) -> None:
    prefix = st.sampled_from(["r1_", "r2_", "a_", "b_", "left_", "right_", "robot_a_", "arm2_"])
    scenario = st.fixed_dictionaries({
        "prefix_1": prefix, "prefix_2": prefix,
        "spacing": st.sampled_from([1.5, 0.5, 1.0, 2.25, 3.0, 0.8]),
        "use_mock_hardware": st.booleans(),
    }).filter(lambda a: a["prefix_1"] != a["prefix_2"])

    found = description_compare.first_difference(description_file, _reference(), scenario)
    assert not found, found


@graded(points=2, hint=(
    "Task 11.2: one joint_state_broadcaster for both robots, and per robot a forward position controller and a "
    "trajectory controller named with the robot's prefix, on that robot's joints only, configured as in task 2.",
    "Declare r1_forward_position_controller, r1_joint_trajectory_controller, r2_... under controller_manager with "
    "their types; each gets its own section with joints (and interface_name / command_interfaces, state_interfaces).",
    "r2_forward_position_controller:\n  ros__parameters:\n    joints: [r2_joint1, r2_joint2]\n    interface_name: position"))
def test_controllers_yaml(controllers_file: Path) -> None:
    name = controllers_file.name
    try:
        data = yaml.safe_load(controllers_file.read_text()) or {}
    except yaml.YAMLError as exc:
        _fail(f"your {name} is not valid YAML: {exc}")
    manager = (data.get("controller_manager") or {}).get("ros__parameters") or {}
    broadcasters = sorted(n for n, v in manager.items()
                          if isinstance(v, dict) and v.get("type") == "joint_state_broadcaster/JointStateBroadcaster")
    assert broadcasters == [JSB], (
        f"your {name} declares the joint state broadcasters {broadcasters}; the task asks for one, named '{JSB}', "
        "for both robots.")
    for prefix in PREFIXES:
        joints = [f"{prefix}joint1", f"{prefix}joint2"]
        for kind, type_name in TYPES.items():
            controller = prefix + kind
            declared = (manager.get(controller) or {}).get("type")
            assert declared == type_name, (
                f"your {name} declares '{controller}' with the type {declared!r}, expected '{type_name}'.")
            params = (data.get(controller) or {}).get("ros__parameters") or {}
            assert params.get("joints") == joints, (
                f"your {name}: '{controller}' has the joints {params.get('joints')}, expected {joints}.")
        fpc = (data.get(prefix + FPC) or {}).get("ros__parameters") or {}
        assert fpc.get("interface_name") == "position", (
            f"your {name}: '{prefix}{FPC}' commands the interface {fpc.get('interface_name')!r}, expected 'position'.")
        jtc = (data.get(prefix + JTC) or {}).get("ros__parameters") or {}
        assert jtc.get("command_interfaces") == ["position"], (
            f"your {name}: '{prefix}{JTC}' has command_interfaces {jtc.get('command_interfaces')}, expected [position].")
        states = jtc.get("state_interfaces")
        assert isinstance(states, list) and sorted(states) == ["position", "velocity"], (
            f"your {name}: '{prefix}{JTC}' has state_interfaces {states}, expected [position, velocity].")
    errors = [f.message for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, f"your {name} would not load on a Jazzy robot: " + "; ".join(errors)


# --------------------------------------------------------------------------------------------- running


@contextmanager
def _system(description_file: Path, controllers_file: Path, spawn: list[str]) -> Iterator[System]:
    try:
        system = bringup(description_file, controllers_file, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        text = _clean(_clean(str(exc), description_file), controllers_file)
        _fail(f"the system does not start from your files with the controllers {spawn}: {text}")
    try:
        yield system
    finally:
        system.shutdown()


def _joints(system: System) -> dict[str, float]:
    msg = system.latest("/joint_states")
    return dict(zip(msg.name, msg.position, strict=True)) if msg is not None else {}


def states_of(cm: Any) -> dict[str, str]:
    return {c.name: c.state for c in cm.list_controllers()}


def _near(joints: dict[str, float], expected: dict[str, float]) -> bool:
    return all(n in joints and abs(joints[n] - v) <= POSITION_TOLERANCE for n, v in expected.items())


def _rounded(joints: dict[str, float]) -> dict[str, float]:
    return {n: round(v, 4) for n, v in sorted(joints.items())}


@graded(points=3, hint=(
    "Task 11: each robot obeys its own controllers only, both ways round: r1's forward command moves r1 while r2's "
    "trajectory moves r2, and r2's forward command moves r2 while r1's trajectory moves r1 (within 1 mrad).",
    "Each controller's joints must be its robot's (r1_joint1, r1_joint2 for r1_...), and the broadcaster must "
    "publish all four joints; `%control list_controllers -v` shows what each claims.",
    "r1_joint_trajectory_controller:\n  ros__parameters:\n    joints: [r1_joint1, r1_joint2]\n"
    "    command_interfaces: [position]\n    state_interfaces: [position, velocity]"))
def test_independent_control(description_file: Path, controllers_file: Path) -> None:
    for forward, trajectory in (PREFIXES, PREFIXES[::-1]):
        spawn = [JSB, forward + FPC, trajectory + JTC]
        with _system(description_file, controllers_file, spawn) as system:
            system.publish(f"/{forward}{FPC}/commands", Float64MultiArray(data=[0.5, -0.25]))
            system.publish(f"/{trajectory}{JTC}/joint_trajectory", JointTrajectory(
                joint_names=[f"{trajectory}joint1", f"{trajectory}joint2"],
                points=[JointTrajectoryPoint(positions=[-0.6, 0.3], time_from_start=1.0)]))
            system.spin(1.5)
            joints = _joints(system)
        expected = {f"{forward}joint1": 0.5, f"{forward}joint2": -0.25,
                    f"{trajectory}joint1": -0.6, f"{trajectory}joint2": 0.3}
        assert _near(joints, expected), (
            f"with {forward}{FPC} sent to [0.5, -0.25] and {trajectory}{JTC} given a trajectory to [-0.6, 0.3] in 1 s, "
            f"the joints are at {_rounded(joints)} after 1.5 s; expected {expected} (within 1 mrad).")


@graded(points=1, hint=(
    "Task 11: stopping one robot's controllers must leave the other robot's running, whichever robot stops.",
    "Each robot's controllers claim only its own joints, so a switch that deactivates r1_... leaves r2_... active "
    "(and the other way round).",
    "cm.switch_controllers(deactivate=['r1_forward_position_controller'], strictness='strict') must leave "
    "r2_forward_position_controller active and obeying its commands."))
def test_one_robot_stops_alone(description_file: Path, controllers_file: Path) -> None:
    with _system(description_file, controllers_file, [JSB, f"r1_{FPC}", f"r2_{FPC}"]) as system:
        cm = system.controller_manager
        for stopped, running, target in (("r1_", "r2_", [0.2, 0.4]), ("r2_", "r1_", [-0.3, 0.1])):
            restart = [] if states_of(cm).get(running + FPC) == "active" else [running + FPC]
            cm.switch_controllers(activate=restart, deactivate=[stopped + FPC], strictness="strict")
            before = _joints(system)
            system.publish(f"/{running}{FPC}/commands", Float64MultiArray(data=target))
            system.publish(f"/{stopped}{FPC}/commands", Float64MultiArray(data=[1.0, 1.0]))
            system.spin(0.1)
            joints = _joints(system)
            states = states_of(cm)
            assert states.get(running + FPC) == "active", (
                f"after deactivating {stopped}{FPC}, {running}{FPC} is {states.get(running + FPC)!r}; it must stay active.")
            expected = {f"{running}joint1": target[0], f"{running}joint2": target[1],
                        f"{stopped}joint1": before.get(f"{stopped}joint1", 0.0),
                        f"{stopped}joint2": before.get(f"{stopped}joint2", 0.0)}
            assert _near(joints, expected), (
                f"with {stopped}{FPC} stopped and {running}{FPC} sent to {target}, the joints are at "
                f"{_rounded(joints)}; expected {expected} (within 1 mrad).")
