"""Grader of task 4: the seven introspection questions, answered with the controller manager's API.

The specification (ROSCon 2022 workshop, task 4, answered there with ``ros2 control`` commands):

1. which controllers are loaded (``list_controllers``);
2. in which state each controller is (``list_controllers``);
3. in which state each hardware component is (``list_hardware_components``);
4. which interfaces are available and which are claimed (``list_hardware_interfaces``);
5. how to switch from one controller to another: load it inactive (``spawner --inactive``), then one
   ``switch_controllers --deactivate old --activate new``;
6. what happens when all controllers are activated at once: the switch is rejected, the error names the
   command interface both claim and the two controllers, and nothing changes;
7. which interfaces each controller uses (``list_controllers -v``).

The learner's ``introspection.py`` has one function per question. Each check brings up fresh systems (the
workshop's RRBot, a prefixed RRBot with other controller names, two RRBots as two hardware components, hardware
left unconfigured) and compares the function's answer with what the specification says for that system, so an
answer typed in by hand cannot pass.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import descriptions_root

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
    """The learner's introspection.py, imported from the graded track."""
    path = task_file(TASK, MAIN_FILE)
    name = "rrbot_workshop_graded_task04_introspection"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None, f"cannot load {path} as a Python module"
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # noqa: BLE001 - any error in the learner's file is a failed check
        sys.modules.pop(name, None)
        pytest.fail(f"{path} does not import: {type(exc).__name__}: {exc}", pytrace=False)
    return module


def _answer(answers: ModuleType, function: str, *args: Any) -> Any:
    """Call the learner's ``function``; a TODO or an error fails the check with a clear message."""
    fn = getattr(answers, function, None)
    if not callable(fn):
        pytest.fail(f"introspection.py has no function '{function}'", pytrace=False)
    try:
        return fn(*args)
    except NotImplementedError as exc:
        pytest.fail(f"{function}() is not written yet ({exc})", pytrace=False)
    except Exception as exc:  # noqa: BLE001 - the learner's error is the check's failure
        pytest.fail(f"{function}() raised {type(exc).__name__}: {exc}", pytrace=False)


# --------------------------------------------------------------------------------------------- systems


def _rrbot_controllers(prefix: str = "", rename: dict[str, str] | None = None,
                       forward_joints: tuple[str, ...] = ("joint1", "joint2")) -> dict[str, Any]:
    """The workshop's controllers YAML (as a mapping), for a prefixed RRBot and with other controller names."""
    rename = rename or {}
    base = yaml.safe_load((descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml").read_text())
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


# --------------------------------------------------------------------------------------------- 4.1, 4.2


@graded(points=2, hint=(
    "Task 4.1: every loaded controller whatever its state (unconfigured ones too), computed from the system: the "
    "grader renames the controllers.",
    "cm.list_controllers() answers as `ros2 control list_controllers` does: one entry per loaded controller, with "
    ".name, .state, .claimed_interfaces.",
    "return [c.name for c in cm.list_controllers()]",
))
def test_loaded_controllers(answers: ModuleType) -> None:
    expected = {
        "workshop": [FORWARD, JSB, JTC],
        "renamed_unconfigured": sorted(RENAMED.values()),
    }
    for kind, names in expected.items():
        with _system(kind) as system:
            got = _answer(answers, "loaded_controllers", system)
        assert isinstance(got, list), f"loaded_controllers() must return a list of names, got {type(got).__name__}"
        assert sorted(got) == names, f"on the '{kind}' system: loaded_controllers() gave {got}, expected {names}"


@graded(points=3, hint="Task 4.2: {c.name: c.state for c in cm.list_controllers()}. A controller that is only "
        "loaded is 'unconfigured', a configured one that does not run is 'inactive', a running one 'active'.")
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
        assert got == states, f"on the '{kind}' system: controller_states() gave {got}, expected {states}"
        assert got_from_cm == states, "controller_states() must accept the controller manager as well as the system"


# --------------------------------------------------------------------------------------------- 4.3, 4.4


@graded(points=2, hint="Task 4.3: {hw.name: hw.state.label for hw in cm.list_hardware_components()}: one entry "
        "per <ros2_control> tag; .state is a lifecycle State, its .label is the string.")
def test_hardware_component_states(answers: ModuleType, tmp_path: Path) -> None:
    expected = {
        "workshop": {"rrbot": "active"},
        "two_arms": {"left_rrbot": "active", "right_rrbot": "inactive"},
        "hardware_unconfigured": {"rrbot": "unconfigured"},
    }
    for kind, states in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "hardware_component_states", system)
        assert got == states, f"on the '{kind}' system: hardware_component_states() gave {got}, expected {states}"


@graded(points=3, hint="Task 4.4: from cm.list_hardware_interfaces(): sorted names of the command interfaces with "
        "is_available, of the state interfaces with is_available, and of the command interfaces with is_claimed. "
        "Unconfigured hardware makes its interfaces unavailable.")
def test_available_interfaces(answers: ModuleType, tmp_path: Path) -> None:
    arms = {f"{side}_{n}" for side in ("left", "right") for n in RRBOT_STATES}
    arm_commands = {f"{side}_{n}" for side in ("left", "right") for n in RRBOT_COMMANDS}
    expected = {
        "workshop": {"command": RRBOT_COMMANDS, "state": RRBOT_STATES, "claimed": ["joint1/position", "joint2/position"]},
        "two_arms": {"command": sorted(arm_commands), "state": sorted(arms),
                     "claimed": ["left_joint1/position", "left_joint2/position"]},
        "hardware_unconfigured": {"command": [], "state": [], "claimed": []},
    }
    for kind, interfaces in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "available_interfaces", system)
        assert isinstance(got, dict), f"available_interfaces() must return a dict, got {type(got).__name__}"
        for key in ("command", "state", "claimed"):
            assert key in got, f"available_interfaces() has no key '{key}' (it must have 'command', 'state', 'claimed')"
            assert sorted(got[key]) == interfaces[key], (
                f"on the '{kind}' system: available_interfaces()['{key}'] gave {list(got[key])}, "
                f"expected {interfaces[key]}"
            )


