"""Grader of task 9: a controller chain on RRBot in MuJoCo, and PID gains tuned to a specification.

The specification (notebook 09, the exercise's TODOs and docstrings):

* ``rrbot_bringup/config/rrbot_chained_controllers.yaml`` declares ``joint_state_broadcaster``,
  ``pid_controller_joint1``/``pid_controller_joint2`` (``pid_controller/PidController``, one DOF each, commanding the
  joint's ``effort``, with references and states ``[position, velocity]``) and ``joint_trajectory_controller``
  (joints ``[joint1, joint2]``, commanding the PIDs' reference interfaces ``pid_controller_jointN/jointN`` with
  ``[position, velocity]``); every parameter is one that Jazzy's controllers declare;
* ``chain.py``: ``activate_chain(cm)`` loads and configures what is missing, then activates the whole chain with
  strict switches the controller manager accepts, from whatever state the chain is in (nothing loaded, some PIDs
  active, the head deactivated, ...); ``deactivate_chain(cm)`` deactivates the chain's active controllers with strict
  switches, head first, leaving every controller loaded and configured, from whatever state;
* running, the trajectory controller is updated before the PIDs (Jazzy's chain order), the PIDs are in chained
  mode, and a trajectory is tracked within :data:`TRACKING_TOLERANCE` and ends within :data:`GOAL_TOLERANCE`;
* the gains meet the step specification on joint1 (:data:`SPEC`), measured in simulation with the PID alone at
  100 Hz (the loop at 100 Hz, the PIDs not slower); each figure is its own check.

The system is the library's RRBot description with ``sim_mujoco:=true`` (MuJoCo, effort-controlled joints).
Generated scenarios try ``activate_chain`` and ``deactivate_chain`` from starting states of the chain within what the
docstrings allow; the expected end state is the docstrings' (every chain controller active, or the active ones
inactive and the others as they were).
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
from hypothesis import HealthCheck, Phase, example, given, settings
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop import tuning
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description.xacro import descriptions_root
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint, MultiDOFCommand
from rrbot_workshop.tools.lint import lint_controllers

TASK = 9
CONTROLLERS = "rrbot_bringup/config/rrbot_chained_controllers.yaml"
CHAIN_FILE = "chain.py"
JSB, JTC = "joint_state_broadcaster", "joint_trajectory_controller"
PIDS = ["pid_controller_joint1", "pid_controller_joint2"]
CHAIN = [JTC, *PIDS]
JOINTS = ["joint1", "joint2"]
TYPES = {
    JSB: "joint_state_broadcaster/JointStateBroadcaster",
    PIDS[0]: "pid_controller/PidController",
    PIDS[1]: "pid_controller/PidController",
    JTC: "joint_trajectory_controller/JointTrajectoryController",
}
#: The rate of the step specification [Hz].
RATE = 100
#: Step specification on joint1 (0 -> 0.5 rad at 100 Hz, PID alone): the learner tunes gains to meet it.
SPEC = {"step": 0.5, "overshoot": 5.0, "settling_time": 0.5, "steady_state_error": 0.005}  # [rad], [%], [s], [rad]
#: Largest allowed distance between the trajectory controller's reference and the joints during a trajectory [rad].
TRACKING_TOLERANCE = 0.03
#: Final position error allowed at the end of the trajectory [rad].
GOAL_TOLERANCE = 0.005
#: States a chain controller can start a scenario in.
STATES = ("unloaded", "unconfigured", "inactive", "active")
#: Hypothesis's phases without "explain" (it re-runs the learner's code many times only to annotate the failure).
NO_EXPLAIN = (Phase.explicit, Phase.generate, Phase.shrink)


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


@pytest.fixture(scope="module")
def controllers_yaml(controllers_file: Path) -> dict[str, Any]:
    try:
        data = yaml.safe_load(controllers_file.read_text())
    except yaml.YAMLError as exc:
        pytest.fail(f"your {controllers_file.name} is not valid YAML: {exc}", pytrace=False)
    if not isinstance(data, dict):
        pytest.fail(f"your {controllers_file.name} must be a mapping of node names to their parameters", pytrace=False)
    return data


@pytest.fixture(scope="module")
def chain(task_file: Callable[[int, str], Path]) -> ModuleType:
    task_file(TASK, CHAIN_FILE)
    module = rw.course.load_module(TASK, CHAIN_FILE, quiet=True)
    if module is None:
        pytest.fail("your chain.py does not import; run notebook 09's cell that loads it to see the error",
                    pytrace=False)
    return module


def _params(data: dict[str, Any], name: str) -> dict[str, Any]:
    params = (data.get(name) or {}).get("ros__parameters")
    if not isinstance(params, dict):
        pytest.fail(f"your controllers YAML has no '{name}: ros__parameters:' section", pytrace=False)
    return params


@contextmanager
def _system(controllers: Path | dict[str, Any], spawn: list[str], inactive: list[str] = ()) -> Iterator[System]:
    try:
        system = bringup(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", controllers,
                         xacro_args={"sim_mujoco": True}, spawn=spawn, inactive=list(inactive))
    except rw.RRBotWorkshopError as exc:
        pytest.fail(f"the system does not start with your rrbot_chained_controllers.yaml: {exc}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _function(chain: ModuleType, name: str) -> Callable[[Any], Any]:
    fn = getattr(chain, name, None)
    if not callable(fn):
        pytest.fail(f"your chain.py has no function {name}(cm)", pytrace=False)
    return fn


def _states(cm: Any) -> dict[str, str]:
    states = {c.name: c.state for c in cm.list_controllers()}
    return {name: states.get(name, "unloaded") for name in [JSB, *CHAIN]}


def _strict(strictness: Any) -> bool:
    return strictness == 2 or (isinstance(strictness, str) and strictness.strip().lower() == "strict")


class _SwitchSpy:
    """Records every switch_controllers call of the learner's function: (activate, deactivate, strictness)."""

    def __init__(self, cm: Any) -> None:
        self.cm = cm
        self.calls: list[tuple[list[str], list[str], Any]] = []

    def __enter__(self) -> _SwitchSpy:
        original = self.cm.switch_controllers

        def recording(activate: Any = (), deactivate: Any = (), strictness: Any = None, *args: Any, **kwargs: Any) -> Any:
            self.calls.append((list(activate or []), list(deactivate or []), strictness))
            return original(activate, deactivate, strictness, *args, **kwargs)

        self.cm.switch_controllers = recording
        return self

    def __exit__(self, *exc: Any) -> None:
        del self.cm.switch_controllers

    def not_strict(self) -> list[str]:
        return [f"switch_controllers(activate={a}, deactivate={d}, strictness={s!r})"
                for a, d, s in self.calls if not _strict(s)]


