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
docstrings allow, among them controllers configured once and cleaned up (configure again); the expected end state is
the docstrings' (every chain controller active, or the active ones inactive and the others as they were). The
trajectory lists joint2 first; the trajectory controller's ``joints`` may be listed in any order, each with its PID's
reference in ``command_joints``.

One slip, one rule: a part of the YAML that breaks a rule is replaced by the task's chain (:data:`REFERENCE_PIDS`,
:data:`REFERENCE_JTC`, 100 Hz) so the chain.py checks judge chain.py alone; the gains (tracking and step figures) are
judged on the learner's PIDs once they are wired as asked, with the rest of the chain standing in where it is not
(``graded(after=...)`` names what each check builds on). The library's ``rrbot_chained_controllers.yaml`` cannot stand
in: it is another chain (velocity-commanding PIDs with position references, for mock hardware). The rate rule (the
step is measured at 100 Hz) is part of the step measurement: a loop or PID at another rate fails the step figures,
with the cause at the overshoot.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
from controllers_layout import Declared, read_manager
from hypothesis import HealthCheck, Phase, example, given, settings
from hypothesis import strategies as st
from yaml_places import MANAGER_KEYS, at

import rrbot_workshop as rw
from rrbot_workshop import tuning
from rrbot_workshop.bringup import System, bringup
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.learner_errors import learner_location, learner_root
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
def controllers_yaml(controllers_file: Path) -> tuple[dict[str, Any], dict[str, Declared]]:
    """The manager's own parameters and the controllers, each type read under controller_manager or in the
    controller's own section (block or flow style), as ``rrbot-workshop lint`` reads them."""
    return _read(controllers_file)


def _read(controllers_file: Path) -> tuple[dict[str, Any], dict[str, Declared]]:
    """:func:`read_manager`, plus the chain's controllers that have a section of their own but no type anywhere (the
    type check names that slip; the others still read the section's parameters)."""
    read = read_manager(controllers_file)
    if isinstance(read, str):
        pytest.fail(read, pytrace=False)
    manager, declared = read
    raw = yaml.safe_load(controllers_file.read_text())
    for name in TYPES:
        if name not in declared:
            section = next((raw[k] for k in _section_keys(name) if isinstance(raw.get(k), dict)), {})
            params = section.get("ros__parameters")
            if isinstance(params, dict):
                declared = {**declared, name: Declared(None, {k: v for k, v in params.items() if k != "type"})}
    return manager, declared


def _section_keys(name: str) -> tuple[str, ...]:
    return (name, f"/{name}", f"/**/{name}")


def _where(path: Path, name: str, *keys: str) -> str:
    """``"rrbot_chained_controllers.yaml, line N"``: where the learner wrote ``name``'s parameter ``keys``."""
    return at(path, _section_keys(name), *keys)


@pytest.fixture(scope="module")
def chain(task_file: Callable[[int, str], Path]) -> ModuleType:
    task_file(TASK, CHAIN_FILE)
    module = rw.course.load_module(TASK, CHAIN_FILE, quiet=True)
    if module is None:
        pytest.fail("your chain.py does not import; run notebook 09's cell that loads it to see the error",
                    pytrace=False)
    return module


def _params(data: tuple[dict[str, Any], dict[str, Declared]], name: str) -> dict[str, Any]:
    declared = data[1].get(name)
    if declared is None:
        pytest.fail(f"your {Path(CONTROLLERS).name} has no '{name}': neither a type under controller_manager nor a "
                    f"'{name}: ros__parameters:' section of its own", pytrace=False)
    return dict(declared.params)


#: The chain as the task asks for it: what stands in for a part of the learner's YAML that breaks a rule, so the
#: other checks judge the learner's other parts on their own (the gains stay the learner's where they can be read).
REFERENCE_PIDS = {pid: {"dof_names": [joint], "command_interface": "effort",
                        "reference_and_state_interfaces": ["position", "velocity"]}
                  for pid, joint in zip(PIDS, JOINTS, strict=True)}
