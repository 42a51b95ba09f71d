"""Grader of task 4: the seven introspection questions, answered with the controller manager's API.

The specification (ROSCon 2022 workshop, task 4, answered there with ``ros2 control`` commands; the exercise's
docstrings and TODOs):

1. which controllers are loaded, whatever their state, in the order ``list_controllers`` gives;
2. in which state each controller is (``list_controllers``);
3. in which state each hardware component is (``list_hardware_components``);
4. which interfaces are available and which are claimed (``list_hardware_interfaces``), each list sorted;
5. how to switch from one controller to another: load and configure it if needed (``spawner --inactive``), then ONE
   strict ``switch_controllers --deactivate old --activate new --strict``; a rejected switch raises ``SwitchError``
   and changes nothing;
6. what happens when all inactive controllers are activated at once, in one strict switch: the switch is rejected,
   the error names the command interfaces and the controllers (each list sorted), and nothing changes; both lists
   are empty when the switch goes through;
7. which interfaces each controller uses (``list_controllers -v``), each list sorted, nothing for an inactive one.

The learner's ``introspection.py`` has one function per question. Each check brings up fresh systems (the
workshop's RRBot, a prefixed RRBot with other controller names, two RRBots as two hardware components, hardware
left unconfigured, controllers only loaded) and compares the function's answer with what the specification says
for that system, so an answer typed in by hand cannot pass. Lists the task asks to be sorted are compared as
they are: the grader never sorts them. A generated check (Hypothesis) then runs sequences of load, configure,
activate, deactivate, cleanup, unload and hardware state changes, and compares the answers of questions 1-4 and 7
after each step with the library's own introspection (``list_controllers``, ``list_hardware_components``,
``list_hardware_interfaces``), reporting the shortest sequence after which they differ.
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

import rrbot_workshop as rw
from rrbot_workshop.controller_manager.switch import normalize_strictness
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import descriptions_root, process_xacro
from rrbot_workshop.exceptions import RRBotWorkshopError

TASK = 4
MAIN_FILE = "introspection.py"

JSB = "joint_state_broadcaster"
FORWARD = "forward_position_controller"
JTC = "joint_trajectory_controller"
RRBOT_STATES = sorted(
    [f"{j}/{i}" for j in ("joint1", "joint2") for i in ("position", "velocity", "acceleration", "effort")]
    + [f"tcp_fts_sensor/{a}" for a in ("fx", "fy", "fz", "tx", "ty", "tz")]
    + [f"flange_gpios/digital_{d}" for d in ("in_1", "in_2", "out_1", "out_2")]
)
RRBOT_COMMANDS = sorted(
    [f"{j}/{i}" for j in ("joint1", "joint2") for i in ("position", "velocity")]
    + ["flange_gpios/digital_out_1", "flange_gpios/digital_out_2"]
)

_TWO_ARMS = """<?xml version="1.0"?>
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


# --------------------------------------------------------------------------------------------- the learner's module


@pytest.fixture(scope="module")
def answers(task_file: Callable[[int, str], Path]) -> ModuleType:
    """The learner's introspection.py, imported from the graded track; an error in it propagates at its line."""
    path = task_file(TASK, MAIN_FILE)
    name = "rrbot_workshop_graded_task04_introspection"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"{MAIN_FILE} cannot be loaded as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _answer(answers: ModuleType, function: str, *args: Any) -> Any:
    """Call the learner's ``function``; what it raises propagates (the learner's error, at its line).

    Questions 4.5 and 4.6 build on 4.2's controller_states (their TODOs say so): while they are asked, the truth stands
    in for it, so a slip in 4.2 costs 4.2's points, not theirs too.
    """
    fn = getattr(answers, function, None)
    if not callable(fn):
        pytest.fail(f"{MAIN_FILE} has no function {function}()", pytrace=False)
    if function not in ("switch_between", "activate_all_at_once"):
        return fn(*args)
    kept = getattr(answers, "controller_states", None)
    answers.controller_states = lambda target: ref_states(getattr(target, "controller_manager", target))
    try:
        return fn(*args)
    finally:
        answers.controller_states = kept


def _list_difference(got: Any, want: list[str]) -> str:
    """How a list of names differs from the expected one, in a few words (long lists are not printed whole)."""
    got = list(got)
    if len(got) + len(want) <= 8:
        return f"gave {got}, expected {want}"
    missing = [n for n in want if n not in got]
    extra = [n for n in got if n not in want]
    parts = []
    if missing:
        parts.append(f"misses {len(missing)} name(s), such as {missing[:2]}")
    if extra:
        parts.append(f"has {len(extra)} name(s) it should not, such as {extra[:2]}")
    return " and ".join(parts) or f"gave {len(got)} names where {len(want)} were expected"


def _out_of_order(got: list[Any], want: list[str], order: str) -> str:
    first = next(i for i, (a, b) in enumerate(zip(got, want, strict=True)) if a != b)
    rule = "sorted by name" if order == "sorted" else "in list_controllers() order"
    return f"has the right names, not {rule}: {got[first]!r} where {want[first]!r} belongs"