# --------------------------------------------------------------------------------------------- 4.5


@graded(points=3, hint="Task 4.5: load and configure the new controller if it is not loaded yet (spawner "
        "--inactive), then cm.switch_controllers(activate=[new], deactivate=[old], strictness='strict'), and return "
        "the controller states afterwards.")
def test_switch_between(answers: ModuleType) -> None:
    with _system("workshop") as system:
        got = _answer(answers, "switch_between", system, FORWARD, JTC)
        live = _states(system)
        claimed = {c.name: sorted(c.claimed_interfaces) for c in system.controller_manager.list_controllers()}
        back = _answer(answers, "switch_between", system, JTC, FORWARD)
        live_back = _states(system)
    want = {JSB: "active", FORWARD: "inactive", JTC: "active"}
    assert live == want, f"after switch_between(system, '{FORWARD}', '{JTC}') the states are {live}, expected {want}"
    assert got == live, f"switch_between() must return the states after the switch: gave {got}, they are {live}"
    assert claimed[JTC] == ["joint1/position", "joint2/position"], f"{JTC} should claim the joints: {claimed}"
    want_back = {JSB: "active", FORWARD: "active", JTC: "inactive"}
    assert live_back == want_back, f"switching back gave {live_back}, expected {want_back}"
    assert back == live_back, "switch_between() must return the states after the switch"

    with _system("jtc_only") as system:  # the new controller is not loaded yet: spawner --inactive first
        got = _answer(answers, "switch_between", system, JTC, FORWARD)
        live = _states(system)
    want = {JSB: "active", JTC: "inactive", FORWARD: "active"}
    assert live == want, (
        f"with '{FORWARD}' not loaded, switch_between(system, '{JTC}', '{FORWARD}') left the states {live}, "
        f"expected {want}: load and configure it first"
    )
    assert got == live, "switch_between() must return the states after the switch"

    with _system("renamed") as system:
        got = _answer(answers, "switch_between", system, RENAMED[JTC], RENAMED[FORWARD])
    want = {RENAMED[JSB]: "active", RENAMED[JTC]: "inactive", RENAMED[FORWARD]: "active"}
    assert got == want, f"on the 'renamed' system switch_between() gave {got}, expected {want}"


@graded(points=1, hint="Task 4.5: the swap is ONE switch_controllers call with both lists (activate=[new], "
        "deactivate=[old]), as `ros2 control switch_controllers --deactivate old --activate new`: two calls leave the "
        "robot without a controller in between, or are rejected because the interfaces are still claimed.")
