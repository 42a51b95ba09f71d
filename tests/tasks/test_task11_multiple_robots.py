"""Grader of task 11: two RRBots in one description, under one controller manager.

The specification:

* ``multi_rrbot_description/urdf/multi_rrbot.urdf.xacro`` takes ``prefix_1`` (``r1_``), ``prefix_2`` (``r2_``), ``spacing``
  (1.5 m) and ``use_mock_hardware`` (true); it places two RRBots (the library's macros) on a ``world`` link, robot 1 at
  ``y = +spacing/2`` and robot 2 at ``y = -spacing/2``; every link, joint, sensor, GPIO and hardware component carries
  its robot's prefix, so the two never collide;
* giving both robots the same prefix is refused with a clear error that names the duplicate;
* ``multi_rrbot_bringup/config/multi_rrbot_controllers.yaml``: one ``joint_state_broadcaster`` and, per robot,
  ``<prefix>forward_position_controller`` and ``<prefix>joint_trajectory_controller`` on that robot's joints
  (configured as in task 2); parameters Jazzy's controllers declare;
* running, each robot follows its own controllers, and stopping one robot's controllers leaves the other running.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.lint import lint_controllers
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.msgs import Float64MultiArray, JointTrajectory, JointTrajectoryPoint

TASK = 11
DESCRIPTION = "multi_rrbot_description/urdf/multi_rrbot.urdf.xacro"
CONTROLLERS = "multi_rrbot_bringup/config/multi_rrbot_controllers.yaml"
JSB = "joint_state_broadcaster"
PREFIXES = ("r1_", "r2_")


@pytest.fixture(scope="module")
def description_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, DESCRIPTION)


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


def _urdf(path: Path, **args: Any) -> str:
    try:
        return process_xacro(path, **args)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"{path.name} does not process: {exc}", pytrace=False)


def _names(urdf: str) -> tuple[list[str], list[Any]]:
    try:
        infos = parse_ros2_control(urdf)
    except rw.DescriptionError as exc:
        pytest.fail(f"the description is refused: {exc}", pytrace=False)
    robot = ET.fromstring(urdf)
    names = [str(e.get("name")) for e in (*robot.findall("link"), *robot.findall("joint"))]
    names += [info.name for info in infos] + [j.name for i in infos for j in i.joints]
    names += [s.name for i in infos for s in i.sensors] + [g.name for i in infos for g in i.gpios]
    return names, infos


def _start(description_file: Path, controllers_file: Path, spawn: list[str]) -> System:
    try:
        return bringup(description_file, controllers_file, spawn=spawn)
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"the system does not start with your files: {exc}", pytrace=False)


def _joints(system: System) -> dict[str, float]:
    msg = system.latest("/joint_states")
    return dict(zip(msg.name, msg.position, strict=True)) if msg is not None else {}


@graded(points=3, hint="Task 11.1: two RRBots, each with its prefix on every name: links, joints, the force-torque "
        "sensor, the GPIO block and the <ros2_control> component (two components).")
def test_two_prefixed_robots(description_file: Path) -> None:
    for prefixes in (PREFIXES, ("left_", "right_")):
        names, infos = _names(_urdf(description_file, prefix_1=prefixes[0], prefix_2=prefixes[1]))
        assert len(infos) == 2, f"{len(infos)} hardware components with prefixes {prefixes}, expected 2"
        for prefix in prefixes:
            mine = [i for i in infos if i.name.startswith(prefix)]
            assert len(mine) == 1, f"no hardware component named with '{prefix}': {[i.name for i in infos]}"
            assert sorted(j.name for j in mine[0].joints) == [f"{prefix}joint1", f"{prefix}joint2"]
            assert [s.name for s in mine[0].sensors] == [f"{prefix}tcp_fts_sensor"]
            assert [g.name for g in mine[0].gpios] == [f"{prefix}flange_gpios"]
        stray = sorted(n for n in names if n != "world" and not n.startswith(prefixes))
        assert not stray, f"names without a robot's prefix (prefixes {prefixes}): {stray}"


@graded(points=1, hint="Task 11.1: the pedestals stand spacing apart along y, centred on the world origin: robot 1 at "
        "+spacing/2, robot 2 at -spacing/2 (use the spacing argument, not a number).")
def test_side_by_side(description_file: Path) -> None:
    for spacing in (1.5, 3.0):
        robot = ET.fromstring(_urdf(description_file, spacing=spacing))
        for prefix, sign in zip(PREFIXES, (1, -1), strict=True):
            mount = [j for j in robot.findall("joint") if j.find("child").get("link") == f"{prefix}base_link"]  # type: ignore[union-attr]
            assert mount, f"no joint holds {prefix}base_link"
            assert mount[0].find("parent").get("link") == "world", f"{prefix}base_link must hang from world"  # type: ignore[union-attr]
            origin = mount[0].find("origin")
            xyz = [float(v) for v in (origin.get("xyz") if origin is not None else "0 0 0").split()]  # type: ignore[union-attr]
            assert xyz == pytest.approx([0.0, sign * spacing / 2, 0.0]), f"spacing {spacing}: {prefix} robot at {xyz}"


@graded(points=1, hint="Task 11.1: with the same prefix twice, the library refuses the URDF and names the duplicate: "
        "your description must not hide that (no fixed names that differ anyway).")
def test_same_prefix_twice_is_a_clear_error(description_file: Path) -> None:
    urdf = _urdf(description_file, prefix_1="r1_", prefix_2="r1_")
    with pytest.raises(rw.DescriptionError, match="twice"):
        parse_ros2_control(urdf)


@graded(points=2, hint="Task 11.2: one broadcaster for both robots, and per robot a forward position controller and a "
        "trajectory controller whose names start with the robot's prefix and which only use its joints.")
def test_controllers_yaml(controllers_file: Path) -> None:
    try:
        data = yaml.safe_load(controllers_file.read_text()) or {}
    except yaml.YAMLError as exc:
        pytest.fail(f"{controllers_file.name} is not valid YAML: {exc}", pytrace=False)
    manager = (data.get("controller_manager") or {}).get("ros__parameters") or {}
    assert (manager.get(JSB) or {}).get("type") == "joint_state_broadcaster/JointStateBroadcaster"
    for prefix in PREFIXES:
        joints = [f"{prefix}joint1", f"{prefix}joint2"]
        for kind, type_name in (("forward_position_controller", "forward_command_controller/ForwardCommandController"),
                                ("joint_trajectory_controller", "joint_trajectory_controller/JointTrajectoryController")):
            name = prefix + kind
            assert (manager.get(name) or {}).get("type") == type_name, f"'{name}' is not declared as {type_name}"
            params = (data.get(name) or {}).get("ros__parameters") or {}
            assert params.get("joints") == joints, f"{name}: joints {params.get('joints')}, expected {joints}"
    errors = [f.message for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, "the YAML would not load on a Jazzy robot: " + "; ".join(errors)


@graded(points=3, hint="Task 11: each robot obeys its own controllers: r1's forward command moves r1 only, r2's "
        "trajectory moves r2 only.")
def test_independent_control(description_file: Path, controllers_file: Path) -> None:
    system = _start(description_file, controllers_file,
                    [JSB, "r1_forward_position_controller", "r2_joint_trajectory_controller"])
    try:
        system.publish("/r1_forward_position_controller/commands", Float64MultiArray(data=[0.5, -0.25]))
        system.publish("/r2_joint_trajectory_controller/joint_trajectory", JointTrajectory(
            joint_names=["r2_joint1", "r2_joint2"],
            points=[JointTrajectoryPoint(positions=[-0.6, 0.3], time_from_start=1.0)]))
        system.spin(1.5)
        joints = _joints(system)
    finally:
        system.shutdown()
    assert joints.get("r1_joint1") == pytest.approx(0.5) and joints.get("r1_joint2") == pytest.approx(-0.25), joints
    assert joints.get("r2_joint1") == pytest.approx(-0.6, abs=1e-3), joints
    assert joints.get("r2_joint2") == pytest.approx(0.3, abs=1e-3), joints


@graded(points=1, hint="Task 11: stopping one robot's controllers must leave the other robot's running.")
def test_one_robot_stops_alone(description_file: Path, controllers_file: Path) -> None:
    system = _start(description_file, controllers_file,
                    [JSB, "r1_forward_position_controller", "r2_forward_position_controller"])
    try:
        system.controller_manager.switch_controllers(deactivate=["r1_forward_position_controller"], strictness="strict")
        system.publish("/r2_forward_position_controller/commands", Float64MultiArray(data=[0.2, 0.4]))
        system.spin(0.1)
        joints = _joints(system)
        states = {c.name: c.state for c in system.controller_manager.list_controllers()}
    finally:
        system.shutdown()
    assert states["r2_forward_position_controller"] == "active", states
    assert joints.get("r2_joint1") == pytest.approx(0.2) and joints.get("r2_joint2") == pytest.approx(0.4), joints