def _same(what: str, got: Any, want: Any, order: str = "sorted") -> None:
    """``got == want``, or a sentence in a few words: lists of names say what is missing, extra or out of order."""
    if got == want:
        return
    if isinstance(got, (list, tuple)) and isinstance(want, list):
        if sorted(map(str, got)) == sorted(want):
            pytest.fail(f"{what} {_out_of_order(list(got), want, order)}", pytrace=False)
        pytest.fail(f"{what} {_list_difference(got, want)}", pytrace=False)
    if isinstance(got, dict) and isinstance(want, dict) and all(isinstance(v, str) for v in want.values()):
        wrong = [f"{k}: {got.get(k, 'missing')!r} (expected {v!r})" for k, v in want.items() if got.get(k) != v]
        wrong += [f"{k}: {got[k]!r} (not expected at all)" for k in got if k not in want]
        pytest.fail(f"{what} is wrong for {'; '.join(wrong)}", pytrace=False)
    pytest.fail(f"{what} gave {got!r}, expected {want!r}", pytrace=False)


# --------------------------------------------------------------------------------------------- systems


@functools.cache
def _workshop_yaml() -> dict[str, Any]:
    """The workshop's controllers YAML, read once (callers copy it)."""
    return yaml.safe_load((descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml").read_text())


@functools.cache
def _rrbot_urdf(prefix: str) -> str:
    """RRBot's URDF with ``prefix``, expanded once per prefix (the generated checks bring up many systems)."""
    return process_xacro(descriptions_root() / "rrbot" / "urdf" / "rrbot.urdf.xacro", prefix=prefix)


def _rrbot_controllers(prefix: str = "", rename: dict[str, str] | None = None,
                       forward_joints: tuple[str, ...] = ("joint1", "joint2")) -> dict[str, Any]:
    """The workshop's controllers YAML (as a mapping), for a prefixed RRBot and with other controller names."""
    rename = rename or {}
    base = copy.deepcopy(_workshop_yaml())
    manager = base["controller_manager"]["ros__parameters"]
    out: dict[str, Any] = {"controller_manager": {"ros__parameters": {"update_rate": manager["update_rate"]}}}
    for name in (JSB, FORWARD, JTC):
        out["controller_manager"]["ros__parameters"][rename.get(name, name)] = manager[name]
    for name in (FORWARD, JTC):
        params = dict(base[name]["ros__parameters"])
        joints = forward_joints if name == FORWARD else ("joint1", "joint2")
        params["joints"] = [prefix + j for j in joints]
        out[rename.get(name, name)] = {"ros__parameters": params}
    return out


#: Names of the "renamed" configuration: a prefixed RRBot whose controllers are called differently.
RENAMED = {JSB: "state_broadcaster", FORWARD: "position_commander", JTC: "trajectory_follower"}


@contextmanager
def _system(kind: str, tmp_path: Path | None = None) -> Iterator[rw.System]:
    """A fresh system of one of the graded configurations; shut down on exit."""
    if kind == "workshop":  # the workshop's rrbot.launch.py: forward controller running, JTC loaded inactive
        system = rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FORWARD], inactive=[JTC])
    elif kind == "both_inactive":  # only the broadcaster runs; both joint controllers are ready
        system = rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB], inactive=[FORWARD, JTC])
    elif kind == "jtc_only":  # the trajectory controller runs; the forward controller is not loaded
        system = rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, JTC])
    elif kind == "renamed":  # prefix r1_, other names, the commander only on joint2
        system = rw.bringup(
            "rrbot", _rrbot_controllers("r1_", RENAMED, forward_joints=("joint2",)), xacro_args={"prefix": "r1_"},
            spawn=[RENAMED[JSB], RENAMED[JTC]], inactive=[RENAMED[FORWARD]],
        )
    elif kind == "renamed_unconfigured":  # as "renamed", the commander only loaded (unconfigured)
        system = rw.bringup(
            "rrbot", _rrbot_controllers("r1_", RENAMED, forward_joints=("joint2",)), xacro_args={"prefix": "r1_"},
            spawn=[RENAMED[JSB], RENAMED[JTC]],
        )
        system.controller_manager.load_controller(RENAMED[FORWARD])
    elif kind == "two_arms":  # two hardware components; the right arm's hardware is left inactive
        assert tmp_path is not None
        path = tmp_path / "two_rrbots.urdf.xacro"
        path.write_text(_TWO_ARMS)
        controllers = {
            "controller_manager": {"ros__parameters": {
                "update_rate": 100,
                JSB: {"type": "joint_state_broadcaster/JointStateBroadcaster"},
                "left_position_controller": {"type": "forward_command_controller/ForwardCommandController"},
                "right_position_controller": {"type": "forward_command_controller/ForwardCommandController"},
            }},
            "left_position_controller": {"ros__parameters": {
                "joints": ["left_joint1", "left_joint2"], "interface_name": "position"}},
            "right_position_controller": {"ros__parameters": {
                "joints": ["right_joint1", "right_joint2"], "interface_name": "position"}},
        }
        system = rw.bringup(
            path, controllers, spawn=[JSB, "left_position_controller"], inactive=["right_position_controller"],
            hardware_initial_state={"right_rrbot": "inactive"},
        )
    elif kind == "joints_reversed":  # both joint controllers on [joint2, joint1]: lists come in that order
        config = _rrbot_controllers(forward_joints=("joint2", "joint1"))
        config[JTC]["ros__parameters"]["joints"] = ["joint2", "joint1"]
        system = rw.bringup("rrbot", config, spawn=[JSB, JTC], inactive=[FORWARD])
    elif kind == "no_conflict":  # the forward controller is ready and nothing holds its joints
        system = rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB], inactive=[FORWARD])
    elif kind == "hardware_unconfigured":  # hardware loaded but not configured: nothing is available
        system = rw.bringup("rrbot", "rrbot_controllers.yaml", hardware_initial_state={"rrbot": "unconfigured"})
    else:
        raise ValueError(f"unknown configuration '{kind}'")
    try:
        yield system
    finally:
        system.shutdown()


