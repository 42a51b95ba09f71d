"""Grader of task 3: the roles of the controller manager, controllers, resource manager and hardware components.

The learner answers in ``task03_components/answers.py`` with functions of a running system. Every check brings
up at least two fresh systems that differ in what matters to the question (controllers active or inactive,
chained or not, one or two hardware components, hardware active, inactive or unconfigured, other rates) and
compares the learner's answer with the truth computed here from the introspection lists
(``list_controllers``, ``list_hardware_components``, ``list_hardware_interfaces``), so an answer copied from one
system cannot pass. The expected values are also spelled out where they follow from the specification alone
(rates, chain order), so a library regression shows up here too.
"""

from __future__ import annotations

import copy
import functools
import importlib.util
import reprlib
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis.errors import HypothesisException

from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.exceptions import RRBotWorkshopError

TASK = 3
ANSWERS = "answers.py"

#: Two RRBots in one URDF, prefixed left_ and right_: two hardware components, left_rrbot and right_rrbot.
TWO_RRBOTS_XACRO = """<?xml version="1.0"?>
<robot name="two_rrbots" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>
  <link name="world"/>
  <xacro:rrbot prefix="left_" parent="world"><origin xyz="0 -1 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot prefix="right_" parent="world"><origin xyz="0 1 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot_ros2_control name="rrbot" prefix="left_"/>
  <xacro:rrbot_ros2_control name="rrbot" prefix="right_"/>
</robot>
"""

#: Controllers of the two RRBots: a 250 Hz loop, a broadcaster restricted to four state interfaces, a forward
#: command controller on the left arm and a chainable PID (two references per joint) on the right arm at 50 Hz.
TWO_RRBOTS_CONTROLLERS: dict[str, Any] = {
    "controller_manager": {"ros__parameters": {
        "update_rate": 250,
        "joint_state_broadcaster": {"type": "joint_state_broadcaster/JointStateBroadcaster"},
        "left_forward_controller": {"type": "forward_command_controller/ForwardCommandController"},
        "right_pid": {"type": "pid_controller/PidController"},
    }},
    "joint_state_broadcaster": {"ros__parameters": {
        "joints": ["left_joint1", "right_joint2"], "interfaces": ["position", "velocity"],
    }},
    "left_forward_controller": {"ros__parameters": {
        "joints": ["left_joint1", "left_joint2"], "interface_name": "position",
    }},
    "right_pid": {"ros__parameters": {
        "dof_names": ["right_joint1", "right_joint2"], "command_interface": "velocity",
        "reference_and_state_interfaces": ["position", "velocity"], "update_rate": 50,
        "gains": {"right_joint1": {"p": 1.0}, "right_joint2": {"p": 1.0}},
    }},
}

#: RRBot's controllers with their own rates on a 100 Hz loop: 30 Hz -> 33 Hz, 500 Hz -> 100 Hz, 50 Hz -> 50 Hz.
RATES_CONTROLLERS: dict[str, Any] = {
    "controller_manager": {"ros__parameters": {
        "update_rate": 100,
        "joint_state_broadcaster": {"type": "joint_state_broadcaster/JointStateBroadcaster"},
        "forward_position_controller": {"type": "forward_command_controller/ForwardCommandController"},
        "joint_trajectory_controller": {"type": "joint_trajectory_controller/JointTrajectoryController"},
    }},
    "joint_state_broadcaster": {"ros__parameters": {"update_rate": 30}},
    "forward_position_controller": {"ros__parameters": {
        "joints": ["joint1", "joint2"], "interface_name": "position", "update_rate": 500,
    }},
    "joint_trajectory_controller": {"ros__parameters": {
        "joints": ["joint1", "joint2"], "command_interfaces": ["position"], "state_interfaces": ["position"],
        "update_rate": 50,
    }},
}

#: Every controller slower than the 100 Hz loop (50, 25 and 20 Hz: whole divisors of it), the trajectory controller on
#: joint2 then joint1 (its state interfaces come in that order: an answer that must be sorted shows it).
SLOW_CONTROLLERS: dict[str, Any] = {
    "controller_manager": {"ros__parameters": {
        "update_rate": 100,
        "joint_state_broadcaster": {"type": "joint_state_broadcaster/JointStateBroadcaster"},
        "forward_position_controller": {"type": "forward_command_controller/ForwardCommandController"},
        "joint_trajectory_controller": {"type": "joint_trajectory_controller/JointTrajectoryController"},
    }},
    "joint_state_broadcaster": {"ros__parameters": {"update_rate": 50}},
    "forward_position_controller": {"ros__parameters": {
        "joints": ["joint2", "joint1"], "interface_name": "position", "update_rate": 25,
    }},
    "joint_trajectory_controller": {"ros__parameters": {
        "joints": ["joint2", "joint1"], "command_interfaces": ["position"], "state_interfaces": ["position", "velocity"],
        "update_rate": 20,
    }},
}

JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
PID1, PID2 = "pid_controller_joint1", "pid_controller_joint2"


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def answers(task_file: Callable[[int, str], Path]) -> ModuleType:
    """The learner's answers module, freshly imported from disk."""
    path = task_file(TASK, ANSWERS)
    name = "rrbot_workshop_task03_answers"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"{ANSWERS} cannot be loaded as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)  # an error in the learner's file propagates, at its line
    return module


@pytest.fixture(scope="module")
def two_rrbots_urdf(tmp_path_factory: pytest.TempPathFactory) -> str:
    from rrbot_workshop.description import process_xacro

    path = tmp_path_factory.mktemp("task03") / "two_rrbots.urdf.xacro"
    path.write_text(TWO_RRBOTS_XACRO)
    return process_xacro(path)


# --------------------------------------------------------------------------------------------- systems


@contextmanager
def _up(**kwargs: Any) -> Iterator[System]:
    system = bringup(**kwargs)
    try:
        yield system
    finally:
        system.shutdown()


def forward_system() -> Any:
    """RRBot: broadcaster and forward position controller active, trajectory controller inactive."""
    return _up(description="rrbot", controllers="rrbot_controllers.yaml", spawn=[JSB, FWD], inactive=[JTC])


def trajectory_system() -> Any:
    """RRBot: broadcaster and trajectory controller active, forward position controller inactive."""
    return _up(description="rrbot", controllers="rrbot_controllers.yaml", spawn=[JSB, JTC], inactive=[FWD])


def chained_system() -> Any:
    """RRBot: trajectory controller -> two PIDs -> hardware velocity; forward position controller inactive."""
    return _up(description="rrbot", controllers="rrbot_chained_controllers.yaml",
               xacro_args={"calculate_dynamics": True}, spawn=[JSB, PID1, PID2, JTC], inactive=[FWD])


def hardware_state_system(state: str) -> Any:
    """RRBot whose hardware starts in ``state``; the forward position controller configured only."""
    spawn = [JSB] if state != "unconfigured" else []
    return _up(description="rrbot", controllers="rrbot_controllers.yaml", spawn=spawn, inactive=[FWD],
               hardware_initial_state={"rrbot": state})


def two_rrbots_system(urdf: str, right: str = "inactive") -> Any:
    """Two RRBots: left hardware active with its forward controller active, right hardware ``right``, PID inactive.

    The broadcaster reads a right-arm interface, so it is only configured when the right arm offers none.
    """
    spawn, inactive = [JSB, "left_forward_controller"], ["right_pid"]
    if right == "unconfigured":
        spawn, inactive = ["left_forward_controller"], [JSB, "right_pid"]
    return _up(description=urdf, controllers=TWO_RRBOTS_CONTROLLERS, spawn=spawn, inactive=inactive,
               hardware_initial_state={"right_rrbot": right})


def slow_system() -> Any:
    """RRBot whose controllers all run slower than the loop; the trajectory controller (joint2, joint1) active."""
    return _up(description="rrbot", controllers=copy.deepcopy(SLOW_CONTROLLERS), spawn=[JSB, JTC], inactive=[FWD])


def rates_system(loop: int = 100) -> Any:
    """RRBot whose controllers ask for rates of their own (30, 500, 50 Hz), on a ``loop`` Hz loop."""
    config = copy.deepcopy(RATES_CONTROLLERS)
    config["controller_manager"]["ros__parameters"]["update_rate"] = loop
    return _up(description="rrbot", controllers=config, spawn=[JSB, FWD], inactive=[JTC])


# --------------------------------------------------------------------------------------------- truth


def _label(state: Any) -> str:
    return str(getattr(state, "label", state))


def true_update_order(system: System) -> list[str]:
    return [c.name for c in system.controller_manager.list_controllers() if c.state == "active"]


def true_claimant(system: System, interface: str) -> str | None:
    holders = [c.name for c in system.controller_manager.list_controllers() if interface in c.claimed_interfaces]
    assert len(holders) <= 1, f"grader: {interface} claimed by {holders}"
    return holders[0] if holders else None


def true_state_interfaces(system: System, controller: str) -> list[str]:
    entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
    if entry.state != "active":
        return []
    loans = system.controller_manager.get_controller(controller).state_interfaces
    return sorted(loan.name for loan in loans)


def true_references(system: System, controller: str) -> list[str]:
    entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
    return sorted(f"{controller}/{r}" for r in entry.reference_interfaces)


