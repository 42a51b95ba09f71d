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

import importlib.util
import logging
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded

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

JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
PID1, PID2 = "pid_controller_joint1", "pid_controller_joint2"


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def answers(task_file: Callable[[int, str], Path]) -> ModuleType:
    """The learner's answers module, freshly imported from disk."""
    path = task_file(TASK, ANSWERS)
    name = "rrbot_workshop_task03_answers"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"cannot load {path} as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # noqa: BLE001 - any error in the learner's file fails the checks that need it
        sys.modules.pop(name, None)
        pytest.fail(f"{path} cannot be imported: {type(exc).__name__}: {exc}", pytrace=False)
    return module


@pytest.fixture(scope="module")
def two_rrbots_urdf(tmp_path_factory: pytest.TempPathFactory) -> str:
    from rrbot_workshop.description import process_xacro

    path = tmp_path_factory.mktemp("task03") / "two_rrbots.urdf.xacro"
    path.write_text(TWO_RRBOTS_XACRO)
    return process_xacro(path)


@pytest.fixture(autouse=True)
def _quiet() -> Iterator[None]:
    """Rejected switches log warnings on purpose; keep the rubric readable."""
    logger = logging.getLogger("rrbot_workshop")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    yield
    logger.setLevel(level)


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


def rates_system() -> Any:
    return _up(description="rrbot", controllers=RATES_CONTROLLERS, spawn=[JSB, FWD], inactive=[JTC])


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
    assert got == expected, f"{what}: your answer is {got!r}, expected {expected!r}"


def _sorted_list(what: str, got: Any) -> list[str]:
    assert isinstance(got, (list, tuple)), f"{what}: expected a list of names, got {type(got).__name__} {got!r}"
    return list(got)


# --------------------------------------------------------------------------------------------- controller manager


@graded(points=1, hint="task 3.1: the loop rate is the controller manager's update_rate in [Hz] "
        "(system.controller_manager.get_update_rate()); the grader also uses a 250 Hz system.")
def test_loop_rate(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with forward_system() as system:
        _same("loop_rate on RRBot (100 Hz YAML)", answers.loop_rate(system), 100)
    with two_rrbots_system(two_rrbots_urdf) as system:
        _same("loop_rate on a 250 Hz system", answers.loop_rate(system), 250)


@graded(points=2, hint="task 3.2: {name: update_rate} for every loaded controller, from list_controllers(); the "
        "rate is settled at configure (no rate -> loop rate, above the loop rate -> loop rate, 30 Hz on 100 Hz -> 33).")
def test_controller_update_rates(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with rates_system() as system:
        expected = {JSB: 33, FWD: 100, JTC: 50}
        assert {c.name: c.update_rate for c in system.controller_manager.list_controllers()} == expected
        _same("controller_update_rates (100 Hz loop, rates 30/500/50 Hz asked)",
              answers.controller_update_rates(system), expected)
    with two_rrbots_system(two_rrbots_urdf) as system:
        expected = {JSB: 250, "left_forward_controller": 250, "right_pid": 50}
        assert {c.name: c.update_rate for c in system.controller_manager.list_controllers()} == expected
        _same("controller_update_rates (250 Hz loop)", answers.controller_update_rates(system), expected)


@graded(points=3, hint="task 3.3: only ACTIVE controllers are updated (inactive ones are skipped), in the order "
        "of list_controllers(): preceding controllers first, e.g. joint_trajectory_controller before the PIDs it "
        "feeds. The answer changes after a switch.")
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


@graded(points=2, hint="task 3.4: the holder of a command interface is the active controller that claimed it "
        "(claimed_interfaces in list_controllers(), or the resource manager's record); None when nobody holds it. "
        "A PID's reference interface is claimed by the trajectory controller in the chain.")
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


@graded(points=2, hint="task 3.5: the sorted state interfaces an ACTIVE controller holds ([] for an inactive one); "
        "joint_state_broadcaster reads every available state interface unless both joints and interfaces are set.")
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
    with two_rrbots_system(two_rrbots_urdf) as system:
        for ctrl in (JSB, "right_pid"):
            _same(f"state_interfaces_read_by('{ctrl}') on two RRBots",
                  _sorted_list("state_interfaces_read_by", answers.state_interfaces_read_by(system, ctrl)),
                  true_state_interfaces(system, ctrl))


def _state_of(system: System, controller: str) -> str:
    return next(c.state for c in system.controller_manager.list_controllers() if c.name == controller)


@graded(points=2, hint="task 3.6: a chainable controller exports its reference interfaces at configure, named "
        "'<controller>/<joint>/<interface>' (list_controllers() shows them without the '<controller>/' prefix); "
        "sorted; [] for a controller that is not chainable.")
def test_reference_interfaces_of(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with chained_system() as system:
        for ctrl in (PID1, PID2, JTC, JSB):
            _same(f"reference_interfaces_of('{ctrl}') in the chain",
                  _sorted_list("reference_interfaces_of", answers.reference_interfaces_of(system, ctrl)),
                  true_references(system, ctrl))
    with two_rrbots_system(two_rrbots_urdf) as system:
        for ctrl in ("right_pid", "left_forward_controller"):
            _same(f"reference_interfaces_of('{ctrl}') on two RRBots (right_pid configured, inactive)",
                  _sorted_list("reference_interfaces_of", answers.reference_interfaces_of(system, ctrl)),
                  true_references(system, ctrl))


# --------------------------------------------------------------------------------------------- resource manager


@graded(points=2, hint="task 3.7: the hardware component whose <ros2_control> tag declares the interface "
        "(list_hardware_components() lists each component's interfaces); None for a controller's exported interface.")
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


@graded(points=2, hint="task 3.8: interfaces are available while their component is INACTIVE or ACTIVE (none "
        "while unconfigured), and a chainable controller's exports while it is active; is_available in "
        "list_hardware_interfaces(); both lists sorted.")
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


@graded(points=3, hint="task 3.9: claimable = available, not claimed, and (hardware interfaces) owned by an ACTIVE "
        "component: inactive hardware shows its interfaces but refuses to be commanded. Sorted.")
def test_claimable_command_interfaces(answers: ModuleType, two_rrbots_urdf: str) -> None:
    with forward_system() as system:
        _same("claimable_command_interfaces with the forward controller active",
              _sorted_list("claimable", answers.claimable_command_interfaces(system)), true_claimable(system))
    with hardware_state_system("inactive") as system:
        truth = true_claimable(system)
        assert truth == [], truth
        _same("claimable_command_interfaces with the RRBot hardware inactive",
              _sorted_list("claimable", answers.claimable_command_interfaces(system)), truth)
    with two_rrbots_system(two_rrbots_urdf, right="inactive") as system:
        _same("claimable_command_interfaces with left_rrbot active and right_rrbot inactive",
              _sorted_list("claimable", answers.claimable_command_interfaces(system)), true_claimable(system))
    with chained_system() as system:
        _same("claimable_command_interfaces in the chain",
              _sorted_list("claimable", answers.claimable_command_interfaces(system)), true_claimable(system))


# --------------------------------------------------------------------------------------------- hardware


def _hardware_states(answers: ModuleType, system: System) -> dict[str, str]:
    got = answers.hardware_states(system)
    assert isinstance(got, dict), f"hardware_states must return a dict, got {type(got).__name__} {got!r}"
    return {k: _label(v) for k, v in got.items()}


@graded(points=2, hint="task 3.10: {component name: state label} from list_hardware_components(); the state "
        "follows hardware_components_initial_state and set_hardware_component_state.")
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