def _states(system: rw.System) -> dict[str, str]:
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


def _snapshot(system: rw.System) -> tuple[Any, Any, Any]:
    cm = system.controller_manager
    return cm.list_controllers(), cm.list_hardware_interfaces(), cm.list_hardware_components()


# --------------------------------------------------------------------------------------------- the reference


def ref_loaded(cm: Any) -> list[str]:
    return [c.name for c in cm.list_controllers()]


def ref_states(cm: Any) -> dict[str, str]:
    return {c.name: c.state for c in cm.list_controllers()}


def ref_hardware(cm: Any) -> dict[str, str]:
    return {c.name: c.state.label for c in cm.list_hardware_components()}


def ref_available(cm: Any) -> dict[str, list[str]]:
    listing = cm.list_hardware_interfaces()
    return {
        "command": sorted(i.name for i in listing.command_interfaces if i.is_available),
        "state": sorted(i.name for i in listing.state_interfaces if i.is_available),
        "claimed": sorted(i.name for i in listing.command_interfaces if i.is_claimed),
    }


def ref_in_use(cm: Any) -> dict[str, dict[str, list[str]]]:
    return {
        c.name: {"command": sorted(c.claimed_interfaces),
                 "state": sorted(c.required_state_interfaces) if c.state == "active" else []}
        for c in cm.list_controllers()
    }


def _dict_of_lists(what: str, got: Any, want: dict[str, Any]) -> None:
    """Compare a dict whose values are lists (or dicts of lists) key by key, lists as given (never sorted here)."""
    if not isinstance(got, dict):
        pytest.fail(f"{what} must return a dict, got {type(got).__name__} {got!r}", pytrace=False)
    if sorted(got) != sorted(want):
        pytest.fail(f"{what} has the keys {sorted(got)}, expected {sorted(want)}", pytrace=False)
    for key, value in want.items():
        if isinstance(value, dict):
            _dict_of_lists(f"{what}['{key}']", got[key], value)
        else:
            _same(f"{what}['{key}']", got[key], value)


# --------------------------------------------------------------------------------------------- 4.1, 4.2


@graded(points=2, hint=(
    "Task 4.1: every loaded controller counts, whatever its state (only loaded = unconfigured, configured = "
    "inactive, running = active), in the order the controller manager lists them; the grader renames the "
    "controllers, so compute the names from the system.",
    "controller_manager_of(target).list_controllers() answers as `ros2 control list_controllers` does: one entry "
    "per loaded controller, with .name, .state, .claimed_interfaces ...",
    "cm = controller_manager_of(target)\nreturn [c.name for c in cm.list_controllers()]",
))
def test_loaded_controllers(answers: ModuleType) -> None:
    for kind, names in {"workshop": {JSB, FORWARD, JTC}, "renamed_unconfigured": set(RENAMED.values()),
                        "jtc_only": {JSB, JTC}}.items():
        with _system(kind) as system:
            want = ref_loaded(system.controller_manager)
            assert set(want) == names, f"grader: the '{kind}' system has the controllers {want}"
            got = _answer(answers, "loaded_controllers", system)
            _same(f"on the '{kind}' system, loaded_controllers()", got, want, order="listed")
            _same(f"on the '{kind}' system, loaded_controllers(system.controller_manager)",
                  _answer(answers, "loaded_controllers", system.controller_manager), want, order="listed")