def _set_states(cm: Any, wanted: dict[str, str]) -> None:
    """Bring the chain's controllers to ``wanted`` with the controller manager's own calls."""
    now = _states(cm)
    if now[JTC] == "active":
        cm.switch_controllers(deactivate=[JTC], strictness="strict")
    active_pids = [p for p in PIDS if now[p] == "active"]
    if active_pids:
        cm.switch_controllers(deactivate=active_pids, strictness="strict")
    for name in CHAIN:
        state, target = _states(cm)[name], wanted[name]
        if target == "unloaded":
            if state != "unloaded":
                cm.unload_controller(name)
            continue
        if state == "unloaded":
            cm.load_controller(name)
            state = "unconfigured"
        if target == "unconfigured" and state == "inactive":
            cm.cleanup_controller(name)
        elif target in ("inactive", "active") and state == "unconfigured":
            cm.configure_controller(name)
    pids = [p for p in PIDS if wanted[p] == "active"]
    if pids:
        cm.switch_controllers(activate=pids, strictness="strict")
    if wanted[JTC] == "active":
        cm.switch_controllers(activate=[JTC], strictness="strict")


def _starting_states() -> st.SearchStrategy[dict[str, str]]:
    """States of the chain a learner's function may meet: the head is only active with both PIDs active."""
    state = st.sampled_from(STATES)
    return st.fixed_dictionaries({JTC: state, PIDS[0]: state, PIDS[1]: state}).filter(
        lambda s: s[JTC] != "active" or all(s[p] == "active" for p in PIDS))


def _described(states: dict[str, str]) -> str:
    return ", ".join(f"{name} {states[name]}" for name in CHAIN)


def _connected(cm: Any) -> list[str]:
    """What is wrong with the chain as it runs, or nothing."""
    entries = {c.name: c for c in cm.list_controllers()}
    problems = [f"{name} is {entries[name].state if name in entries else 'not loaded'}"
                for name in CHAIN if name not in entries or entries[name].state != "active"]
    if problems:
        return problems
    problems += [f"{p} is not in chained mode" for p in PIDS if not entries[p].is_chained]
    expected = sorted(f"{p}/{j}/{i}" for p, j in zip(PIDS, JOINTS, strict=True) for i in ("position", "velocity"))
    if sorted(entries[JTC].claimed_interfaces) != expected:
        problems.append(f"{JTC} claims {sorted(entries[JTC].claimed_interfaces)}, expected {expected}")
    if entries.get(JSB) is None or entries[JSB].state != "active":
        problems.append(f"{JSB} is no longer active")
    return problems