def test_switch_is_one_step(answers: ModuleType) -> None:
    with _system("workshop") as system:
        cm = system.controller_manager
        calls: list[tuple[list[str], list[str]]] = []
        original = cm.switch_controllers

        def spy(activate: Any = (), deactivate: Any = (), *args: Any, **kwargs: Any) -> Any:
            calls.append((list(activate), list(deactivate)))
            return original(activate, deactivate, *args, **kwargs)

        cm.switch_controllers = spy  # type: ignore[method-assign]
        _answer(answers, "switch_between", system, FORWARD, JTC)
    assert calls == [([JTC], [FORWARD])], (
        f"switch_between() called switch_controllers as {calls} (activate, deactivate); expected one call that "
        f"activates ['{JTC}'] and deactivates ['{FORWARD}']"
    )


# --------------------------------------------------------------------------------------------- 4.6


@graded(points=3, hint="Task 4.6: activate every 'inactive' controller in one switch, catch the SwitchError, and "
        "return the names it quotes: the command interfaces (joint1/position...) and the controllers that both want "
        "them, each list sorted.")
def test_conflict_names(answers: ModuleType) -> None:
    joints = ["joint1/position", "joint2/position"]
    expected = {
        "workshop": {"interfaces": joints, "controllers": sorted([FORWARD, JTC])},
        "both_inactive": {"interfaces": joints, "controllers": sorted([FORWARD, JTC])},
        "renamed": {"interfaces": ["r1_joint2/position"], "controllers": sorted([RENAMED[FORWARD], RENAMED[JTC]])},
    }
    for kind, names in expected.items():
        with _system(kind) as system:
            got = _answer(answers, "activate_all_at_once", system)
        assert isinstance(got, dict), f"activate_all_at_once() must return a dict, got {type(got).__name__}"
        got_lists = {key: sorted(got.get(key, [])) for key in ("interfaces", "controllers")}
        assert got_lists == names, f"on the '{kind}' system: activate_all_at_once() gave {got}, expected {names}"


@graded(points=2, hint="Task 4.6: a rejected switch changes nothing. Ask for all the inactive controllers in ONE "
        "switch_controllers call and do not retry them one by one: the controller states and the claimed interfaces "
        "must be the same afterwards.")
def test_conflict_leaves_system_unchanged(answers: ModuleType) -> None:
    for kind in ("workshop", "both_inactive"):
        with _system(kind) as system:
            cm = system.controller_manager
            calls: list[list[str]] = []
            original = cm.switch_controllers

            def spy(activate: Any = (), *args: Any, _calls: list[list[str]] = calls, _orig: Any = original,
                    **kwargs: Any) -> Any:
                _calls.append(list(activate))
                return _orig(activate, *args, **kwargs)

            before = _snapshot(system)
            cm.switch_controllers = spy  # type: ignore[method-assign]
            _answer(answers, "activate_all_at_once", system)
            after = _snapshot(system)
        assert any(calls), (
            "activate_all_at_once() never asked switch_controllers to activate a controller: it must try to activate "
            "every inactive one"
        )
        assert after[0] == before[0], (
            f"on the '{kind}' system the controllers changed: before {[(c.name, c.state) for c in before[0]]}, "
            f"after {[(c.name, c.state) for c in after[0]]}"
        )
        assert after[1] == before[1], f"on the '{kind}' system the interfaces' availability or claims changed"
        assert after[2] == before[2], f"on the '{kind}' system the hardware changed"


# --------------------------------------------------------------------------------------------- 4.7


@graded(points=3, hint="Task 4.7: for each entry of cm.list_controllers(): 'command' = sorted(claimed_interfaces), "
        "'state' = sorted(required_state_interfaces) if the controller is active, else []. An inactive controller "
        "uses nothing, even though it lists required interfaces.")
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
        "two_arms": {
            JSB: {"command": [], "state": arm_states},
            "left_position_controller": {"command": ["left_joint1/position", "left_joint2/position"], "state": []},
            "right_position_controller": nothing,
        },
    }
    for kind, uses in expected.items():
        with _system(kind, tmp_path) as system:
            got = _answer(answers, "interfaces_in_use", system)
        assert isinstance(got, dict), f"interfaces_in_use() must return a dict, got {type(got).__name__}"
        assert sorted(got) == sorted(uses), f"on the '{kind}' system interfaces_in_use() has the controllers " \
            f"{sorted(got)}, expected {sorted(uses)}"
        for name, want in uses.items():
            have = {key: sorted(got[name].get(key, [])) for key in ("command", "state")} \
                if isinstance(got[name], dict) else got[name]
            assert have == want, f"on the '{kind}' system: interfaces_in_use()['{name}'] gave {got[name]}, expected {want}"