@graded(points=2, after=("test_loaded_controllers",), hint=(
    "Task 4.2: each loaded controller's lifecycle state as a label: 'unconfigured' when only loaded, 'inactive' "
    "when configured but not running, 'active' when running.",
    "Each entry of cm.list_controllers() has .name and .state (already the label, a string).",
    "return {c.name: c.state for c in controller_manager_of(target).list_controllers()}",
))
def test_controller_states(answers: ModuleType) -> None:
    expected = {
        "workshop": {JSB: "active", FORWARD: "active", JTC: "inactive"},
        "both_inactive": {JSB: "active", FORWARD: "inactive", JTC: "inactive"},
        "renamed_unconfigured": {RENAMED[JSB]: "active", RENAMED[JTC]: "active", RENAMED[FORWARD]: "unconfigured"},
    }
    for kind, states in expected.items():
        with _system(kind) as system:
            got = _answer(answers, "controller_states", system)
            got_from_cm = _answer(answers, "controller_states", system.controller_manager)
        _same(f"on the '{kind}' system, controller_states()", got, states)
        _same(f"on the '{kind}' system, controller_states(system.controller_manager)", got_from_cm, states)


# --------------------------------------------------------------------------------------------- 4.3, 4.4


@graded(points=2, hint=(
    "Task 4.3: one entry per hardware component (one per <ros2_control> tag, so two for two RRBots), with its "
    "lifecycle state as a label: 'unconfigured', 'inactive' or 'active'.",
    "cm.list_hardware_components() gives .name and .state; .state is a lifecycle State object, its .label is the "
    "string.",
    "return {hw.name: hw.state.label for hw in controller_manager_of(target).list_hardware_components()}",
))
def test_hardware_component_states(answers: ModuleType, tmp_path: Path) -> None:
    expected = {
        "workshop": {"rrbot": "active"},
        "two_arms": {"left_rrbot": "active", "right_rrbot": "inactive"},
        "hardware_unconfigured": {"rrbot": "unconfigured"},
    }
    for kind, states in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "hardware_component_states", system)
        _same(f"on the '{kind}' system, hardware_component_states()", got, states)


@graded(points=3, hint=(
    "Task 4.4: an interface exists from the moment its component is loaded but is available only while the "
    "component is configured (inactive or active); a command interface is claimed while an active controller "
    "holds it. Three lists, each sorted by name.",
    "cm.list_hardware_interfaces() has .command_interfaces and .state_interfaces, entries with .name, "
    ".is_available and .is_claimed.",
    "listing = cm.list_hardware_interfaces()\nreturn {\"command\": sorted(i.name for i in listing.command_interfaces "
    "if i.is_available), \"state\": sorted(... state_interfaces if i.is_available), \"claimed\": sorted(... "
    "command_interfaces if i.is_claimed)}",
))
def test_available_interfaces(answers: ModuleType, tmp_path: Path) -> None:
    arms = {f"{side}_{n}" for side in ("left", "right") for n in RRBOT_STATES}
    arm_commands = {f"{side}_{n}" for side in ("left", "right") for n in RRBOT_COMMANDS}
    expected = {
        "workshop": {"command": RRBOT_COMMANDS, "state": RRBOT_STATES,
                     "claimed": ["joint1/position", "joint2/position"]},
        "two_arms": {"command": sorted(arm_commands), "state": sorted(arms),
                     "claimed": ["left_joint1/position", "left_joint2/position"]},
        "hardware_unconfigured": {"command": [], "state": [], "claimed": []},
        "renamed": {"command": ["r1_" + n for n in RRBOT_COMMANDS], "state": ["r1_" + n for n in RRBOT_STATES],
                    "claimed": ["r1_joint1/position", "r1_joint2/position"]},
    }
    for kind, interfaces in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "available_interfaces", system)
        _dict_of_lists(f"on the '{kind}' system, available_interfaces()", got, interfaces)


# --------------------------------------------------------------------------------------------- 4.5


