"""Grader of task 10: RRBot on DiffBot, two robots' macros reused in one description with one controller manager.

The specification:

* ``rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro`` takes ``base_prefix`` (default ``base_``),
  ``arm_prefix`` (default ``arm_``) and ``use_mock_hardware`` (default true); it reuses the library's DiffBot and RRBot
  macros unchanged: the DiffBot is the root of the tree, the RRBot stands on ``<base_prefix>top_plate``
  (0.1 m towards the front); every link, joint, sensor and GPIO carries its robot's prefix;
* one ``<ros2_control>`` tag per robot: two hardware components with different names, the base's with the two wheel
  joints, the arm's with the two arm joints, the force-torque sensor and the GPIOs;
* ``rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml``: ``joint_state_broadcaster``,
  ``diffbot_base_controller`` (DiffDriveController on the base's wheels, wheel separation and radius equal to the
  description's) and ``joint_trajectory_controller`` (the arm's joints, position commands, position and velocity
  states); parameters Jazzy's controllers declare;
* running, the three controllers are active at once; the base drives a circle of radius v/w while the arm follows a
  trajectory; stopping either robot's controller leaves the other one moving;
* ``answers.py``: the original workshop's questions (components, plugins per tag, controller managers).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.lint import lint_controllers
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint, Twist, TwistStamped, Vector3

TASK = 10
DESCRIPTION = "rrbot_on_diffbot_description/urdf/rrbot_on_diffbot.urdf.xacro"
CONTROLLERS = "rrbot_on_diffbot_bringup/config/rrbot_on_diffbot_controllers.yaml"
JSB, BASE, ARM = "joint_state_broadcaster", "diffbot_base_controller", "joint_trajectory_controller"
WHEEL_SEPARATION, WHEEL_RADIUS = 0.55, 0.1  # [m], the DiffBot macro's geometry


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


def _urdf(description_file: Path, **args: Any) -> str:
    try:
        return process_xacro(description_file, **args)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"{description_file.name} does not process: {exc}", pytrace=False)


def _components(urdf: str) -> list[Any]:
    try:
        return parse_ros2_control(urdf)
    except rw.DescriptionError as exc:
        pytest.fail(f"the <ros2_control> tags do not parse: {exc}", pytrace=False)


def _component_with(infos: list[Any], joint: str) -> Any:
    found = [info for info in infos if joint in [j.name for j in info.joints]]
    if len(found) != 1:
        pytest.fail(f"joint '{joint}' is in {len(found)} hardware components; it must be in exactly one", pytrace=False)
    return found[0]


@contextmanager
def _system(description_file: Path, controllers_file: Path, spawn: list[str]) -> Iterator[System]:
    try:
        system = bringup(description_file, controllers_file, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"the system does not start with your files: {exc}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _drive(system: System, v: float, w: float, seconds: float) -> None:
    for _ in range(system.clock.cycles_for(seconds)):
        system.publish(f"/{BASE}/cmd_vel", TwistStamped(twist=Twist(linear=Vector3(x=v), angular=Vector3(z=w))))
        system.spin_cycles(1)


def _joints(system: System) -> dict[str, float]:
    msg = system.latest("/joint_states")
    return dict(zip(msg.name, msg.position, strict=True)) if msg is not None else {}


# --------------------------------------------------------------------------------------------- 10.1 the tree


@graded(points=2, hint="Task 10.1: instantiate both macros, each with its prefix argument; the base is the root, the "
        "arm's parent is the base's top plate. Open the macros in descriptions/ to see their parameters.")
def test_both_robots_in_one_tree(description_file: Path) -> None:
    import xml.etree.ElementTree as ET

    robot = ET.fromstring(_urdf(description_file))
    links = {link.get("name") for link in robot.findall("link")}
    joints = {j.get("name"): (j.find("parent").get("link"), j.find("child").get("link"))  # type: ignore[union-attr]
              for j in robot.findall("joint")}
    for name in ("base_base_link", "base_top_plate", "arm_base_link", "arm_link1", "arm_link2"):
        assert name in links, f"no link '{name}' (links: {sorted(links)})"
    children = {child for _parent, child in joints.values()}
    roots = sorted(links - children)
    assert roots == ["base_base_link"], f"the tree must have one root, the base's base_link; roots: {roots}"
    mount = [(name, pc) for name, pc in joints.items() if pc[1] == "arm_base_link"]
    assert mount and mount[0][1][0] == "base_top_plate", f"the arm's base_link must hang from base_top_plate: {mount}"
    origin = robot.find(f"joint[@name='{mount[0][0]}']/origin")
    xyz = [float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()]
    assert xyz == pytest.approx([0.1, 0.0, 0.0]), f"the arm stands at {xyz} on the top plate, expected 0.1 m forward"


@graded(points=2, hint="Task 10.1: every name comes from its robot's prefix argument, never written out: with "
        "base_prefix:=b_ and arm_prefix:=a_ no name may start with base_ or arm_.")
def test_prefix_arguments_rename_everything(description_file: Path) -> None:
    import xml.etree.ElementTree as ET

    urdf = _urdf(description_file, base_prefix="b_", arm_prefix="a_")
    infos = _components(urdf)
    robot = ET.fromstring(urdf)
    names = [j.name for info in infos for j in info.joints] + [s.name for info in infos for s in info.sensors] + [
        g.name for info in infos for g in info.gpios] + [info.name for info in infos] + [
        str(e.get("name")) for e in (*robot.findall("link"), *robot.findall("joint"))]
    unprefixed = sorted(n for n in names if not n.startswith(("b_", "a_")))
    assert names and not unprefixed, f"names without the new prefixes: {unprefixed}"


# --------------------------------------------------------------------------------------------- 10.2 components


@graded(points=3, hint="Task 10.2: one <ros2_control> tag per robot (the macros write one each): two hardware "
        "components with different names, the wheels in one, the arm's joints, sensor and GPIOs in the other.")
def test_two_hardware_components(description_file: Path) -> None:
    infos = _components(_urdf(description_file))
    assert len(infos) == 2, f"{len(infos)} hardware components ({[i.name for i in infos]}), expected 2"
    assert len({i.name for i in infos}) == 2, f"the components have the same name: {[i.name for i in infos]}"
    base = _component_with(infos, "base_left_wheel_joint")
    arm = _component_with(infos, "arm_joint1")
    assert base is not arm, "the base's wheels and the arm's joints are in the same component"
    assert sorted(j.name for j in base.joints) == ["base_left_wheel_joint", "base_right_wheel_joint"]
    assert sorted(j.name for j in arm.joints) == ["arm_joint1", "arm_joint2"]
    assert [s.name for s in arm.sensors] == ["arm_tcp_fts_sensor"] and [g.name for g in arm.gpios] == ["arm_flange_gpios"]
    assert base.hardware_plugin_name == arm.hardware_plugin_name == "mock_components/GenericSystem"


@graded(points=2, hint="Task 10.2: a diff drive controller on the base's wheel joints with the description's geometry "
        "(wheel_separation, wheel_radius in m) and the arm's trajectory controller; `rrbot-workshop lint` checks names.")
def test_controllers_yaml(controllers_file: Path) -> None:
    try:
        data = yaml.safe_load(controllers_file.read_text()) or {}
    except yaml.YAMLError as exc:
        pytest.fail(f"{controllers_file.name} is not valid YAML: {exc}", pytrace=False)
    manager = (data.get("controller_manager") or {}).get("ros__parameters") or {}
    types = {n: (manager.get(n) or {}).get("type") for n in (JSB, BASE, ARM)}
    assert types == {JSB: "joint_state_broadcaster/JointStateBroadcaster",
                     BASE: "diff_drive_controller/DiffDriveController",
                     ARM: "joint_trajectory_controller/JointTrajectoryController"}, f"types {types}"
    base = (data.get(BASE) or {}).get("ros__parameters") or {}
    assert base.get("left_wheel_names") == ["base_left_wheel_joint"], base.get("left_wheel_names")
    assert base.get("right_wheel_names") == ["base_right_wheel_joint"], base.get("right_wheel_names")
    assert base.get("wheel_separation") == pytest.approx(WHEEL_SEPARATION), "wheel_separation is not the description's"
    assert base.get("wheel_radius") == pytest.approx(WHEEL_RADIUS), "wheel_radius is not the description's"
    arm = (data.get(ARM) or {}).get("ros__parameters") or {}
    assert arm.get("joints") == ["arm_joint1", "arm_joint2"], f"{ARM}: joints {arm.get('joints')}"
    assert arm.get("command_interfaces") == ["position"], f"{ARM}: command_interfaces {arm.get('command_interfaces')}"
    errors = [f.message for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, "the YAML would not load on a Jazzy robot: " + "; ".join(errors)


# --------------------------------------------------------------------------------------------- running


@graded(points=3, hint="Task 10: with disjoint interfaces, the base's and the arm's controllers run at the same time; "
        "the base drives a circle of radius v/w while the arm follows its trajectory.")
def test_base_and_arm_move_together(description_file: Path, controllers_file: Path) -> None:
    with _system(description_file, controllers_file, [JSB, BASE, ARM]) as system:
        states = {c.name: c.state for c in system.controller_manager.list_controllers()}
        assert all(states.get(n) == "active" for n in (JSB, BASE, ARM)), f"controllers: {states}"
        system.publish(f"/{ARM}/joint_trajectory", JointTrajectory(
            joint_names=["arm_joint1", "arm_joint2"],
            points=[JointTrajectoryPoint(positions=[0.8, -0.4], time_from_start=2.0)]))
        _drive(system, 0.5, 0.5, 1.0)  # accelerate onto the circle
        radii = []
        for _ in range(8):
            _drive(system, 0.5, 0.5, 0.5)
            p = system.latest(f"/{BASE}/odom").pose.pose.position
            radii.append(math.hypot(p.x, p.y - 1.0))
        joints = _joints(system)
    assert max(abs(r - 1.0) for r in radii) < 0.05, f"the odometry is not on a 1 m circle: radii {radii}"
    assert joints.get("arm_joint1") == pytest.approx(0.8, abs=1e-3), f"arm: {joints}"
    assert joints.get("arm_joint2") == pytest.approx(-0.4, abs=1e-3), f"arm: {joints}"


@graded(points=2, hint="Task 10: the robots share a controller manager, nothing else: deactivating the base's "
        "controller must not stop the arm, and the other way round.")
def test_base_and_arm_are_independent(description_file: Path, controllers_file: Path) -> None:
    with _system(description_file, controllers_file, [JSB, BASE, ARM]) as system:
        cm = system.controller_manager
        cm.switch_controllers(deactivate=[BASE], strictness="strict")
        system.publish(f"/{ARM}/joint_trajectory", JointTrajectory(
            joint_names=["arm_joint1", "arm_joint2"],
            points=[JointTrajectoryPoint(positions=[-0.5, 0.3], time_from_start=1.0)]))
        system.spin(1.5)
        arm = _joints(system)
        cm.switch_controllers(activate=[BASE], deactivate=[ARM], strictness="strict")
        _drive(system, 0.4, 0.0, 2.0)
        x = system.latest(f"/{BASE}/odom").pose.pose.position.x
    assert arm.get("arm_joint1") == pytest.approx(-0.5, abs=1e-3), f"the arm stopped with the base: {arm}"
    assert x > 0.5, f"the base did not drive with the arm's controller stopped (odometry x = {x:.3f} m)"


# --------------------------------------------------------------------------------------------- 10.3 answers


@graded(points=1, hint="Task 10.3: count from your description: how many <ros2_control> tags, how many <plugin> in "
        "each, how many controller managers run them? %control list_hardware_components confirms.")
def test_answers(task_file: Callable[[int, str], Path]) -> None:
    task_file(TASK, "answers.py")
    answers: ModuleType | None = rw.course.load_module(TASK, "answers.py", quiet=True)
    assert answers is not None, "answers.py does not import"
    expected = {"HARDWARE_COMPONENTS": 2, "PLUGINS_PER_ROS2_CONTROL_TAG": 1, "CONTROLLER_MANAGERS": 1}
    got = {name: getattr(answers, name, None) for name in expected}
    wrong = {n: v for n, v in got.items() if v != expected[n] or isinstance(v, bool)}
    assert not wrong, f"not right yet: {sorted(wrong)}"