def true_owner(system: System, interface: str) -> str | None:
    for comp in system.controller_manager.list_hardware_components():
        if interface in {i.name for i in [*comp.command_interfaces, *comp.state_interfaces]}:
            return comp.name
    return None


def true_available(system: System) -> dict[str, list[str]]:
    itfs = system.controller_manager.list_hardware_interfaces()
    return {
        "state": sorted(i.name for i in itfs.state_interfaces if i.is_available),
        "command": sorted(i.name for i in itfs.command_interfaces if i.is_available),
    }


def true_hardware_states(system: System) -> dict[str, str]:
    return {comp.name: _label(comp.state) for comp in system.controller_manager.list_hardware_components()}


def true_claimable(system: System) -> list[str]:
    states = true_hardware_states(system)
    out = []
    for itf in system.controller_manager.list_hardware_interfaces().command_interfaces:
        owner = true_owner(system, itf.name)
        if itf.is_available and not itf.is_claimed and (owner is None or states[owner] == "active"):
            out.append(itf.name)
    return sorted(out)


def _same(what: str, got: Any, expected: Any) -> None:
    """``got == expected``, or a sentence; a list with the right names in another order says which order."""
    if got == expected:
        return
    if isinstance(got, (list, tuple)) and isinstance(expected, list) and sorted(map(str, got)) == sorted(expected):
        order = "sorted by name" if expected == sorted(expected) else "in update order"
        first = next(i for i, (a, b) in enumerate(zip(got, expected, strict=True)) if a != b)
        pytest.fail(f"{what}: your answer has the right names but not {order}: at position {first + 1} it has "
                    f"{got[first]!r} where {expected[first]!r} belongs", pytrace=False)
    pytest.fail(f"{what}: your answer{_brief_difference(got, expected)}", pytrace=False)


@contextmanager
def _truth_standing_in(answers: ModuleType) -> Iterator[None]:
    """While task 3.9 is asked, the answers it may build on (3.7, 3.8, 3.10) are the truth: their own checks judge
    them, so one slip there costs their rule, not 3.9's too."""
    truth: dict[str, Callable[..., Any]] = {"owner_of_interface": true_owner, "available_interfaces": true_available,
                                            "hardware_states": true_hardware_states}
    kept = {name: getattr(answers, name, None) for name in truth}
    for name, function in truth.items():
        setattr(answers, name, function)
    try:
        yield
    finally:
        for name, function in kept.items():
            setattr(answers, name, function)


def _claimable(answers: ModuleType, system: System) -> Any:
    with _truth_standing_in(answers):
        return _sorted_list("claimable", answers.claimable_command_interfaces(system))


def _sorted_list(what: str, got: Any) -> Any:
    """The learner's list as it is (never sorted here); anything else than a list fails with a sentence."""
    if not isinstance(got, (list, tuple)):
        pytest.fail(f"{what}: expected a list of names, got {type(got).__name__} {got!r}", pytrace=False)
    return list(got)


# --------------------------------------------------------------------------------------------- controller manager


@graded(points=1, hint=(
    "Task 3.1: the loop rate is the controller manager's update_rate in [Hz], from the YAML (controller_manager: "
    "ros__parameters: update_rate); the grader also brings up 250 Hz and 40 Hz systems, so ask the system.",
    "system.controller_manager.get_update_rate() returns it.",
    "return system.controller_manager.get_update_rate()",
))
def test_loop_rate(answers: ModuleType, two_rrbots_urdf: str) -> None:
    for what, make in (("RRBot with its 100 Hz YAML", forward_system),
                       ("two RRBots on a 250 Hz loop", lambda: two_rrbots_system(two_rrbots_urdf)),
                       ("RRBot on a 40 Hz loop", lambda: rates_system(40)),
                       ("RRBot on a 100 Hz loop whose controllers all run slower (50, 25, 20 Hz)", slow_system)):
        with make() as system:
            _same(f"loop_rate on {what}", answers.loop_rate(system), system.controller_manager.get_update_rate())


@graded(points=2, hint=(
    "Task 3.2: each loaded controller runs at its own rate, settled when it is configured: no rate (or 0) means "
    "the loop rate, a rate above the loop rate is cut to it, one that does not divide it is rounded to one the "
    "loop can keep (30 Hz on a 100 Hz loop: every third cycle, 33 Hz).",
    "Each entry of system.controller_manager.list_controllers() has .name and .update_rate, already settled.",
    "return {c.name: c.update_rate for c in system.controller_manager.list_controllers()}",
))
def test_controller_update_rates(answers: ModuleType, two_rrbots_urdf: str) -> None:
    cases = (("a 100 Hz loop whose controllers ask for 30, 500 and 50 Hz", rates_system),
             ("a 40 Hz loop whose controllers ask for 30, 500 and 50 Hz", lambda: rates_system(40)),
             ("two RRBots on a 250 Hz loop, the PID at 50 Hz", lambda: two_rrbots_system(two_rrbots_urdf)),
             ("a 100 Hz loop whose controllers all run slower (50, 25, 20 Hz)", slow_system))
    for what, make in cases:
        with make() as system:
            truth = {c.name: c.update_rate for c in system.controller_manager.list_controllers()}
            _same(f"controller_update_rates on {what}", answers.controller_update_rates(system), truth)