@graded(points=3, hint=(
    "Task 4.5: the new controller may not be loaded yet, or only loaded (unconfigured): bring it to inactive first, "
    "as `spawner <name> --inactive` does, then swap; return the controller states after the switch.",
    "cm.load_controller(name) if it is not in cm.controllers; cm.configure_controller(name) if its state is "
    "'unconfigured'; then cm.switch_controllers(activate=[new], deactivate=[old], strictness=\"strict\").",
    "if activate not in cm.controllers:\n    cm.load_controller(activate)\nif controller_states(cm)[activate] == "
    "\"unconfigured\":\n    cm.configure_controller(activate)\ncm.switch_controllers(activate=[activate], "
    "deactivate=[deactivate], strictness=\"strict\")\nreturn controller_states(cm)",
))
def test_switch_between(answers: ModuleType) -> None:
    with _system("workshop") as system:
        got = _answer(answers, "switch_between", system, FORWARD, JTC)
        live = _states(system)
        claimed = {c.name: sorted(c.claimed_interfaces) for c in system.controller_manager.list_controllers()}
        back = _answer(answers, "switch_between", system, JTC, FORWARD)
        live_back = _states(system)
    want = {JSB: "active", FORWARD: "inactive", JTC: "active"}
    _same(f"the states after switch_between(system, '{FORWARD}', '{JTC}')", live, want)
    _same("switch_between()'s answer (the controller states after the switch)", got, live)
    _same(f"the interfaces {JTC} claims after the switch", claimed[JTC], ["joint1/position", "joint2/position"])
    _same(f"the states after switching back with switch_between(system, '{JTC}', '{FORWARD}')", live_back,
          {JSB: "active", FORWARD: "active", JTC: "inactive"})
    _same("switch_between()'s answer after switching back", back, live_back)

    with _system("jtc_only") as system:  # the new controller is not loaded yet: spawner --inactive first
        got = _answer(answers, "switch_between", system, JTC, FORWARD)
        live = _states(system)
    _same(f"with '{FORWARD}' not loaded yet, the states after switch_between(system, '{JTC}', '{FORWARD}')", live,
          {JSB: "active", JTC: "inactive", FORWARD: "active"})
    _same("switch_between()'s answer", got, live)

    with _system("renamed_unconfigured") as system:  # the new controller is loaded but not configured
        got = _answer(answers, "switch_between", system, RENAMED[JTC], RENAMED[FORWARD])
        live = _states(system)
    _same(f"with '{RENAMED[FORWARD]}' only loaded (unconfigured), the states after switch_between(system, "
          f"'{RENAMED[JTC]}', '{RENAMED[FORWARD]}')", live,
          {RENAMED[JSB]: "active", RENAMED[JTC]: "inactive", RENAMED[FORWARD]: "active"})
    _same("switch_between()'s answer", got, live)


def _spy_switches(cm: Any) -> list[tuple[list[str], list[str], Any]]:
    """Record every switch_controllers call on ``cm`` as (activate, deactivate, strictness); the call goes through."""
    calls: list[tuple[list[str], list[str], Any]] = []
    original = cm.switch_controllers

    def spy(activate: Any = (), deactivate: Any = (), strictness: Any = None, *args: Any, **kwargs: Any) -> Any:
        calls.append((list(activate), list(deactivate), strictness))
        return original(activate, deactivate, strictness, *args, **kwargs)

    cm.switch_controllers = spy
    return calls


def _strict(strictness: Any) -> bool:
    """Whether the switch was asked as strict, in any form the controller manager takes ("strict", 2, ...)."""
    if strictness is None:
        return False
    try:
        return normalize_strictness(strictness) == "strict"
    except RRBotWorkshopError:
        return False


@graded(points=1, after=("test_switch_between",), hint=(
    "Task 4.5: the swap is ONE strict switch with both lists, as `ros2 control switch_controllers --deactivate old "
    "--activate new --strict`: two calls leave the robot without a controller in between or are rejected, and a "
    "best-effort switch could do half of it.",
    "cm.switch_controllers(activate=[...], deactivate=[...], strictness=\"strict\") takes both lists at once; "
    "the default strictness is best_effort in Jazzy.",
    "cm.switch_controllers(activate=[activate], deactivate=[deactivate], strictness=\"strict\")",
))
def test_switch_is_one_strict_step(answers: ModuleType) -> None:
    with _system("renamed") as system:
        calls = _spy_switches(system.controller_manager)
        _answer(answers, "switch_between", system, RENAMED[JTC], RENAMED[FORWARD])
    described = [(a, d, s) for a, d, s in calls]
    ok = len(calls) == 1 and calls[0][0] == [RENAMED[FORWARD]] and calls[0][1] == [RENAMED[JTC]]
    assert ok, (
        f"switch_between() called switch_controllers {len(calls)} time(s), as (activate, deactivate, strictness) "
        f"{described}; expected one call that activates ['{RENAMED[FORWARD]}'] and deactivates ['{RENAMED[JTC]}']"
    )
    assert _strict(calls[0][2]), (
        f"switch_between() switched with strictness={calls[0][2]!r}; the swap must be strict "
        "(strictness=\"strict\"), so that a rejected switch changes nothing"
    )


@graded(points=1, after=("test_switch_between", "test_switch_is_one_strict_step"), hint=(
    "Task 4.5: a switch the controller manager rejects raises SwitchError, and nothing changes: switch_between "
    "must let the error through, not catch it, retry or return states as if it had worked.",
    "A strict cm.switch_controllers raises rw.SwitchError when any part is impossible (here: the new controller "
    "needs interfaces that a third, still active controller holds).",
    "Call cm.switch_controllers(..., strictness=\"strict\") without try/except around it.",
))
def test_rejected_switch_raises_and_changes_nothing(answers: ModuleType) -> None:
    with _system("workshop") as system:  # JTC needs the joints the forward controller holds; JSB is let go instead
        before = _snapshot(system)
        try:
            got = _answer(answers, "switch_between", system, JSB, JTC)
        except rw.SwitchError:
            got = None
        after = _snapshot(system)
        states = _states(system)
    changed = {n: s for n, s in states.items() if s != {JSB: "active", FORWARD: "active", JTC: "inactive"}[n]}
    assert after == before, (
        f"switch_between(system, '{JSB}', '{JTC}') while '{FORWARD}' holds the joints changed the system ({changed}); "
        "that switch is rejected, and a rejected switch must change nothing"
    )
    assert got is None, (
        f"switch_between(system, '{JSB}', '{JTC}') while '{FORWARD}' holds the joints returned instead of raising; "
        "the switch is rejected, so SwitchError must reach the caller"
    )