# --------------------------------------------------------------------------------------------- 9.1 the YAML


@graded(points=1, hint=(
    "Task 9.1: the controller manager declares the four controllers with the Jazzy type names, and every "
    "parameter is one that controller declares (a misspelt one is silently ignored on a real robot).",
    "Run `rrbot-workshop lint` on your YAML (or notebook 09's lint cell): it names each parameter Jazzy would not "
    "accept and each type that does not exist.",
    "controller_manager:\n  ros__parameters:\n    pid_controller_joint1:\n      type: pid_controller/PidController"))
def test_yaml_is_valid_for_jazzy(controllers_file: Path, controllers_yaml: dict[str, Any]) -> None:
    manager = _params(controllers_yaml, "controller_manager")
    types = {name: (manager.get(name) or {}).get("type") for name in TYPES}
    wrong = {n: t for n, t in types.items() if t != TYPES[n]}
    assert not wrong, (
        "your rrbot_chained_controllers.yaml declares " + "; ".join(f"'{n}' with the type {t!r}, expected "
                                                                    f"'{TYPES[n]}'" for n, t in wrong.items()) + ".")
    errors = [f for f in lint_controllers(controllers_file) if f.level == "error"]
    assert not errors, ("your rrbot_chained_controllers.yaml would not load on a Jazzy robot: "
                        + "; ".join(f.message for f in errors))


@graded(points=2, hint=(
    "Task 9.1: a PID that drives a joint's effort and is fed by a trajectory controller needs a reference for "
    "position AND velocity; each PidController has one DOF, its joint.",
    "pid_controller's parameters: dof_names, command_interface (the joint interface it writes) and "
    "reference_and_state_interfaces (the second is the derivative of the first).",
    "pid_controller_joint1:\n  ros__parameters:\n    dof_names: [joint1]\n    command_interface: effort\n"
    "    reference_and_state_interfaces: [position, velocity]"))
def test_pids_command_effort_with_position_and_velocity_references(controllers_yaml: dict[str, Any]) -> None:
    for pid, joint in zip(PIDS, JOINTS, strict=True):
        params = _params(controllers_yaml, pid)
        assert params.get("dof_names") == [joint], (
            f"your YAML gives {pid} the dof_names {params.get('dof_names')}, expected [{joint}].")
        assert params.get("command_interface") == "effort", (
            f"your YAML gives {pid} the command_interface {params.get('command_interface')!r}, expected 'effort' "
            "(the simulated joints are effort-controlled).")
        refs = params.get("reference_and_state_interfaces")
        assert refs == ["position", "velocity"], (
            f"your YAML gives {pid} the reference_and_state_interfaces {refs}, expected [position, velocity] "
            "(the trajectory controller sends both; the second must be the derivative of the first).")


@graded(points=2, hint=(
    "Task 9.1: the trajectory controller reads the joints' states, but its commands go to the interfaces the PIDs "
    "export, named <controller>/<dof>/<interface>.",
    "joint_trajectory_controller's command_joints names where its commands go (its joints stay the robot's); "
    "command_interfaces must match what the PIDs take.",
    "    joints: [joint1, joint2]\n    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n"
    "    command_interfaces: [position, velocity]\n    state_interfaces: [position, velocity]"))
def test_trajectory_controller_commands_the_pids(controllers_yaml: dict[str, Any]) -> None:
    params = _params(controllers_yaml, JTC)
    assert params.get("joints") == JOINTS, f"your YAML gives {JTC} the joints {params.get('joints')}, expected {JOINTS}."
    expected = [f"{pid}/{joint}" for pid, joint in zip(PIDS, JOINTS, strict=True)]
    assert params.get("command_joints") == expected, (
        f"your YAML gives {JTC} the command_joints {params.get('command_joints')}, expected {expected}.")
    assert params.get("command_interfaces") == ["position", "velocity"], (
        f"your YAML gives {JTC} the command_interfaces {params.get('command_interfaces')}, expected [position, "
        "velocity]: the PIDs take position and velocity references.")
    assert params.get("state_interfaces") == ["position", "velocity"], (
        f"your YAML gives {JTC} the state_interfaces {params.get('state_interfaces')}, expected [position, velocity].")