REFERENCE_GAINS = {"joint1": {"p": 300.0, "i": 100.0, "d": 10.0, "i_clamp_max": 20.0, "i_clamp_min": -20.0},
                   "joint2": {"p": 300.0, "i": 300.0, "d": 10.0, "i_clamp_max": 20.0, "i_clamp_min": -20.0}}
REFERENCE_JTC = {"joints": list(JOINTS), "command_joints": [f"{p}/{j}" for p, j in zip(PIDS, JOINTS, strict=True)],
                 "command_interfaces": ["position", "velocity"], "state_interfaces": ["position", "velocity"],
                 "allow_partial_joints_goal": False,
                 "constraints": {"stopped_velocity_tolerance": 0.01, "goal_time": 0.0}}

#: The checks of the YAML's rules, each with what judges it: while one fails, the others run on the reference's part.
YAML_RULES = ("test_yaml_is_valid_for_jazzy", "test_pids_command_effort_with_position_and_velocity_references",
              "test_trajectory_controller_commands_the_pids")
#: The check of the PIDs' wiring: the gains are judged on the learner's PIDs once they are wired as asked.
PID_RULE = YAML_RULES[1]


@functools.cache
def _broken(controllers_file: Path) -> frozenset[str]:
    """The YAML rules (:data:`YAML_RULES`) the learner's file breaks; every one when it cannot be read."""
    try:
        data = _read(controllers_file)
    except pytest.fail.Exception:
        return set(YAML_RULES)
    broken = set()
    for rule, check in zip(YAML_RULES, (lambda: _check_types_and_lint(controllers_file, data),
                                        lambda: _check_pids(controllers_file, data),
                                        lambda: _check_trajectory_controller(controllers_file, data)), strict=True):
        try:
            check()
        except (AssertionError, pytest.fail.Exception):
            broken.add(rule)
    return frozenset(broken)


def _learner_gains(data: tuple[dict[str, Any], dict[str, Declared]] | None, pid: str, joint: str) -> dict[str, Any]:
    entry = None if data is None else data[1].get(pid)
    gains = None if entry is None else entry.params.get("gains")
    mine = gains.get(joint) if isinstance(gains, Mapping) else None
    return {joint: dict(mine)} if isinstance(mine, Mapping) else {joint: dict(REFERENCE_GAINS[joint])}


def _stand_in(controllers_file: Path, keep_pids: bool) -> dict[str, Any]:
    """The reference chain at 100 Hz, with the learner's PIDs (``keep_pids``, their wiring is right) or the reference's
    wiring around the learner's gains."""
    try:
        data: tuple[dict[str, Any], dict[str, Declared]] | None = _read(controllers_file)
    except pytest.fail.Exception:
        data = None
    config: dict[str, Any] = {"controller_manager": {"ros__parameters": {
        "update_rate": RATE, **{name: {"type": kind} for name, kind in TYPES.items()}}}}
    for pid, joint in zip(PIDS, JOINTS, strict=True):
        if keep_pids and data is not None:
            params = {k: v for k, v in data[1][pid].params.items() if k != "update_rate"}
        else:
            params = {**REFERENCE_PIDS[pid], "gains": _learner_gains(data, pid, joint)}
        config[pid] = {"ros__parameters": params}
    config[JTC] = {"ros__parameters": dict(REFERENCE_JTC)}
    return config


def _chain_config(controllers_file: Path) -> Path | dict[str, Any]:
    """What the chain.py checks run on: the learner's YAML when it keeps every YAML rule, else the reference chain
    (a slip in the YAML costs the YAML's checks only)."""
    broken = _broken(controllers_file)
    return controllers_file if not broken else _stand_in(controllers_file, keep_pids=PID_RULE not in broken)