# --------------------------------------------------------------------------------------------- 4.6


@graded(points=3, hint=(
    "Task 4.6: ask for every inactive controller in one strict switch; when it is rejected, answer with the names "
    "the rejection quotes: the command interfaces and the controllers involved, each list sorted.",
    "catch rw.SwitchError: the exception carries its data (help(rw.SwitchError)): .interfaces and .controllers, "
    "no need to parse its text.",
    "except SwitchError as error:\n    return {\"interfaces\": sorted(error.interfaces), \"controllers\": "
    "sorted(error.controllers)}",
))
def test_conflict_names(answers: ModuleType) -> None:
    joints = ["joint1/position", "joint2/position"]
    expected = {
        "workshop": {"interfaces": joints, "controllers": sorted([FORWARD, JTC])},
        "both_inactive": {"interfaces": joints, "controllers": sorted([FORWARD, JTC])},
        "renamed": {"interfaces": ["r1_joint2/position"], "controllers": sorted([RENAMED[FORWARD], RENAMED[JTC]])},
        "joints_reversed": {"interfaces": joints, "controllers": sorted([FORWARD, JTC])},
    }
    for kind, names in expected.items():
        with _system(kind) as system:
            got = _answer(answers, "activate_all_at_once", system)
        _dict_of_lists(f"on the '{kind}' system, activate_all_at_once()", got, names)


@graded(points=1, after=("test_conflict_names",), hint=(
    "Task 4.6: when nothing conflicts, the switch goes through: the inactive controllers are now active and both "
    "lists are empty.",
    "If cm.switch_controllers raises nothing, the answer is {\"interfaces\": [], \"controllers\": []}.",
    "try:\n    cm.switch_controllers(activate=inactive, strictness=\"strict\")\nexcept SwitchError as error:\n"
    "    return {...}\nreturn {\"interfaces\": [], \"controllers\": []}",
))
def test_switch_that_goes_through(answers: ModuleType) -> None:
    with _system("no_conflict") as system:
        got = _answer(answers, "activate_all_at_once", system)
        states = _states(system)
    _same(f"with only '{FORWARD}' inactive and nothing in its way, activate_all_at_once()", got,
          {"interfaces": [], "controllers": []})
    _same(f"the states after activate_all_at_once() with only '{FORWARD}' inactive", states,
          {JSB: "active", FORWARD: "active"})


@graded(points=2, after=("test_conflict_names",), hint=(
    "Task 4.6: a rejected strict switch changes nothing. Ask for all the inactive controllers in ONE strict "
    "switch_controllers call (strictness=\"strict\") and do not retry them one by one: the controller states and "
    "the claimed interfaces must be the same afterwards.",
    "cm.switch_controllers(activate=[every inactive controller], strictness=\"strict\"): the default, best_effort, "
    "would activate what it can.",
    "inactive = [name for name, state in controller_states(cm).items() if state == \"inactive\"]\n"
    "cm.switch_controllers(activate=inactive, strictness=\"strict\")",
))
def test_conflict_leaves_system_unchanged(answers: ModuleType) -> None:
    for kind in ("workshop", "both_inactive"):
        with _system(kind) as system:
            inactive = sorted(n for n, s in _states(system).items() if s == "inactive")
            before = _snapshot(system)
            calls = _spy_switches(system.controller_manager)
            _answer(answers, "activate_all_at_once", system)
            after = _snapshot(system)
        asked = [sorted(a) for a, _, _ in calls]
        assert inactive in asked, (
            f"on the '{kind}' system activate_all_at_once() asked switch_controllers to activate {asked}; it must "
            f"ask for every inactive controller, {inactive}, in one switch"
        )
        strictness = calls[asked.index(inactive)][2]
        assert _strict(strictness), (
            f"on the '{kind}' system activate_all_at_once() switched with strictness={strictness!r}; the task asks "
            "for one strict switch (strictness=\"strict\")"
        )
        assert after[0] == before[0], (
            f"on the '{kind}' system the controllers changed: before {[(c.name, c.state) for c in before[0]]}, "
            f"after {[(c.name, c.state) for c in after[0]]}"
        )
        assert after[1] == before[1], f"on the '{kind}' system the interfaces' availability or claims changed"
        assert after[2] == before[2], f"on the '{kind}' system the hardware changed"


# --------------------------------------------------------------------------------------------- 4.7