# --------------------------------------------------------------------------------------------- 9.2 the order


@graded(points=3, hint=(
    "Task 9.2: a controller can only claim reference interfaces that an ACTIVE controller exports, and the task "
    "asks for strict switches.",
    "cm.switch_controllers(activate=[...], strictness='strict'): activate the PIDs first, or in the same switch as "
    "the trajectory controller. (Without strictness Jazzy takes best_effort, which drops what it cannot do.)",
    "cm.switch_controllers(activate=['pid_controller_joint1', 'pid_controller_joint2'], strictness='strict')\n"
    "cm.switch_controllers(activate=['joint_trajectory_controller'], strictness='strict')"))
def test_activate_chain_connects(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    with _system(controllers_file, [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager
        with _SwitchSpy(cm) as spy:
            activate(cm)
        assert spy.calls, "activate_chain() made no switch: the chain's controllers were loaded and configured, not active."
        problems = _connected(cm)
        assert not problems, "after activate_chain(), the chain is not connected: " + "; ".join(problems) + "."
        loose = spy.not_strict()
        assert not loose, ("activate_chain() connected the chain, but with switches that are not strict: "
                           + "; ".join(loose) + ". The task asks for strict switches.")


@graded(points=2, hint=(
    "Task 9.2: activate_chain() must work from whatever state the chain is in: nothing loaded, some controllers "
    "only loaded, a PID already active, the head deactivated while the PIDs run.",
    "Read each controller's state with cm.list_controllers(); load_controller() what is missing, "
    "configure_controller() what is unconfigured, and activate (strictly) only what is not active yet.",
    "states = {c.name: c.state for c in cm.list_controllers()}\nfor name in CHAIN:\n    if name not in states: "
    "cm.load_controller(name); states[name] = 'unconfigured'\n    if states[name] == 'unconfigured': "
    "cm.configure_controller(name)"))
def test_activate_chain_from_any_state(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    with _system(controllers_file, [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager

        @settings(derandomize=True, database=None, deadline=None, max_examples=8,
                  suppress_health_check=list(HealthCheck), phases=NO_EXPLAIN, report_multiple_bugs=False)
        @given(_starting_states())
        @example(dict.fromkeys(CHAIN, "active"))
        @example({JTC: "inactive", PIDS[0]: "active", PIDS[1]: "active"})
        @example(dict.fromkeys(CHAIN, "unloaded"))
        def scenario(start: dict[str, str]) -> None:
            _set_states(cm, start)
            with _SwitchSpy(cm) as spy:
                activate(cm)
            problems = _connected(cm)
            assert not problems, (
                f"starting from {_described(start)}, activate_chain() leaves the chain not connected: "
                + "; ".join(problems) + ".")
            loose = spy.not_strict()
            assert not loose, (f"starting from {_described(start)}, activate_chain() switched without strictness "
                               "'strict': " + "; ".join(loose) + ".")

        scenario()


@graded(points=2, hint=(
    "Task 9.2: Jazzy updates a preceding controller before its followers, whatever the load order: the trajectory "
    "controller first, then the PIDs. That order comes from the chain your YAML wires.",
    "cm.list_controllers() lists the controllers in update order; the order is worked out when a controller is "
    "configured, from which controller claims which reference interfaces.",
    "Point the trajectory controller at the PIDs' references (command_joints: [pid_controller_joint1/joint1, "
    "pid_controller_joint2/joint2]) and activate the chain with activate_chain()."))
def test_update_order_is_jazzy(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    # the PIDs loaded first, so the order cannot come from the load order
    with _system(controllers_file, [JSB], inactive=[*PIDS, JTC]) as system:
        activate(system.controller_manager)
        order = [c.name for c in system.controller_manager.list_controllers() if c.name in CHAIN]
        assert len(order) == 3 and order.index(JTC) < order.index(PIDS[0]) and order.index(JTC) < order.index(PIDS[1]), (
            f"with your files the controllers update in the order {order}; the trajectory controller must come "
            "before the PIDs it feeds.")


@graded(points=2, hint=(
    "Task 9.2: the PIDs cannot stop while the trajectory controller still claims their references: deactivate the "
    "head of the chain first, with strict switches. Everything stays loaded and configured (inactive).",
    "cm.switch_controllers(deactivate=[...], strictness='strict'), the head in a switch before (or with) the PIDs; "
    "no unload_controller() or cleanup_controller().",
    "cm.switch_controllers(deactivate=['joint_trajectory_controller'], strictness='strict')\n"
    "cm.switch_controllers(deactivate=['pid_controller_joint1', 'pid_controller_joint2'], strictness='strict')"))
def test_deactivate_chain(controllers_file: Path, chain: ModuleType) -> None:
    activate, deactivate = _function(chain, "activate_chain"), _function(chain, "deactivate_chain")
    with _system(controllers_file, [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager
        _set_states(cm, dict.fromkeys(CHAIN, "active"))
        with _SwitchSpy(cm) as spy:
            deactivate(cm)
        states = _states(cm)
        wrong = {n: s for n, s in states.items() if s != ("active" if n == JSB else "inactive")}
        assert not wrong, (f"after deactivate_chain() of the running chain the states are {states}; every chain "
                           f"controller must be inactive (loaded and configured) and {JSB} still active.")
        loose = spy.not_strict()
        assert not loose, "deactivate_chain() switched without strictness 'strict': " + "; ".join(loose) + "."
        activate(cm)
        problems = _connected(cm)
        assert not problems, ("after deactivate_chain(), activate_chain() does not bring the chain back: "
                              + "; ".join(problems) + ".")


@graded(points=1, hint=(
    "Task 9.2: deactivate_chain() must work from whatever state the chain is in: only the active controllers "
    "stop, the others stay as they are (unloaded, unconfigured or inactive).",
    "Read the states with cm.list_controllers() and deactivate (strictly) only what is active: a strict switch "
    "that names a controller which is not active is rejected.",
    "active = {c.name for c in cm.list_controllers() if c.state == 'active'}\nif CHAIN[0] in active: "
    "cm.switch_controllers(deactivate=[CHAIN[0]], strictness='strict')\n"
    "followers = [n for n in CHAIN[1:] if n in active]"))
def test_deactivate_chain_from_any_state(controllers_file: Path, chain: ModuleType) -> None:
    deactivate = _function(chain, "deactivate_chain")
    with _system(controllers_file, [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager

        @settings(derandomize=True, database=None, deadline=None, max_examples=8,
                  suppress_health_check=list(HealthCheck), phases=NO_EXPLAIN, report_multiple_bugs=False)
        @given(_starting_states())
        @example(dict.fromkeys(CHAIN, "active"))
        @example({JTC: "inactive", PIDS[0]: "active", PIDS[1]: "active"})
        @example(dict.fromkeys(CHAIN, "unloaded"))
        def scenario(start: dict[str, str]) -> None:
            _set_states(cm, start)
            with _SwitchSpy(cm) as spy:
                deactivate(cm)
            expected = {n: ("inactive" if s == "active" else s) for n, s in start.items()}
            got = {n: s for n, s in _states(cm).items() if n in CHAIN}
            assert got == expected, (
                f"starting from {_described(start)}, deactivate_chain() leaves {_described(got)}; expected "
                f"{_described(expected)} (the active ones inactive, the others as they were).")
            assert _states(cm)[JSB] == "active", f"deactivate_chain() stopped {JSB}; it must leave it running."
            loose = spy.not_strict()
            assert not loose, (f"starting from {_described(start)}, deactivate_chain() switched without strictness "
                               "'strict': " + "; ".join(loose) + ".")

        scenario()


# --------------------------------------------------------------------------------------------- running the chain


def _trajectory() -> JointTrajectory:
    points = [([0.6, -0.4], 1.5), ([0.0, 0.5], 3.0), ([-0.3, 0.0], 4.5)]
    return JointTrajectory(
        joint_names=list(JOINTS),
        points=[JointTrajectoryPoint(positions=list(p), velocities=[0.0, 0.0], time_from_start=t) for p, t in points],
    )


@graded(points=3, hint=(
    f"Task 9: with the chain connected, the joints follow the trajectory controller's reference within "
    f"{TRACKING_TOLERANCE} rad and end within {GOAL_TOLERANCE} rad of the goal.",
    "Large errors during the motion come from soft gains (p too small, d too small for the velocity reference); "
    "an error left at the end comes from too little i against joint2's weight. rw.tuning.predict_step shows both.",
    "gains:\n  joint2: {p: 300.0, i: 300.0, d: 10.0, i_clamp_max: 20.0, i_clamp_min: -20.0}   "
    "(the same kind of gains for joint1)"))
def test_trajectory_is_tracked_through_the_chain(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    with _system(controllers_file, [JSB], inactive=CHAIN) as system:
        activate(system.controller_manager)
        system.spin(seconds=1.0)
        system.publish(f"/{JTC}/joint_trajectory", _trajectory())
        worst, when = 0.0, 0.0
        for k in range(600):
            system.spin(seconds=0.01)
            state = system.latest(f"/{JTC}/controller_state")
            if state is not None and state.error.positions:
                error = max(abs(e) for e in state.error.positions)
                if error > worst:
                    worst, when = error, (k + 1) * 0.01
        msg = system.latest("/joint_states")
        final = [msg.position[msg.name.index(j)] for j in JOINTS]
    assert worst <= TRACKING_TOLERANCE, (
        f"the largest tracking error is {worst:.3f} rad, {when:.2f} s after the trajectory started; the task allows "
        f"{TRACKING_TOLERANCE} rad.")
    assert all(math.isclose(a, b, abs_tol=GOAL_TOLERANCE) for a, b in zip(final, [-0.3, 0.0], strict=True)), (
        f"the joints end at [{final[0]:.4f}, {final[1]:.4f}] rad, the goal is [-0.3, 0.0] (within {GOAL_TOLERANCE} rad).")


# --------------------------------------------------------------------------------------------- 9.3 tuning


def _step_check_hint(figure: str) -> tuple[str, str, str]:
    return (
        f"Task 9.3: a 0.5 rad step of joint1 with the PID alone at 100 Hz: overshoot at most {SPEC['overshoot']:g} %, "
        f"within 2 % in at most {SPEC['settling_time']:g} s, error at most {SPEC['steady_state_error']:g} rad 3 s after "
        f"the step. This check is the {figure}.",
        "Predict with rw.tuning.predict_step(plant, rw.tuning.PidGains(p, i, d), period=0.01, step=0.5) before you "
        "simulate: more p is stiffer and faster, d damps, i removes the last error (too much overshoots).",
        "joint1: {p: 300.0, i: 100.0, d: 10.0, i_clamp_max: 20.0, i_clamp_min: -20.0, u_clamp_max: 1000.0, "
        "u_clamp_min: -1000.0}",
    )


@pytest.fixture(scope="module")
def step_response(controllers_file: Path, controllers_yaml: dict[str, Any]) -> tuning.StepResponse:
    # the specification is at 100 Hz: the loop at 100 Hz, and no PID slower than the loop
    manager = _params(controllers_yaml, "controller_manager")
    rate = manager.get("update_rate", RATE)
    if rate != RATE:
        pytest.fail(f"your YAML runs the loop at {rate} Hz; the step specification is measured at {RATE} Hz "
                    "(controller_manager's update_rate).", pytrace=False)
    for pid in PIDS:
        own = (manager.get(pid) or {}).get("update_rate")
        if own is not None and own < RATE:
            pytest.fail(f"your YAML runs {pid} at {own} Hz, slower than the {RATE} Hz of the step specification.",
                        pytrace=False)
    with _system(controllers_file, [JSB, *PIDS]) as system:
        for pid, joint in zip(PIDS, JOINTS, strict=True):
            system.publish(f"/{pid}/reference", MultiDOFCommand(dof_names=[joint], values=[0.0], values_dot=[0.0]))
        system.spin(seconds=2.0)
        return tuning.measure_step(system, PIDS[0], SPEC["step"])


@graded(points=2, hint=_step_check_hint("overshoot"))
def test_step_overshoot(step_response: tuning.StepResponse) -> None:
    assert step_response.overshoot <= SPEC["overshoot"], (
        f"with your gains a 0.5 rad step of joint1 overshoots by {step_response.overshoot:.1f} %; the specification "
        f"allows {SPEC['overshoot']:g} %.")


@graded(points=1, hint=_step_check_hint("settling time"))
def test_step_settling_time(step_response: tuning.StepResponse) -> None:
    assert step_response.settling_time <= SPEC["settling_time"], (
        f"with your gains a 0.5 rad step of joint1 stays within 2 % only after {step_response.settling_time:.2f} s; "
        f"the specification allows {SPEC['settling_time']:g} s.")


@graded(points=1, hint=_step_check_hint("final error"))
def test_step_final_error(step_response: tuning.StepResponse) -> None:
    assert abs(step_response.steady_state_error) <= SPEC["steady_state_error"], (
        f"with your gains joint1 ends {step_response.steady_state_error:+.4f} rad from a 0.5 rad step; the "
        f"specification allows {SPEC['steady_state_error']:g} rad.")