@graded(points=3, hint=(
    "Task 3.3: only ACTIVE controllers are updated, in the manager's order: preceding controllers first (the "
    "trajectory controller before the PIDs it feeds). The answer changes after a switch.",
    "list_controllers() already comes in update order; each entry has .state ('active', 'inactive', ...).",
    'return [c.name for c in system.controller_manager.list_controllers() if c.state == "active"]',
))
def test_update_order(answers: ModuleType) -> None:
    with forward_system() as system:
        _same("update_order with the forward controller active, the trajectory controller inactive",
              _sorted_list("update_order", answers.update_order(system)), true_update_order(system))
        system.controller_manager.switch_controllers(activate=[JTC], deactivate=[FWD], strictness="strict")
        _same("update_order after switching to the trajectory controller",
              _sorted_list("update_order", answers.update_order(system)), true_update_order(system))
    with chained_system() as system:
        truth = true_update_order(system)
        assert truth.index(JTC) < truth.index(PID1) and truth.index(JTC) < truth.index(PID2), truth
        _same("update_order of the chain joint_trajectory_controller -> pid_controller_joint1/2",
              _sorted_list("update_order", answers.update_order(system)), truth)


# --------------------------------------------------------------------------------------------- controllers


@graded(points=2, hint=(
    "Task 3.4: a command interface is held by at most one controller, the active one that claimed it; None when "
    "nobody holds it. A PID's reference interface is a command interface too, claimed by the trajectory "
    "controller in the chain.",
    "Each entry of list_controllers() has .claimed_interfaces; the resource manager keeps the same record "
    "(system.resource_manager.command_interface_holder(name)).",
    "return next((c.name for c in system.controller_manager.list_controllers() if interface in "
    "c.claimed_interfaces), None)",
))
def test_claimant_of(answers: ModuleType) -> None:
    cases = {
        forward_system: ["joint1/position", "joint2/position", "joint1/velocity", "flange_gpios/digital_out_1"],
        trajectory_system: ["joint1/position", "joint2/position", "joint2/velocity"],
        chained_system: ["pid_controller_joint1/joint1/position", "pid_controller_joint2/joint2/position",
                         "joint1/velocity", "joint2/velocity", "joint1/position"],
    }
    for make, interfaces in cases.items():
        with make() as system:
            for itf in interfaces:
                _same(f"claimant_of('{itf}') [{make.__doc__}]", answers.claimant_of(system, itf),
                      true_claimant(system, itf))