@graded(points=3, hint=(
    "Task 4.7: an active controller uses the command interfaces it claimed and the state interfaces it requires; "
    "a controller that is not active uses none, even though it lists required interfaces. Each list sorted.",
    "Each entry of cm.list_controllers() has .state, .claimed_interfaces and .required_state_interfaces.",
    "{c.name: {\"command\": sorted(c.claimed_interfaces), \"state\": sorted(c.required_state_interfaces) if "
    "c.state == \"active\" else []} for c in cm.list_controllers()}",
))
def test_interfaces_in_use(answers: ModuleType, tmp_path: Path) -> None:
    nothing: dict[str, list[str]] = {"command": [], "state": []}
    jtc_states = ["joint1/position", "joint1/velocity", "joint2/position", "joint2/velocity"]
    arm_states = sorted(f"{side}_{n}" for side in ("left", "right") for n in RRBOT_STATES)
    expected = {
        "workshop": {
            JSB: {"command": [], "state": RRBOT_STATES},
            FORWARD: {"command": ["joint1/position", "joint2/position"], "state": []},
            JTC: nothing,
        },
        "renamed": {
            RENAMED[JSB]: {"command": [], "state": ["r1_" + n for n in RRBOT_STATES]},
            RENAMED[JTC]: {"command": ["r1_joint1/position", "r1_joint2/position"],
                           "state": ["r1_" + n for n in jtc_states]},
            RENAMED[FORWARD]: nothing,
        },
        "renamed_unconfigured": {
            RENAMED[JSB]: {"command": [], "state": ["r1_" + n for n in RRBOT_STATES]},
            RENAMED[JTC]: {"command": ["r1_joint1/position", "r1_joint2/position"],
                           "state": ["r1_" + n for n in jtc_states]},
            RENAMED[FORWARD]: nothing,
        },
        "two_arms": {
            JSB: {"command": [], "state": arm_states},
            "left_position_controller": {"command": ["left_joint1/position", "left_joint2/position"], "state": []},
            "right_position_controller": nothing,
        },
        "joints_reversed": {
            JSB: {"command": [], "state": RRBOT_STATES},
            JTC: {"command": ["joint1/position", "joint2/position"], "state": jtc_states},
            FORWARD: nothing,
        },
    }
    for kind, uses in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "interfaces_in_use", system)
        _dict_of_lists(f"on the '{kind}' system, interfaces_in_use()", got, uses)


# --------------------------------------------------------------------------------------------- generated sequences

#: Scenarios run at most by a generated check, generation and shrinking together (keeps grading fast).
SCENARIO_BUDGET = 30

_OPS = ("load", "configure", "activate", "deactivate", "cleanup", "unload")
_STEP = st.one_of(
    st.tuples(st.sampled_from(_OPS), st.sampled_from((JSB, FORWARD, JTC))),
    st.tuples(st.just("hardware"), st.sampled_from(("unconfigured", "inactive", "active"))),
)
_START = st.sampled_from(("not loaded", "unconfigured", "inactive", "active"))
_SCENARIO = st.tuples(st.sampled_from(("", "r1_")), st.booleans(), st.tuples(_START, _START, _START),
                      st.lists(_STEP, max_size=5))


def _start_system(prefix: str, names: dict[str, str], start: tuple[str, str, str]) -> tuple[rw.System, str]:
    """Bring up the scenario's RRBot with each controller in its start state; also say so in words."""
    wanted = dict(zip((JSB, FORWARD, JTC), start, strict=True))
    if wanted[FORWARD] == wanted[JTC] == "active":  # both cannot hold the joints
        wanted[JTC] = "inactive"
    spawn = [names[n] for n, s in wanted.items() if s == "active"]
    inactive = [names[n] for n, s in wanted.items() if s == "inactive"]
    config = _rrbot_controllers(prefix, names if names[JSB] != JSB else None)
    system = rw.bringup(_rrbot_urdf(prefix), config, spawn=spawn, inactive=inactive)
    for name, state in wanted.items():
        if state == "unconfigured":
            system.controller_manager.load_controller(names[name])
    loaded = ", ".join(f"{names[n]} {s}" for n, s in wanted.items() if s != "not loaded") or "no controller loaded"
    return system, f"RRBot{f' prefixed {prefix!r}' if prefix else ''} with {loaded}"

#: The questions compared with the library's introspection after every step, with their reference.
_QUESTIONS: dict[str, Callable[[Any], Any]] = {
    "loaded_controllers": ref_loaded,
    "controller_states": ref_states,
    "hardware_component_states": ref_hardware,
    "available_interfaces": ref_available,
    "interfaces_in_use": ref_in_use,
}


def _apply(system: rw.System, op: str, arg: str) -> bool:
    """Do one step with the library; False if the controller manager refused it (the system is unchanged then)."""
    cm = system.controller_manager
    try:
        if op == "hardware":
            for component in ref_hardware(cm):
                if not cm.set_hardware_component_state(component, arg):
                    return False
        elif op == "load":
            cm.load_controller(arg)
        elif op == "configure":
            cm.configure_controller(arg)
        elif op == "activate":
            cm.switch_controllers(activate=[arg], strictness="strict")
        elif op == "deactivate":
            cm.switch_controllers(deactivate=[arg], strictness="strict")
        elif op == "cleanup":
            cm.cleanup_controller(arg)
        else:
            cm.unload_controller(arg)
    except RRBotWorkshopError:
        return False
    return True