def _gains_config(controllers_file: Path) -> Path | dict[str, Any]:
    """What the gains are judged on: the learner's YAML when it keeps every YAML rule, else the learner's PIDs in the
    reference chain; the PIDs must be wired as asked (the gains are theirs), or the check fails after that rule."""
    broken = _broken(controllers_file)
    if PID_RULE in broken:
        pytest.fail(f"the gains are measured on your PIDs once they are wired as task 9.1 asks; this fails because "
                    f"{PID_RULE.removeprefix('test_')} fails.", pytrace=False)
    return controllers_file if not broken else _stand_in(controllers_file, keep_pids=True)


@contextmanager
def _system(controllers: Path | dict[str, Any], spawn: list[str], inactive: list[str] = ()) -> Iterator[System]:
    try:
        system = bringup(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", controllers,
                         xacro_args={"sim_mujoco": True}, spawn=spawn, inactive=list(inactive))
    except rw.RRBotWorkshopError as exc:
        what = (f"your {controllers.name}" if isinstance(controllers, Path)
                else "your PIDs' parameters in the task's chain")
        pytest.fail(f"the system does not start with {what}: {exc}", pytrace=False)
    try:
        yield system
    finally:
        system.shutdown()


def _function(chain: ModuleType, name: str) -> Callable[[Any], Any]:
    fn = getattr(chain, name, None)
    if not callable(fn):
        pytest.fail(f"your chain.py has no function {name}(cm)", pytrace=False)
    return fn


def _run(fn: Callable[[Any], Any], cm: Any, start: dict[str, str]) -> None:
    """Call the learner's function; if it raises, fail with where it raised and the state it started from."""
    try:
        fn(cm)
    except Exception as exc:  # noqa: BLE001 - the learner's code: whatever it raises is the reason
        failure = (f"{learner_location(exc, learner_root()) or f'{_yours(fn)} raised {type(exc).__name__}: {exc}'}"
                   f" (starting from {_described(start)}{_history(start)})")
    else:
        return
    pytest.fail(failure, pytrace=False)  # outside the except block: the learner's error is given once


def _yours(fn: Callable[[Any], Any]) -> str:
    """``"your chain.py, line N, activate_chain()"``: where the learner's function starts."""
    code = getattr(fn, "__code__", None)
    line = f", line {code.co_firstlineno}" if code is not None else ""
    return f"your {CHAIN_FILE}{line}, {getattr(fn, '__name__', 'function')}()"


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

    def described(self) -> str:
        return "; ".join(f"switch_controllers(activate={a}, deactivate={d}, strictness={s!r})"
                         for a, d, s in self.calls) or "none"

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


def _shown(value: Any) -> str:
    """A parameter's value as the learner wrote it in YAML: ``[position, velocity]``, ``effort``, or "not given"."""
    if value is None:
        return "not given"
    if isinstance(value, list):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return str(value)


def _history(start: dict[str, str]) -> str:
    unconfigured = [n for n in CHAIN if start[n] == "unconfigured"]
    return (f" ({', '.join(unconfigured)} configured before, then cleaned up: the manager's cleanup_controller "
            "leaves a controller unconfigured)") if unconfigured else ""


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


# a parameter the PID or trajectory controller check judges, left empty, is also one Jazzy refuses: that check's cause
@graded(points=1, after=("test_pids_command_effort_with_position_and_velocity_references",
                         "test_trajectory_controller_commands_the_pids"), hint=(
    "Task 9.1: the controller manager declares the four controllers with the Jazzy type names, and every "
    "parameter is one that controller declares (a misspelt one is silently ignored on a real robot).",
    "Run `rrbot-workshop lint` on your YAML (or notebook 09's lint cell): it names each parameter Jazzy would not "
    "accept and each type that does not exist.",
    "controller_manager:\n  ros__parameters:\n    pid_controller_joint1:\n      type: pid_controller/PidController"))