@graded(points=2, hint=(
    "Task 3.5: a controller reads state interfaces only while it is ACTIVE ([] when it is not); the broadcaster "
    "reads every available one unless both its joints and interfaces are set. Sorted by name.",
    "An active controller's entry in list_controllers() has .state and .required_state_interfaces (the loans it "
    "holds: system.controller_manager.get_controller(name).state_interfaces).",
    "entry = next(c for c in cm.list_controllers() if c.name == controller)\n"
    'return sorted(entry.required_state_interfaces) if entry.state == "active" else []',
))
def test_state_interfaces_read_by(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with forward_system() as system:
        for ctrl in (JSB, FWD, JTC):
            _same(f"state_interfaces_read_by('{ctrl}') with {ctrl} {_state_of(system, ctrl)}",
                  _sorted_list("state_interfaces_read_by", answers.state_interfaces_read_by(system, ctrl)),
                  true_state_interfaces(system, ctrl))
    with trajectory_system() as system:
        _same(f"state_interfaces_read_by('{JTC}') with it active",
              _sorted_list("state_interfaces_read_by", answers.state_interfaces_read_by(system, JTC)),
              true_state_interfaces(system, JTC))
    with slow_system() as system:
        _same(f"state_interfaces_read_by('{JTC}') with it active on joints [joint2, joint1] (the answer is sorted by "
              "name, whatever the order of the joints)",
              _sorted_list("state_interfaces_read_by", answers.state_interfaces_read_by(system, JTC)),
              true_state_interfaces(system, JTC))
    with two_rrbots_system(two_rrbots_urdf) as system:
        for ctrl in (JSB, "right_pid"):
            _same(f"state_interfaces_read_by('{ctrl}') on two RRBots",
                  _sorted_list("state_interfaces_read_by", answers.state_interfaces_read_by(system, ctrl)),
                  true_state_interfaces(system, ctrl))


def _state_of(system: System, controller: str) -> str:
    return next(c.state for c in system.controller_manager.list_controllers() if c.name == controller)


@graded(points=2, hint=(
    "Task 3.6: a chainable controller exports reference interfaces at configure, named "
    "'<controller>/<joint>/<interface>'; a controller that is not chainable exports none. Sorted by name.",
    "list_controllers() gives .reference_interfaces without the '<controller>/' prefix; "
    "system.resource_manager.get_controller_reference_interface_names(name) gives the full names.",
    "entry = next(c for c in cm.list_controllers() if c.name == controller)\n"
    'return sorted(f"{controller}/{r}" for r in entry.reference_interfaces)',
))
def test_reference_interfaces_of(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with chained_system() as system:
        for ctrl in (PID1, PID2, JTC, JSB):
            _same(f"reference_interfaces_of('{ctrl}') in the chain",
                  _sorted_list("reference_interfaces_of", answers.reference_interfaces_of(system, ctrl)),
                  true_references(system, ctrl))
        cm = system.controller_manager
        cm.switch_controllers(deactivate=[JTC, PID1, PID2], strictness="strict")
        for step, when in ((cm.cleanup_controller, "cleaned up"), (cm.configure_controller, "configured again")):
            step(PID1)
            _same(f"reference_interfaces_of('{PID1}') {when}",
                  _sorted_list("reference_interfaces_of", answers.reference_interfaces_of(system, PID1)),
                  true_references(system, PID1))
    with two_rrbots_system(two_rrbots_urdf) as system:
        for ctrl in ("right_pid", "left_forward_controller"):
            _same(f"reference_interfaces_of('{ctrl}') on two RRBots (right_pid configured, inactive)",
                  _sorted_list("reference_interfaces_of", answers.reference_interfaces_of(system, ctrl)),
                  true_references(system, ctrl))


# --------------------------------------------------------------------------------------------- resource manager


@graded(points=2, hint=(
    "Task 3.7: every interface a <ros2_control> tag declares belongs to that hardware component (two RRBots: "
    "left_rrbot and right_rrbot); an interface a controller exports belongs to none: None.",
    "list_hardware_components() lists each component's .command_interfaces and .state_interfaces (each with "
    ".name); system.resource_manager.hardware_of_interface(name) answers too.",
    "for comp in cm.list_hardware_components():\n    if interface in [i.name for i in (*comp.command_interfaces, "
    "*comp.state_interfaces)]:\n        return comp.name\nreturn None",
))
def test_owner_of_interface(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with two_rrbots_system(two_rrbots_urdf) as system:
        for itf in ("left_joint1/position", "right_joint2/velocity", "right_tcp_fts_sensor/fx",
                    "left_flange_gpios/digital_out_2", "right_pid/right_joint1/position"):
            _same(f"owner_of_interface('{itf}') on two RRBots", answers.owner_of_interface(system, itf),
                  true_owner(system, itf))
    with chained_system() as system:
        for itf in ("joint2/velocity", "tcp_fts_sensor/tz", "pid_controller_joint1/joint1/position"):
            _same(f"owner_of_interface('{itf}') on RRBot", answers.owner_of_interface(system, itf),
                  true_owner(system, itf))


def _available(answers: ModuleType, system: System) -> dict[str, list[str]]:
    got = answers.available_interfaces(system)
    assert isinstance(got, dict) and set(got) == {"state", "command"}, (
        f'available_interfaces must return {{"state": [...], "command": [...]}}, got {got!r}'
    )
    return {k: list(v) for k, v in got.items()}


@graded(points=2, hint=(
    "Task 3.8: a component's interfaces are available while it is INACTIVE or ACTIVE (none while unconfigured); "
    "a chainable controller's exported interfaces while it is active. Both lists sorted by name.",
    "list_hardware_interfaces() has .state_interfaces and .command_interfaces, each entry with .name and "
    ".is_available.",
    'listing = cm.list_hardware_interfaces()\nreturn {"state": sorted(i.name for i in listing.state_interfaces '
    'if i.is_available), "command": sorted(... command_interfaces if i.is_available)}',
))
def test_available_interfaces(answers: ModuleType, two_rrbots_urdf: str) -> None:
    for state in ("unconfigured", "inactive"):
        with hardware_state_system(state) as system:
            _same(f"available_interfaces with the RRBot hardware {state}", _available(answers, system),
                  true_available(system))
    with two_rrbots_system(two_rrbots_urdf, right="unconfigured") as system:
        _same("available_interfaces with left_rrbot active and right_rrbot unconfigured",
              _available(answers, system), true_available(system))
    with chained_system() as system:
        _same("available_interfaces with the PIDs active (their references count)", _available(answers, system),
              true_available(system))


@graded(points=3, hint=(
    "Task 3.9: claimable = available AND not claimed AND, for a hardware interface, owned by an ACTIVE component: "
    "inactive hardware shows its interfaces but refuses to be commanded. Sorted by name.",
    "Combine your answers 3.7 (owner), 3.8 (available) and 3.10 (component states) with .is_claimed from "
    "list_hardware_interfaces().",
    'keep name if not claimed and (owner_of_interface(system, name) is None or '
    'hardware_states(system)[owner_of_interface(system, name)] == "active")',
))
def test_claimable_command_interfaces(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with forward_system() as system:
        _same("claimable_command_interfaces with the forward controller active", _claimable(answers, system),
              true_claimable(system))
    with hardware_state_system("inactive") as system:
        truth = true_claimable(system)
        assert truth == [], truth
        _same("claimable_command_interfaces with the RRBot hardware inactive", _claimable(answers, system), truth)
    with two_rrbots_system(two_rrbots_urdf, right="inactive") as system:
        _same("claimable_command_interfaces with left_rrbot active and right_rrbot inactive",
              _claimable(answers, system), true_claimable(system))
    with chained_system() as system:
        _same("claimable_command_interfaces in the chain", _claimable(answers, system), true_claimable(system))


# --------------------------------------------------------------------------------------------- hardware


def _hardware_states(answers: ModuleType, system: System) -> dict[str, str]:
    got = answers.hardware_states(system)
    assert isinstance(got, dict), f"hardware_states must return a dict, got {type(got).__name__} {got!r}"
    return got


@graded(points=2, hint=(
    "Task 3.10: each hardware component has a lifecycle of its own (unconfigured, inactive, active); it follows "
    "hardware_components_initial_state and set_hardware_component_state.",
    "list_hardware_components() gives .name and .state, a lifecycle State whose .label is the text.",
    "return {c.name: c.state.label for c in system.controller_manager.list_hardware_components()}",
))
def test_hardware_states(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with hardware_state_system("unconfigured") as system:
        _same("hardware_states of an unconfigured RRBot", _hardware_states(answers, system), true_hardware_states(system))
        system.controller_manager.set_hardware_component_state("rrbot", "active")
        _same("hardware_states after activating it", _hardware_states(answers, system), true_hardware_states(system))
    with two_rrbots_system(two_rrbots_urdf, right="inactive") as system:
        _same("hardware_states of two RRBots", _hardware_states(answers, system), true_hardware_states(system))
        system.controller_manager.set_hardware_component_state("left_rrbot", "inactive")
        system.controller_manager.set_hardware_component_state("right_rrbot", "unconfigured")
        _same("hardware_states after changing both", _hardware_states(answers, system), true_hardware_states(system))


# --------------------------------------------------------------------------------------------- generated sequences

#: Scenarios run at most by a generated check, generation and shrinking together (keeps grading fast).
SCENARIO_BUDGET = 50

CHAIN = (JSB, PID1, PID2, JTC, FWD)
_STEP = st.one_of(
    st.tuples(st.sampled_from(("load", "configure", "activate", "deactivate", "cleanup")), st.sampled_from(CHAIN)),
    st.tuples(st.just("hardware"), st.sampled_from(("unconfigured", "inactive", "active"))),
)


@functools.cache
def _chained_urdf() -> str:
    """RRBot's URDF with dynamics (the chain's PIDs command velocities), expanded once."""
    from rrbot_workshop.description import descriptions_root, process_xacro

    return process_xacro(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", calculate_dynamics=True)


@functools.cache
def _chained_yaml() -> dict[str, Any]:
    """The chained controllers YAML, read once (callers copy it)."""
    from rrbot_workshop.description import descriptions_root

    return yaml.safe_load((descriptions_root() / "rrbot" / "config" / "rrbot_chained_controllers.yaml").read_text())


_START = st.sampled_from(("not loaded", "unconfigured", "inactive", "active"))


def _start_chain(start: tuple[str, ...]) -> tuple[System, str]:
    """The chained RRBot with each controller of CHAIN in its start state (made consistent); and in words."""
    wanted = dict(zip(CHAIN, start, strict=True))
    if wanted[JTC] == "active" and (wanted[PID1] != "active" or wanted[PID2] != "active"):
        wanted[JTC] = "inactive"  # the trajectory controller needs both PIDs active
    if wanted[FWD] == "active" and "active" in (wanted[PID1], wanted[PID2]):
        wanted[FWD] = "inactive"  # a joint is commanded in position or in velocity, not both (the mock refuses)
    spawn = [n for n, s in wanted.items() if s == "active"]
    inactive = [n for n, s in wanted.items() if s == "inactive"]
    system = bringup(description=_chained_urdf(), controllers=copy.deepcopy(_chained_yaml()), spawn=spawn,
                     inactive=inactive)
    for name, state in wanted.items():
        if state == "unconfigured":
            system.controller_manager.load_controller(name)
    loaded = ", ".join(f"{n} {s}" for n, s in wanted.items() if s != "not loaded") or "no controller loaded"
    return system, f"chained RRBot with {loaded}"


def _apply(system: System, op: str, arg: str) -> bool:
    """One step done with the library; False when the controller manager refuses it (nothing changes then)."""
    cm = system.controller_manager
    try:
        if op == "hardware":
            return bool(cm.set_hardware_component_state("rrbot", arg))
        if op == "load":
            cm.load_controller(arg)
        elif op == "configure":
            cm.configure_controller(arg)
        elif op == "activate":
            cm.switch_controllers(activate=[arg], strictness="strict")
        elif op == "deactivate":
            cm.switch_controllers(deactivate=[arg], strictness="strict")
        else:
            cm.cleanup_controller(arg)
    except RRBotWorkshopError:
        return False
    return True


def _first_difference(answers: ModuleType, system: System) -> str | None:
    """The first answer that differs from the controller manager's lists, as a sentence; None if all agree."""
    cm = system.controller_manager
    loaded = [c.name for c in cm.list_controllers()]
    commands = [i.name for i in cm.list_hardware_interfaces().command_interfaces]
    questions: list[tuple[str, Callable[[], Any], Callable[[], Any]]] = [
        ("update_order(system)", lambda: answers.update_order(system), lambda: true_update_order(system)),
        ("hardware_states(system)", lambda: _hardware_states(answers, system), lambda: true_hardware_states(system)),
        ("available_interfaces(system)", lambda: _available(answers, system), lambda: true_available(system)),
        ("claimable_command_interfaces(system)", lambda: _claimable(answers, system), lambda: true_claimable(system)),
        ("controller_update_rates(system)", lambda: answers.controller_update_rates(system),
         lambda: {c.name: c.update_rate for c in cm.list_controllers()}),
    ]
    for itf in commands:
        questions.append((f"claimant_of(system, '{itf}')", lambda i=itf: answers.claimant_of(system, i),
                          lambda i=itf: true_claimant(system, i)))
    for name in loaded:
        questions.append((f"state_interfaces_read_by(system, '{name}')",
                          lambda n=name: answers.state_interfaces_read_by(system, n),
                          lambda n=name: _OneOf(true_state_interfaces(system, n), _required_if_active(system, n))))
        questions.append((f"reference_interfaces_of(system, '{name}')",
                          lambda n=name: answers.reference_interfaces_of(system, n),
                          lambda n=name: true_references(system, n)))
    for what, mine, truth in questions:
        got, want = mine(), truth()
        if isinstance(got, tuple):
            got = list(got)
        accepted = want.answers if isinstance(want, _OneOf) else (want,)
        if got not in accepted:
            return f"{what}{_brief_difference(got, accepted[0])}"
    return None


class _OneOf:
    """Several right answers: the loans a controller holds, or the interfaces list_controllers() says it requires.

    They differ only when an active controller's hardware has left the active and inactive states (the loans stay,
    the list of available interfaces the broadcaster requires empties); the task's own hints accept both.
    """

    def __init__(self, *answers: Any) -> None:
        self.answers = answers


def _required_if_active(system: System, controller: str) -> list[str]:
    entry = next(c for c in system.controller_manager.list_controllers() if c.name == controller)
    return sorted(entry.required_state_interfaces) if entry.state == "active" else []


def _short(value: Any) -> str:
    """``repr`` of a value, long lists and strings abridged."""
    shortener = reprlib.Repr()
    shortener.maxlist = shortener.maxdict = 2
    shortener.maxstring = shortener.maxother = 40
    return shortener.repr(value)


def _brief_difference(got: Any, want: Any) -> str:
    """Where ``got`` first differs from ``want``, in a few words."""
    if isinstance(got, dict) and isinstance(want, dict):
        keys = [k for k in [*want, *(k for k in got if k not in want)] if got.get(k, ...) != want.get(k, ...)]
        if keys and keys[0] in got and keys[0] in want:
            more = f" (and {len(keys) - 1} more key(s))" if len(keys) > 1 else ""
            return f"[{keys[0]!r}]{_brief_difference(got[keys[0]], want[keys[0]])}{more}"
        if keys:
            return f" has {'no key' if keys[0] not in got else 'the unexpected key'} {keys[0]!r}"
    if isinstance(got, list) and isinstance(want, list) and sorted(map(str, got)) == sorted(want) and got:
        first = next(i for i, (a, b) in enumerate(zip(got, want, strict=True)) if a != b)
        return f" has the right names in the wrong order: {got[first]!r} where {want[first]!r} belongs"
    if isinstance(got, list) and isinstance(want, list) and len(got) + len(want) > 4:
        missing, extra = [n for n in want if n not in got], [n for n in got if n not in want]
        parts = [f"misses {len(missing)} name(s) such as {missing[0]!r}"] if missing else []
        parts += [f"has {len(extra)} name(s) it should not, such as {extra[0]!r}"] if extra else []
        return " " + " and ".join(parts or [f"gave {len(got)} names where {len(want)} were expected"])
    return f" gave {_short(got)}, expected {_short(want)}"


def _case(problem: str, when: str, where: str, done: list[str]) -> str:
    """The failing case in one sentence, the answer that differs first; details dropped when too long to read."""
    text = f"{problem}, {when}, on the {where}"
    if len(text) > 250:
        text = f"{problem}, {when}, on the %s" % where.split(" with ")[0]
    if len(text) > 250 and len(done) > 1:
        text = f"{problem}, after {len(done)} steps ending with {done[-1]!r}, on the %s" % where.split(" with ")[0]
    return text


#: The answers the generated sequences compare: when one of their checks fails, so may the sequences.
_COMPARED = (
    "test_update_order", "test_hardware_states", "test_available_interfaces", "test_claimable_command_interfaces",
    "test_controller_update_rates", "test_claimant_of", "test_state_interfaces_read_by",
    "test_reference_interfaces_of",
)


@graded(points=2, after=_COMPARED, hint=(
    "Tasks 3.3-3.10 after any sequence of load, configure, activate, deactivate, cleanup and hardware state "
    "changes on the chained RRBot (joint_trajectory_controller -> pid_controller_joint1/2): every answer must be "
    "what the controller manager's lists say at that moment. The reason shows the shortest sequence where yours "
    "differs.",
    "Replay the sequence the reason names with cm.load_controller, cm.configure_controller, cm.switch_controllers("
    "..., strictness=\"strict\"), cm.cleanup_controller and cm.set_hardware_component_state(\"rrbot\", state), then "
    "print your answer next to list_controllers(), list_hardware_components() and list_hardware_interfaces().",
    "Compute every answer from the system each time it is asked (nothing cached, nothing typed in); filter on the "
    "states the question names (active controllers, available interfaces, active hardware).",
))
def test_any_sequence_matches_the_controller_manager(answers: ModuleType) -> None:
    found: list[str] = []
    raised: list[BaseException] = []  # the learner's first error: raised as it is after the search, not shrunk
    budget = [SCENARIO_BUDGET]  # examples run at most: once spent, the smallest difference found so far is reported

    @settings(derandomize=True, database=None, deadline=None, max_examples=12,
              suppress_health_check=list(HealthCheck))
    @given(st.tuples(*[_START] * len(CHAIN)), st.lists(_STEP, max_size=5))
    @example(("not loaded",) * len(CHAIN), [])  # the simplest cases first: nothing loaded, nothing done ...
    @example(("not loaded",) * len(CHAIN), [("hardware", "inactive")])  # ... then the hardware leaves active
    @example(("not loaded",) * len(CHAIN), [("hardware", "unconfigured")])
    def scenario(start: tuple[str, ...], steps: list[tuple[str, str]]) -> None:
        if raised or budget[0] <= 0:
            return
        budget[0] -= 1
        system, where = _start_chain(start)
        done: list[str] = []
        problem = None
        try:
            problem = _first_difference(answers, system)
            for op, arg in steps:
                if problem:
                    break
                accepted = _apply(system, op, arg)
                done.append(f"{op} {arg}" + ("" if accepted else " (refused)"))
                problem = _first_difference(answers, system)
        except Exception as exc:  # noqa: BLE001 - the learner's error, raised again below with its traceback
            exc.add_note(f"(on the chained RRBot, after: {', then '.join(done)})")
            raised.append(exc)
            return
        finally:
            system.shutdown()
        if problem:
            when = f"after {', then '.join(done)}" if done else "as brought up"
            found.append(_case(problem, when, where, done))
            raise AssertionError(found[-1])

    try:
        scenario()
    except (AssertionError, HypothesisException):
        if not found:
            raise
        pytest.fail(f"in the shortest case found, {found[-1]}", pytrace=False)
    if raised:
        raise raised[0]