def _short(value: Any) -> str:
    """``repr`` of a value, long lists and strings abridged."""
    shortener = reprlib.Repr()
    shortener.maxlist = shortener.maxdict = 3
    shortener.maxstring = shortener.maxother = 40
    return shortener.repr(value)


def _brief_difference(got: Any, want: Any) -> str:
    """Where ``got`` first differs from ``want``, in a few words (``['key'] gave [...], expected [...]``)."""
    if isinstance(got, dict) and isinstance(want, dict):
        keys = [k for k in [*want, *(k for k in got if k not in want)] if got.get(k, ...) != want.get(k, ...)]
        if not keys:
            return f" gave {_short(got)}, expected {_short(want)}"
        more = f" (and {len(keys) - 1} more key(s))" if len(keys) > 1 else ""
        if keys[0] not in got:
            return f" has no key {keys[0]!r}{more}"
        if keys[0] not in want:
            return f" has the key {keys[0]!r}, which it should not have{more}"
        return f"[{keys[0]!r}]{_brief_difference(got[keys[0]], want[keys[0]])}{more}"
    if isinstance(got, (list, tuple)) and isinstance(want, list):
        if sorted(map(str, got)) == sorted(want) and got:
            return " " + _out_of_order(list(got), want, "sorted" if want == sorted(want) else "listed")
        return " " + _list_difference(got, want)
    return f" gave {_short(got)}, expected {_short(want)}"


def _mismatch(answers: ModuleType, system: rw.System) -> str | None:
    for function, reference in _QUESTIONS.items():
        want = reference(system.controller_manager)
        got = _answer(answers, function, system)
        if got != want:
            return f"{function}(){_brief_difference(got, want)}"
    return None


def _case(problem: str, when: str, where: str, done: list[str]) -> str:
    """The failing case in one sentence, the answer that differs first; details dropped when too long to read."""
    text = f"{problem}, {when}, on the {where}"
    if len(text) > 250:
        text = f"{problem}, {when}, on the %s" % where.split(" with ")[0]
    if len(text) > 250 and len(done) > 1:
        text = f"{problem}, after {len(done)} steps ending with {done[-1]!r}, on the %s" % where.split(" with ")[0]
    return text


@graded(points=2, after=(
    "test_loaded_controllers", "test_controller_states", "test_hardware_component_states", "test_available_interfaces",
    "test_interfaces_in_use",
), hint=(
    "Tasks 4.1-4.4 and 4.7 after any sequence of load, configure, activate, deactivate, cleanup, unload and hardware "
    "state changes: each answer must be what list_controllers(), list_hardware_components() and "
    "list_hardware_interfaces() say at that moment. The reason shows the shortest sequence where yours differs.",
    "Replay the sequence the reason names with cm.load_controller, cm.configure_controller, cm.switch_controllers, "
    "cm.cleanup_controller, cm.unload_controller and cm.set_hardware_component_state, and print your answer next "
    "to `%control list_controllers` (or list_hardware_interfaces).",
    "Compute each answer from the lists every time (no cached or typed-in names), keep every loaded controller "
    "whatever its state, and sort the lists the task asks to sort.",
))
def test_any_sequence_matches_the_controller_manager(answers: ModuleType) -> None:
    found: list[str] = []
    raised: list[BaseException] = []  # the learner's first error: raised as it is after the search, not shrunk
    budget = [SCENARIO_BUDGET]  # examples run at most: once spent, the smallest difference found so far is reported

    @settings(derandomize=True, database=None, deadline=None, max_examples=12,
              suppress_health_check=list(HealthCheck))
    @given(_SCENARIO)
    @example(("", False, ("not loaded",) * 3, []))  # the simplest cases first: nothing loaded, nothing done ...
    @example(("", False, ("not loaded",) * 3, [("hardware", "unconfigured")]))  # ... then the hardware leaves active
    def scenario(case: tuple[str, bool, tuple[str, str, str], list[tuple[str, str]]]) -> None:
        if raised or budget[0] <= 0:
            return
        budget[0] -= 1
        prefix, renamed, start, steps = case
        names = RENAMED if renamed else {n: n for n in (JSB, FORWARD, JTC)}
        system, where = _start_system(prefix, names, start)
        done: list[str] = []
        try:
            problem = _mismatch(answers, system)
            for op, arg in steps:
                target = names.get(arg, arg)
                accepted = _apply(system, op, target)
                done.append(f"{op} {target}" + ("" if accepted else " (refused)"))
                problem = problem or _mismatch(answers, system)
                if problem:
                    break
        except Exception as exc:  # noqa: BLE001 - the learner's error, raised again below with its traceback
            exc.add_note(f"(on {where}, after: {', then '.join(done) if done else 'nothing done yet'})")
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