def test_yaml_is_valid_for_jazzy(controllers_file: Path,
                                 controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    _check_types_and_lint(controllers_file, controllers_yaml)


def _type_problem(path: Path, declared: Mapping[str, Declared], name: str) -> str:
    if name not in declared or declared[name].type is None:
        return (f"{_where(path, name)}: '{name}' has no type, neither under controller_manager nor in its own "
                f"section (expected '{TYPES[name]}')")
    entry = declared[name]
    where = (at(path, MANAGER_KEYS, name, "type") if "type" in entry.manager_entry
             else _where(path, name, "type"))
    return f"{where}: '{name}' has the type {entry.type!r}, expected '{TYPES[name]}'"


@functools.cache
def _lint_errors(controllers_file: Path) -> list[Any]:
    """What ``rrbot-workshop lint`` finds Jazzy would refuse (once per grading: the file does not change meanwhile)."""
    return [f for f in lint_controllers(controllers_file) if f.level == "error"]


def _check_types_and_lint(controllers_file: Path, controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    declared = controllers_yaml[1]
    wrong = [_type_problem(controllers_file, declared, n) for n in TYPES
             if n not in declared or declared[n].type != TYPES[n]]
    assert not wrong, "your " + "; ".join(wrong) + "."
    errors = _lint_errors(controllers_file)
    assert not errors, "; ".join(
        f"your {controllers_file.name}{f', line {f.line}' if f.line else ''}: {f.message}" for f in errors
    ) + " (Jazzy would not load it)."


@graded(points=2, hint=(
    "Task 9.1: a PID that drives a joint's effort and is fed by a trajectory controller needs a reference for "
    "position AND velocity; each PidController has one DOF, its joint.",
    "pid_controller's parameters: dof_names, command_interface (the joint interface it writes) and "
    "reference_and_state_interfaces (the second is the derivative of the first).",
    "pid_controller_joint1:\n  ros__parameters:\n    dof_names: [joint1]\n    command_interface: effort\n"
    "    reference_and_state_interfaces: [position, velocity]"))
def test_pids_command_effort_with_position_and_velocity_references(
        controllers_file: Path, controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    _check_pids(controllers_file, controllers_yaml)


def _check_pids(path: Path, controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    for pid, joint in zip(PIDS, JOINTS, strict=True):
        params = _params(controllers_yaml, pid)
        assert params.get("dof_names") == [joint], (
            f"your {_where(path, pid, 'dof_names')}: {pid} has the dof_names {_shown(params.get('dof_names'))}, "
            f"expected [{joint}].")
        assert params.get("command_interface") == "effort", (
            f"your {_where(path, pid, 'command_interface')}: {pid} has the command_interface "
            f"{_shown(params.get('command_interface'))}, expected effort (the simulated joints are effort-controlled).")
        refs = params.get("reference_and_state_interfaces")
        assert refs == ["position", "velocity"], (
            f"your {_where(path, pid, 'reference_and_state_interfaces')}: {pid} has the "
            f"reference_and_state_interfaces {_shown(refs)}, expected [position, velocity] (the trajectory controller "
            "sends both; the second must be the derivative of the first).")


@graded(points=2, hint=(
    "Task 9.1: the trajectory controller reads the joints' states, but its commands go to the interfaces the PIDs "
    "export, named <controller>/<dof>/<interface>.",
    "joint_trajectory_controller's command_joints names where its commands go (its joints stay the robot's); "
    "command_interfaces must match what the PIDs take.",
    "    joints: [joint1, joint2]\n    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n"
    "    command_interfaces: [position, velocity]\n    state_interfaces: [position, velocity]"))
def test_trajectory_controller_commands_the_pids(
        controllers_file: Path, controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    _check_trajectory_controller(controllers_file, controllers_yaml)


def _check_trajectory_controller(path: Path, controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> None:
    params = _params(controllers_yaml, JTC)
    joints = params.get("joints")
    assert isinstance(joints, list) and sorted(map(str, joints)) == JOINTS, (
        f"your {_where(path, JTC, 'joints')}: {JTC} has the joints {_shown(joints)}, expected the RRBot's "
        f"{_shown(JOINTS)} (in any order).")
    expected = [f"{PIDS[JOINTS.index(j)]}/{j}" for j in joints]  # the PID of each joint, in the order of joints
    assert params.get("command_joints") == expected, (
        f"your {_where(path, JTC, 'command_joints')}: {JTC} has the command_joints "
        f"{_shown(params.get('command_joints'))}, expected {_shown(expected)} (each joint's PID reference, <controller>/<dof>, in the order of joints).")
    assert params.get("command_interfaces") == ["position", "velocity"], (
        f"your {_where(path, JTC, 'command_interfaces')}: {JTC} has the command_interfaces "
        f"{_shown(params.get('command_interfaces'))}, expected [position, velocity]: the PIDs take position and "
        "velocity references.")
    assert params.get("state_interfaces") == ["position", "velocity"], (
        f"your {_where(path, JTC, 'state_interfaces')}: {JTC} has the state_interfaces "
        f"{_shown(params.get('state_interfaces'))}, expected [position, velocity].")


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
    with _system(_chain_config(controllers_file), [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager
        with _SwitchSpy(cm) as spy:
            activate(cm)
        assert spy.calls, (f"{_yours(activate)} made no switch: the chain's controllers were loaded and configured "
                           "(inactive), and they are still not active.")
        problems = _connected(cm)
        assert not problems, (f"{_yours(activate)} leaves the chain not connected: " + "; ".join(problems)
                              + f" (its switches: {spy.described()}).")
        loose = spy.not_strict()
        assert not loose, (f"{_yours(activate)} connected the chain, but with switches that are not strict: "
                           + "; ".join(loose) + ". The task asks for strict switches.")


@graded(points=2, after=("test_activate_chain_connects",), hint=(
    "Task 9.2: activate_chain() must work from whatever state the chain is in: nothing loaded, some controllers "
    "only loaded, a PID already active, the head deactivated while the PIDs run.",
    "Read each controller's state with cm.list_controllers(); load_controller() what is missing, "
    "configure_controller() what is unconfigured, and activate (strictly) only what is not active yet.",
    "states = {c.name: c.state for c in cm.list_controllers()}\nfor name in CHAIN:\n    if name not in states: "
    "cm.load_controller(name); states[name] = 'unconfigured'\n    if states[name] == 'unconfigured': "
    "cm.configure_controller(name)"))
def test_activate_chain_from_any_state(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    with _system(_chain_config(controllers_file), [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager

        @settings(derandomize=True, database=None, deadline=None, max_examples=8,
                  suppress_health_check=list(HealthCheck), phases=NO_EXPLAIN, report_multiple_bugs=False)
        @given(_starting_states())
        @example(dict.fromkeys(CHAIN, "active"))
        @example({JTC: "inactive", PIDS[0]: "active", PIDS[1]: "active"})
        @example(dict.fromkeys(CHAIN, "unloaded"))
        @example(dict.fromkeys(CHAIN, "unconfigured"))  # configured once, then cleaned up: configure again
        @example({JTC: "unloaded", PIDS[0]: "inactive", PIDS[1]: "unconfigured"})
        def scenario(start: dict[str, str]) -> None:
            _set_states(cm, start)
            with _SwitchSpy(cm) as spy:
                _run(activate, cm, start)
            problems = _connected(cm)
            assert not problems, (
                f"{_yours(activate)}, starting from {_described(start)}{_history(start)}, leaves the chain not "
                "connected: " + "; ".join(problems) + ".")
            loose = spy.not_strict()
            assert not loose, (f"{_yours(activate)}, starting from {_described(start)}, switched without strictness "
                               "'strict': " + "; ".join(loose) + ".")

        scenario()


@graded(points=2, after=("test_activate_chain_connects",), hint=(
    "Task 9.2: Jazzy updates a preceding controller before its followers, whatever the load order: the trajectory "
    "controller first, then the PIDs. That order comes from the chain your YAML wires.",
    "cm.list_controllers() lists the controllers in update order; the order is worked out when a controller is "
    "configured, from which controller claims which reference interfaces.",
    "Point the trajectory controller at the PIDs' references (command_joints: [pid_controller_joint1/joint1, "
    "pid_controller_joint2/joint2]) and activate the chain with activate_chain()."))
def test_update_order_is_jazzy(controllers_file: Path, chain: ModuleType) -> None:
    activate = _function(chain, "activate_chain")
    # the PIDs loaded first, so the order cannot come from the load order
    with _system(_chain_config(controllers_file), [JSB], inactive=[*PIDS, JTC]) as system:
        activate(system.controller_manager)
        order = [c.name for c in system.controller_manager.list_controllers() if c.name in CHAIN]
        assert len(order) == 3 and order.index(JTC) < order.index(PIDS[0]) and order.index(JTC) < order.index(PIDS[1]), (
            f"after {_yours(activate)}, the controllers update in the order {order}; the trajectory controller must "
            "come before the PIDs it feeds (the manager orders them when the chain is wired as task 9.1 asks and "
            "the PIDs are active before the head).")


@graded(points=2, after=("test_activate_chain_connects",), hint=(
    "Task 9.2: the PIDs cannot stop while the trajectory controller still claims their references: deactivate the "
    "head of the chain first, with strict switches. Everything stays loaded and configured (inactive).",
    "cm.switch_controllers(deactivate=[...], strictness='strict'), the head in a switch before (or with) the PIDs; "
    "no unload_controller() or cleanup_controller().",
    "cm.switch_controllers(deactivate=['joint_trajectory_controller'], strictness='strict')\n"
    "cm.switch_controllers(deactivate=['pid_controller_joint1', 'pid_controller_joint2'], strictness='strict')"))
def test_deactivate_chain(controllers_file: Path, chain: ModuleType) -> None:
    activate, deactivate = _function(chain, "activate_chain"), _function(chain, "deactivate_chain")
    with _system(_chain_config(controllers_file), [JSB], inactive=CHAIN) as system:
        cm = system.controller_manager
        _set_states(cm, dict.fromkeys(CHAIN, "active"))
        with _SwitchSpy(cm) as spy:
            deactivate(cm)
        states = _states(cm)
        wrong = {n: s for n, s in states.items() if s != ("active" if n == JSB else "inactive")}
        shown = ", ".join(f"{n} {s}" for n, s in states.items())
        assert not wrong, (f"{_yours(deactivate)} of the running chain leaves {shown} (its switches: "
                           f"{spy.described()}); every chain controller must be inactive (loaded and configured) and "
                           f"{JSB} still active.")
        loose = spy.not_strict()
        assert not loose, f"{_yours(deactivate)} switched without strictness 'strict': " + "; ".join(loose) + "."
        activate(cm)
        problems = _connected(cm)
        assert not problems, (f"after {_yours(deactivate)}, activate_chain() does not bring the chain back: "
                              + "; ".join(problems) + ".")


@graded(points=1, after=("test_deactivate_chain",), hint=(
    "Task 9.2: deactivate_chain() must work from whatever state the chain is in: only the active controllers "
    "stop, the others stay as they are (unloaded, unconfigured or inactive).",
    "Read the states with cm.list_controllers() and deactivate (strictly) only what is active: a strict switch "
    "that names a controller which is not active is rejected.",
    "active = {c.name for c in cm.list_controllers() if c.state == 'active'}\nif CHAIN[0] in active: "
    "cm.switch_controllers(deactivate=[CHAIN[0]], strictness='strict')\n"
    "followers = [n for n in CHAIN[1:] if n in active]"))
def test_deactivate_chain_from_any_state(controllers_file: Path, chain: ModuleType) -> None:
    deactivate = _function(chain, "deactivate_chain")
    with _system(_chain_config(controllers_file), [JSB], inactive=CHAIN) as system:
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
                _run(deactivate, cm, start)
            expected = {n: ("inactive" if s == "active" else s) for n, s in start.items()}
            got = {n: s for n, s in _states(cm).items() if n in CHAIN}
            assert got == expected, (
                f"{_yours(deactivate)}, starting from {_described(start)}, leaves {_described(got)}; expected "
                f"{_described(expected)} (the active ones inactive, the others as they were).")
            assert _states(cm)[JSB] == "active", f"{_yours(deactivate)} stopped {JSB}; it must leave it running."
            loose = spy.not_strict()
            assert not loose, (f"{_yours(deactivate)}, starting from {_described(start)}, switched without "
                               "strictness 'strict': " + "; ".join(loose) + ".")

        scenario()


# --------------------------------------------------------------------------------------------- running the chain


def _trajectory() -> JointTrajectory:
    """Three points through both joints' ranges, joint2 listed first (the controller matches joints by name)."""
    points = [([-0.4, 0.6], 1.5), ([0.5, 0.0], 3.0), ([0.0, -0.3], 4.5)]
    return JointTrajectory(
        joint_names=list(reversed(JOINTS)),
        points=[JointTrajectoryPoint(positions=list(p), velocities=[0.0, 0.0], time_from_start=t) for p, t in points],
    )


#: Where the trajectory ends, per joint [rad].
GOAL = {"joint1": -0.3, "joint2": 0.0}


def _gains_at(controllers_file: Path, joint: str) -> str:
    """``"rrbot_chained_controllers.yaml, line N"``: where the learner wrote ``joint``'s gains."""
    return _where(controllers_file, PIDS[JOINTS.index(joint)], "gains", joint)


@graded(points=3, after=(PID_RULE,), hint=(
    f"Task 9: with the chain connected, the joints follow the trajectory controller's reference within "
    f"{TRACKING_TOLERANCE} rad and end within {GOAL_TOLERANCE} rad of the goal.",
    "Large errors during the motion come from soft gains (p too small, d too small for the velocity reference); "
    "an error left at the end comes from too little i against joint2's weight. rw.tuning.predict_step shows both.",
    "gains:\n  joint2: {p: 300.0, i: 300.0, d: 10.0, i_clamp_max: 20.0, i_clamp_min: -20.0}   "
    "(the same kind of gains for joint1)"))
def test_trajectory_is_tracked_through_the_chain(controllers_file: Path) -> None:
    # the grader connects the chain itself: activate_chain() has checks of its own, this one judges the gains
    with _system(_gains_config(controllers_file), [JSB], inactive=CHAIN) as system:
        _set_states(system.controller_manager, dict.fromkeys(CHAIN, "active"))
        system.spin(seconds=1.0)
        system.publish(f"/{JTC}/joint_trajectory", _trajectory())
        worst = dict.fromkeys(JOINTS, (0.0, 0.0))  # joint -> (largest error [rad], when [s])
        for k in range(600):
            system.spin(seconds=0.01)
            state = system.latest(f"/{JTC}/controller_state")
            if state is not None and state.error.positions:
                for joint, error in zip(state.joint_names, state.error.positions, strict=False):
                    if joint in worst and abs(error) > worst[joint][0]:
                        worst[joint] = (abs(error), (k + 1) * 0.01)
        msg = system.latest("/joint_states")
        final = {j: msg.position[msg.name.index(j)] for j in JOINTS}
    joint = max(JOINTS, key=lambda j: worst[j][0])
    error, when = worst[joint]
    assert error <= TRACKING_TOLERANCE, (
        f"your gains of {joint} ({_gains_at(controllers_file, joint)}) let it lag {error:.3f} rad behind the "
        f"trajectory controller's reference, {when:.2f} s after the trajectory started; the task allows "
        f"{TRACKING_TOLERANCE} rad.")
    off = [j for j in JOINTS if not math.isclose(final[j], GOAL[j], abs_tol=GOAL_TOLERANCE)]
    assert not off, (
        f"your gains of {off[0]} ({_gains_at(controllers_file, off[0])}) leave it at {final[off[0]]:.4f} rad at the "
        f"end of the trajectory; the goal is {GOAL[off[0]]} rad (within {GOAL_TOLERANCE} rad).")


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
def step_response(controllers_file: Path,
                  controllers_yaml: tuple[dict[str, Any], dict[str, Declared]]) -> tuning.StepResponse:
    config = _gains_config(controllers_file)
    # the specification is at 100 Hz: the loop at 100 Hz, and no PID slower than the loop
    manager, declared = controllers_yaml
    rate = manager.get("update_rate", RATE)
    if rate != RATE:
        pytest.fail(f"your {at(controllers_file, MANAGER_KEYS, 'update_rate')}: the loop runs at {rate} Hz; the "
                    f"step specification is measured at {RATE} Hz (controller_manager's update_rate).", pytrace=False)
    for pid in PIDS:
        entry = declared.get(pid)
        own = None if entry is None else entry.params.get("update_rate", entry.manager_entry.get("update_rate"))
        if isinstance(own, (int, float)) and own < RATE:
            where = (_where(controllers_file, pid, "update_rate") if "update_rate" in entry.params
                     else at(controllers_file, MANAGER_KEYS, pid, "update_rate"))
            pytest.fail(f"your {where}: {pid} runs at {own} Hz, slower than the {RATE} Hz of the step "
                        "specification (leave its update_rate out, or give it the loop's).", pytrace=False)
    with _system(config, [JSB, *PIDS]) as system:
        for pid, joint in zip(PIDS, JOINTS, strict=True):
            system.publish(f"/{pid}/reference", MultiDOFCommand(dof_names=[joint], values=[0.0], values_dot=[0.0]))
        system.spin(seconds=2.0)
        return tuning.measure_step(system, PIDS[0], SPEC["step"])


#: The step's figures, each a check: a slow response also ends far off, so each figure builds on the ones before it.
OVERSHOOT = "test_step_overshoot"
SETTLING = "test_step_settling_time"


@graded(points=2, after=(PID_RULE,), hint=_step_check_hint("overshoot"))
def test_step_overshoot(controllers_file: Path, step_response: tuning.StepResponse) -> None:
    assert step_response.overshoot <= SPEC["overshoot"], (
        f"your gains of joint1 ({_gains_at(controllers_file, 'joint1')}) overshoot a 0.5 rad step by "
        f"{step_response.overshoot:.1f} %; the specification allows {SPEC['overshoot']:g} %.")


@graded(points=1, after=(PID_RULE, OVERSHOOT), hint=_step_check_hint("settling time"))
def test_step_settling_time(controllers_file: Path, step_response: tuning.StepResponse) -> None:
    assert step_response.settling_time <= SPEC["settling_time"], (
        f"your gains of joint1 ({_gains_at(controllers_file, 'joint1')}) keep a 0.5 rad step within 2 % only after "
        f"{step_response.settling_time:.2f} s; the specification allows {SPEC['settling_time']:g} s.")


@graded(points=1, after=(PID_RULE, OVERSHOOT, SETTLING), hint=_step_check_hint("final error"))
def test_step_final_error(controllers_file: Path, step_response: tuning.StepResponse) -> None:
    assert abs(step_response.steady_state_error) <= SPEC["steady_state_error"], (
        f"your gains of joint1 ({_gains_at(controllers_file, 'joint1')}) end {step_response.steady_state_error:+.4f} "
        f"rad from a 0.5 rad step; the specification allows {SPEC['steady_state_error']:g} rad.")
