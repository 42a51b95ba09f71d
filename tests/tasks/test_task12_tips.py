"""Grader of task 12: parameter injection into the description and the controllers YAML at bringup.

The specification (notebook 12, the exercise's docstring and TODOs):

* ``rrbot_bringup/config/rrbot_controllers.yaml`` is the RRBot's controllers YAML (task 2) whose joints follow the
  launch argument ``prefix`` through ``$(var prefix)`` substitutions (read as launch's
  ``ParameterFile(path, allow_substs=True)`` reads it); with ``prefix=""`` it is task 2's file;
* ``rrbot_bringup/bringup.py``: ``start_rrbot(prefix="", robot_controller="forward_position_controller",
  update_rate=None, use_mock_hardware=True)`` returns a running RRBot whose every name carries ``prefix``, with the
  broadcaster and ``robot_controller`` active and the other robot controller loaded and inactive; ``update_rate``
  overrides the file's rate without changing the file; ``use_mock_hardware=False`` brings the RRBot's driver
  (``controlko_hardware_interface/RRBotHardwareInterface``) instead of ``mock_components/GenericSystem``; an unknown
  ``robot_controller`` raises ``ValueError`` whose message names the two valid controllers, before anything starts.

Every rule is tried with the defaults and with other values (prefixes, rates, the other controller, the driver),
and a generated check (Hypothesis) compares ``start_rrbot`` with the library's own bringup of the same arguments,
reporting the smallest set of arguments that tells them apart. The driver is always the library's reference here,
so task 12 never depends on the learner's task 7.
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
import yaml_places
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis.errors import HypothesisException

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, systems
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded
from rrbot_workshop.description import descriptions_root
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.hardware.rrbot import RRBotHardwareInterface
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.param_substitution import load_with_substitutions, override
from rrbot_workshop.msgs import Float64MultiArray

TASK = 12
CONTROLLERS = "rrbot_bringup/config/rrbot_controllers.yaml"
BRINGUP = "rrbot_bringup/bringup.py"
JSB, FPC, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
ROBOT_CONTROLLERS = (FPC, JTC)
MOCK = "mock_components/GenericSystem"
DRIVER = "controlko_hardware_interface/RRBotHardwareInterface"
#: Task 2's controllers YAML, as the library ships it: what the learner's file must be with ``prefix=""``.
TASK2_YAML = descriptions_root() / "rrbot" / "config" / "rrbot_controllers.yaml"


# --------------------------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def controllers_file(task_file: Callable[[int, str], Path]) -> Path:
    return task_file(TASK, CONTROLLERS)


@pytest.fixture(scope="module")
def package_copy(task_file: Callable[[int, str], Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A copy of the learner's ``rrbot_bringup`` that the bringup checks run (the learner's folder is never written).

    When the learner's controllers YAML breaks task 12.1 (judged by :func:`test_yaml_follows_the_prefix` alone), the
    copy holds task 2's file with the joints prefixed instead: one slip in the YAML costs the YAML's points only, and
    the bringup is judged on its own.
    """
    bringup = task_file(TASK, BRINGUP)
    copy = tmp_path_factory.mktemp("task12") / "rrbot_bringup"
    shutil.copytree(bringup.parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
    yaml_file = tracks.task_dir(TASK) / CONTROLLERS
    if not yaml_file.is_file() or _yaml_problem(yaml_file) is not None:
        (copy / "config").mkdir(exist_ok=True)
        (copy / "config" / Path(CONTROLLERS).name).write_text(reference_yaml())
    return copy


@pytest.fixture(scope="module")
def bringup_module(package_copy: Path, task_file: Callable[[int, str], Path]) -> ModuleType:
    """The learner's bringup.py, imported afresh from :func:`package_copy` (its ``__file__`` there, so the files it
    reads beside it are the copy's) but compiled under the learner's own path: an error in it propagates with the
    learner's file and line."""
    original = task_file(TASK, BRINGUP)
    path = package_copy / original.name
    name = "rrbot_workshop_graded_task12_bringup"
    module = ModuleType(name)
    module.__file__ = str(path)
    sys.modules[name] = module
    sys.path.insert(0, str(path.parent))
    try:
        exec(compile(path.read_bytes(), str(original), "exec"), module.__dict__)  # noqa: S102 - the learner's module
    finally:
        sys.path.remove(str(path.parent))
    if not callable(getattr(module, "start_rrbot", None)):
        pytest.fail(f"{BRINGUP} has no function start_rrbot()", pytrace=False)
    return module


@pytest.fixture(autouse=True)
def _no_system_left() -> Iterator[None]:
    """Each check starts with no system running and ends with none, even after a start_rrbot() that raised."""
    for running in list(systems().values()):
        running.shutdown()
    yield
    for running in list(systems().values()):
        running.shutdown()


@pytest.fixture(autouse=True)
def _reference_driver() -> Iterator[None]:
    """``controlko_hardware_interface/RRBotHardwareInterface`` is the library's driver here, not task 7's."""
    plugins.register("hardware", DRIVER, RRBotHardwareInterface)
    yield
    plugins.unregister("hardware", DRIVER)


# --------------------------------------------------------------------------------------------- helpers


def _call(kwargs: dict[str, Any]) -> str:
    args = ", ".join(f"{k}={v!r}" for k, v in kwargs.items())
    return f"start_rrbot({args})"


def _start(module: ModuleType, **kwargs: Any) -> System:
    """``start_rrbot(**kwargs)``; what it raises propagates (the learner's error, at its line).

    A switch the library rejects while starting the learner's configuration (joints that do not match the
    description's) is reported in one sentence naming the learner's file and the first problem.
    """
    try:
        system = module.start_rrbot(**kwargs)
    except rw.SwitchError as err:
        pytest.fail(f"{_call(kwargs)} (your {BRINGUP}): {_rejected(err)}", pytrace=False)
    if not isinstance(system, System):
        pytest.fail(f"{_call(kwargs)} returned {type(system).__name__}, not the running System that "
                    "rw.bringup(...) returns", pytrace=False)
    return system


def _rejected(err: rw.SwitchError) -> str:
    first = err.reasons[0].split(" (available", 1)[0] if err.reasons else str(err)
    return f"its controllers were refused ({first})"


def _states(system: System) -> dict[str, str]:
    return {c.name: c.state for c in system.controller_manager.list_controllers()}


def _state_differences(states: dict[str, str], want: dict[str, str]) -> str:
    """The controllers whose state is not the expected one, as a short sentence."""
    parts = [f"{name} is {states.get(name, 'not loaded')} (expected {state})" for name, state in want.items()
             if states.get(name) != state]
    parts += [f"{name} is loaded ({states[name]}) but should not be" for name in states if name not in want]
    return "; ".join(parts)


def _components(system: System) -> list[tuple[str, str, str]]:
    return [(c.name, c.plugin_name, c.state.label) for c in system.controller_manager.list_hardware_components()]


def _joints_in(data: dict[str, Any], controller: str) -> Any:
    return ((data.get(controller) or {}).get("ros__parameters") or {}).get("joints")


def summary(system: System) -> dict[str, Any]:
    """What a bringup's arguments decide, as ``ros2 control`` would show it."""
    cm = system.controller_manager
    return {
        "update rate [Hz]": cm.get_update_rate(),
        "hardware (name, plugin, state)": _components(system),
        "controllers (state, claimed interfaces)": {
            c.name: (c.state, sorted(c.claimed_interfaces)) for c in cm.list_controllers()
        },
        "state interfaces": sorted(i.name for i in cm.list_hardware_interfaces().state_interfaces),
    }


def reference_start(prefix: str = "", robot_controller: str = FPC, update_rate: int | None = None,
                    use_mock_hardware: bool = True) -> System:
    """The library's bringup of what ``start_rrbot`` is asked for (task 2's YAML, joints prefixed, rate set)."""
    config = yaml.safe_load(TASK2_YAML.read_text())
    for name in ROBOT_CONTROLLERS:
        config = override(config, name, {"joints": [f"{prefix}joint1", f"{prefix}joint2"]})
    if update_rate is not None:
        config = override(config, "controller_manager", {"update_rate": update_rate})
    other = [name for name in ROBOT_CONTROLLERS if name != robot_controller]
    return rw.bringup("rrbot", config, xacro_args={"prefix": prefix, "use_mock_hardware": use_mock_hardware},
                      spawn=[JSB, robot_controller], inactive=other)


def _differences(mine: dict[str, Any], ref: dict[str, Any]) -> str:
    """What differs between two summaries, item by item, in a few words each."""
    parts = []
    for key, want in ref.items():
        got = mine[key]
        if got == want:
            continue
        if isinstance(want, dict):
            for name in [*want, *(n for n in got if n not in want)]:
                if got.get(name) != want.get(name):
                    parts.append(f"{name}: yours {got.get(name, 'not loaded')}, expected {want.get(name, 'not loaded')}")
        elif key == "state interfaces":
            missing, extra = sorted(set(want) - set(got)), sorted(set(got) - set(want))
            parts.append(f"{len(missing)} state interfaces missing (such as {missing[:1]}), {len(extra)} unexpected "
                         f"(such as {extra[:1]})")
        else:
            parts.append(f"{key}: yours {got}, expected {want}")
    return "; ".join(parts)


# --------------------------------------------------------------------------------------------- 12.1 the YAML


@graded(points=2, hint=(
    "Task 12.1: a parameter file read with substitutions (launch's ParameterFile(path, allow_substs=True)) replaces "
    "$(var name) by the launch argument `name`; every joint name of both robot controllers must follow `prefix`, "
    "and with prefix \"\" the file must still be task 2's.",
    "Write the substitution inside the YAML value, in front of the joint's own name: the prefix is text glued to "
    "it. The notebook's cell reads your file with injection.load_with_substitutions(path, {'prefix': ...}).",
    "joints:\n  - $(var prefix)joint1\n  - $(var prefix)joint2   (in forward_position_controller AND "
    "joint_trajectory_controller)",
))
def test_yaml_follows_the_prefix(controllers_file: Path) -> None:
    problem = _yaml_problem(controllers_file)
    if problem:
        pytest.fail(problem, pytrace=False)


def reference_yaml() -> str:
    """Task 2's controllers YAML with both robot controllers' joints following ``$(var prefix)``."""
    data = yaml.safe_load(TASK2_YAML.read_text())
    for name in ROBOT_CONTROLLERS:
        data[name]["ros__parameters"]["joints"] = ["$(var prefix)joint1", "$(var prefix)joint2"]
    return yaml.safe_dump(data, sort_keys=False)


def _read(path: Path, prefix: str) -> Any:
    """The file read with ``prefix`` substituted, as the controller manager reads it; a reason if it cannot be."""
    where = f"your {path.name} read with prefix {prefix!r}"
    try:
        return rw.params.load_controllers_yaml(load_with_substitutions(path, {"prefix": prefix}))
    except (RRBotWorkshopError, yaml.YAMLError, OSError) as exc:
        return f"{where}: {' '.join(str(exc).split())}"


def _yaml_problem(path: Path) -> str | None:
    """What breaks task 12.1 in the learner's controllers YAML, starting with the file and line, or None.

    Either layout Jazzy reads is accepted: each ``type`` under the controller manager or in the controller's own
    section, block or flow style.
    """
    task2 = rw.params.load_controllers_yaml(yaml.safe_load(TASK2_YAML.read_text()))
    for prefix in ("left_", "r2_", ""):
        cfg = _read(path, prefix)
        if isinstance(cfg, str):
            return cfg
        for name in ROBOT_CONTROLLERS:
            joints = yaml_places.parameters(cfg, name).get("joints")
            want = [f"{prefix}joint1", f"{prefix}joint2"]
            if joints != want:
                where = yaml_places.at(path, yaml_places.section_keys(cfg, name), "joints")
                return (f"your {where}: read with prefix {prefix!r}, {name}'s joints are {joints}, expected {want}; "
                        "each joint must follow the launch argument with $(var prefix) glued in front of its name")
    for name in yaml_places.declared(task2):
        want_type, got_type = yaml_places.type_of(task2, name), yaml_places.type_of(cfg, name)
        if got_type != want_type:
            return (f"your {yaml_places.type_at(path, cfg, name)}: '{name}' has the type {got_type!r}; task 2's file "
                    f"gives it {want_type!r}")
        want, got = yaml_places.parameters(task2, name), yaml_places.parameters(cfg, name)
        if got != want:
            where = yaml_places.at(path, yaml_places.section_keys(cfg, name))
            return (f"your {where}: read with prefix '', {name}'s parameters are {got}; with no prefix the file must "
                    f"be task 2's: {want}")
    extra = sorted(set(yaml_places.declared(cfg)) - set(yaml_places.declared(task2)))
    if extra:
        return f"your {path.name} declares controllers task 2's file does not have: {extra}"
    if cfg.update_rate != task2.update_rate:
        return (f"your {yaml_places.at(path, yaml_places.MANAGER_KEYS, 'update_rate')}: update_rate is "
                f"{cfg.update_rate}; task 2's file runs at {task2.update_rate} Hz")
    return None


# --------------------------------------------------------------------------------------------- 12.2 the bringup


@graded(points=1, hint=(
    "Task 12.2: without arguments, start_rrbot() is task 2's robot: no prefix, mock hardware, the file's 100 Hz, "
    "joint_state_broadcaster and forward_position_controller active, joint_trajectory_controller loaded and "
    "inactive (configured, ready to be switched to).",
    "rw.bringup(description, controllers, xacro_args={...}, spawn=[...], inactive=[...]): `spawn` loads, "
    "configures and activates; `inactive` loads and configures only (the spawner's --inactive).",
    "return rw.bringup(\"rrbot\", controllers, xacro_args={\"prefix\": prefix, \"use_mock_hardware\": "
    "use_mock_hardware}, spawn=[\"joint_state_broadcaster\", robot_controller], inactive=[the other one])",
))
def test_defaults(bringup_module: ModuleType) -> None:
    system = _start(bringup_module)
    states = _states(system)
    want = {JSB: "active", FPC: "active", JTC: "inactive"}
    assert states == want, f"after start_rrbot(): {_state_differences(states, want)}"
    components = _components(system)
    assert components == [("rrbot", MOCK, "active")], (
        f"start_rrbot() brought the hardware {components} (name, plugin, state), expected one component 'rrbot' "
        f"on {MOCK}, active"
    )
    rate = system.controller_manager.get_update_rate()
    assert rate == 100, f"start_rrbot() runs at {rate} Hz; without update_rate it must keep the file's 100 Hz"


@graded(points=3, hint=(
    "Task 12.2: the prefix must reach both the description (a xacro argument: component, joint and interface "
    "names) and the controllers (the YAML read with its substitutions): then the broadcaster publishes "
    "<prefix>joint1 and the forward controller moves it. Tried with two prefixes.",
    "xacro_args={\"prefix\": prefix} for the description; load_with_substitutions(CONTROLLERS, {\"prefix\": "
    "prefix}) from rrbot_workshop.middleware.param_substitution for the controllers, passed to rw.bringup as "
    "a mapping.",
    "controllers = load_with_substitutions(CONTROLLERS, {\"prefix\": prefix})\n"
    "rw.bringup(\"rrbot\", controllers, xacro_args={\"prefix\": prefix, ...}, ...)",
))
def test_prefix_reaches_the_running_system(bringup_module: ModuleType) -> None:
    for prefix in ("left_", "r2_"):
        call = _call({"prefix": prefix})
        system = _start(bringup_module, prefix=prefix)
        components = [name for name, _, _ in _components(system)]
        assert components == [f"{prefix}rrbot"], (
            f"{call} brought the hardware components {components}, expected ['{prefix}rrbot']: the prefix must "
            "reach the description as a xacro argument"
        )
        states = _states(system)
        assert states.get(JSB) == "active" and states.get(FPC) == "active", (
            f"{call} left the controllers {states}; the broadcaster and {FPC} must be active"
        )
        claimed = sorted(next(c for c in system.controller_manager.list_controllers() if c.name == FPC)
                         .claimed_interfaces)
        want = [f"{prefix}joint1/position", f"{prefix}joint2/position"]
        assert claimed == want, f"with {call}, {FPC} claims {claimed}, expected {want}"
        system.publish(f"/{FPC}/commands", Float64MultiArray(data=[0.4, -0.2]))
        system.spin(0.1)
        msg = system.latest("/joint_states")
        system.shutdown()
        assert msg is not None, f"with {call}, nothing was published on /joint_states"
        names = list(msg.name)
        assert names == [f"{prefix}joint1", f"{prefix}joint2"], (
            f"with {call}, /joint_states names {names}, expected ['{prefix}joint1', '{prefix}joint2']"
        )
        moved = [round(p, 6) for p in msg.position]
        assert moved == [0.4, -0.2], (
            f"with {call}, the command [0.4, -0.2] on /{FPC}/commands left the joints at {moved} rad"
        )


@graded(points=2, after=("test_defaults", "test_prefix_reaches_the_running_system"), hint=(
    "Task 12.2: robot_controller chooses which robot controller runs; the other one is loaded and configured "
    "(inactive), never left unconfigured nor active. Tried both ways, with a prefix.",
    "Put robot_controller in rw.bringup's spawn list, next to the broadcaster, and the other robot controller "
    "in its inactive list.",
    "other = [c for c in (\"forward_position_controller\", \"joint_trajectory_controller\") if c != "
    "robot_controller]\nrw.bringup(..., spawn=[\"joint_state_broadcaster\", robot_controller], inactive=other)",
))
def test_robot_controller_choice(bringup_module: ModuleType) -> None:
    for chosen, other in ((JTC, FPC), (FPC, JTC)):
        kwargs = {"prefix": "r2_", "robot_controller": chosen}
        system = _start(bringup_module, **kwargs)
        states = _states(system)
        want = {JSB: "active", chosen: "active", other: "inactive"}
        assert states == want, f"after {_call(kwargs)}: {_state_differences(states, want)}"
        claimed = sorted(next(c for c in system.controller_manager.list_controllers() if c.name == chosen)
                         .claimed_interfaces)
        system.shutdown()
        assert claimed == ["r2_joint1/position", "r2_joint2/position"], (
            f"with {_call(kwargs)}, {chosen} claims {claimed}, expected ['r2_joint1/position', 'r2_joint2/position']"
        )


UNKNOWN = ("joint_state_broadcaster", "forward_position_controllers", "")


@graded(points=1, hint=(
    "Task 12.2: an unknown robot_controller is refused with ValueError before anything starts: no system may be "
    "left running. Only forward_position_controller and joint_trajectory_controller are robot controllers (the "
    "broadcaster is not one).",
    "Test robot_controller against the two valid names at the top of start_rrbot(), before rw.bringup.",
    "if robot_controller not in (\"forward_position_controller\", \"joint_trajectory_controller\"):\n"
    "    raise ValueError(...)",
))
def test_unknown_robot_controller_refused(bringup_module: ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    started: list[str] = []  # every system brought up, even one shut down again before the ValueError
    bring_up = System.__init__

    def counted(self: System, name: str, *args: Any, **kwargs: Any) -> None:
        started.append(name)
        bring_up(self, name, *args, **kwargs)

    monkeypatch.setattr(System, "__init__", counted)
    for name in UNKNOWN:
        call = _call({"robot_controller": name})
        try:
            bringup_module.start_rrbot(robot_controller=name)
        except ValueError:
            pass
        else:
            pytest.fail(f"{call} started a robot; an unknown robot_controller must raise ValueError", pytrace=False)
        left = sorted(systems())
        assert not left, f"{call} raised, but left the system(s) {left} running: refuse before starting anything"
        assert not started, (f"{call} raised ValueError, but only after bringing up the system(s) {started} (shut "
                             "down again): refuse before starting anything")


@graded(points=1, after=("test_unknown_robot_controller_refused",), hint=(
    "Task 12.2: the docstring asks the ValueError's message to name what would be valid (the project's rule for "
    "bad input): both robot controllers, forward_position_controller and joint_trajectory_controller.",
    "Put the tuple of valid names in the message, with the name that was given.",
    "raise ValueError(f\"robot_controller must be one of {ROBOT_CONTROLLERS}, got {robot_controller!r}\")",
))
def test_refusal_names_the_valid_controllers(bringup_module: ModuleType) -> None:
    for name in UNKNOWN:
        try:
            bringup_module.start_rrbot(robot_controller=name)
        except ValueError as exc:
            message = str(exc)
        else:
            pytest.fail(f"start_rrbot(robot_controller={name!r}) raised nothing, so no message names the valid "
                        "controllers", pytrace=False)
        missing = [valid for valid in ROBOT_CONTROLLERS if valid not in message]
        assert not missing, (
            f"start_rrbot(robot_controller={name!r}) raised ValueError({message!r}); the message must name the valid "
            f"controllers, and it does not name {missing}"
        )


@graded(points=2, after=("test_defaults",), hint=(
    "Task 12.2: update_rate, when given, overrides the controller manager's rate from the file (lower or higher "
    "than 100 Hz) without editing the file: the next start without it is back at the file's 100 Hz.",
    "injection.override(config, \"controller_manager\", {\"update_rate\": update_rate}) returns a changed copy of "
    "the loaded mapping; the file on disk stays as it is.",
    "if update_rate is not None:\n    controllers = override(controllers, \"controller_manager\", "
    "{\"update_rate\": update_rate})",
))
def test_update_rate_is_injected(bringup_module: ModuleType, package_copy: Path) -> None:
    controllers_file = package_copy / "config" / Path(CONTROLLERS).name
    before = controllers_file.read_text()
    for rate in (50, 250):
        system = _start(bringup_module, update_rate=rate)
        got = system.controller_manager.get_update_rate()
        controller_rates = {c.name: c.update_rate for c in system.controller_manager.list_controllers()}
        system.shutdown()
        assert got == rate, f"start_rrbot(update_rate={rate}) runs the controller manager at {got} Hz"
        slow = {n: r for n, r in controller_rates.items() if r != rate}
        assert not slow, (
            f"start_rrbot(update_rate={rate}): the controllers run at {slow} Hz, not at the loop's {rate} Hz (the YAML "
            "gives them no rate of their own)"
        )
        assert controllers_file.read_text() == before, f"start_rrbot(update_rate={rate}) changed {CONTROLLERS}"
    system = _start(bringup_module)
    got = system.controller_manager.get_update_rate()
    system.shutdown()
    assert got == 100, f"start_rrbot() after a start with update_rate runs at {got} Hz, not the file's 100 Hz"


@graded(points=2, after=("test_prefix_reaches_the_running_system",), hint=(
    "Task 12.2: use_mock_hardware chooses the hardware plugin through the xacro argument of the same name: True "
    f"gives {MOCK}, False the RRBot's driver {DRIVER}. Tried both ways, with a prefix.",
    "Pass use_mock_hardware on to the description: xacro_args={\"prefix\": prefix, \"use_mock_hardware\": "
    "use_mock_hardware}.",
    "rw.bringup(\"rrbot\", controllers, xacro_args={\"prefix\": prefix, \"use_mock_hardware\": use_mock_hardware}, "
    "...)",
))
def test_use_mock_hardware_is_injected(bringup_module: ModuleType) -> None:
    for mock, plugin in ((False, DRIVER), (True, MOCK)):
        kwargs = {"prefix": "r2_", "use_mock_hardware": mock}
        system = _start(bringup_module, **kwargs)
        components = _components(system)
        states = _states(system)
        system.shutdown()
        assert components == [("r2_rrbot", plugin, "active")], (
            f"{_call(kwargs)} brought the hardware {components} (name, plugin, state), expected "
            f"[('r2_rrbot', '{plugin}', 'active')]"
        )
        assert states.get(FPC) == "active", f"{_call(kwargs)} left the controllers {states}"


# --------------------------------------------------------------------------------------------- generated scenarios

#: Bring-ups of the learner's and the library's system compared at most (about 0.4 s a pair): the five simplest calls
#: (one argument each) come first, then generated ones; a wrong solution is graded in about 5 s.
BRINGUP_PAIRS = 9

_ARGUMENTS = st.fixed_dictionaries({}, optional={
    "prefix": st.sampled_from(["", "a_", "r2_", "left_", "arm1_"]),
    "robot_controller": st.sampled_from(ROBOT_CONTROLLERS),
    "update_rate": st.sampled_from([20, 50, 200, 500]),
    "use_mock_hardware": st.booleans(),
})


def _outcome(start: Callable[..., System], kwargs: dict[str, Any]) -> Any:
    """The summary of ``start(**kwargs)``'s system, or the error it raised, as text; nothing left running."""
    try:
        system = start(**kwargs)
        if not isinstance(system, System):
            return f"it returned {type(system).__name__}, not a System"
        return summary(system)
    except rw.SwitchError as err:
        return _rejected(err)
    except Exception as exc:  # noqa: BLE001 - a scenario's outcome; the fixed checks show the learner's traceback
        return f"it raised {type(exc).__name__}" + (f": {exc}" if str(exc) else " (with no message)")
    finally:
        for running in list(systems().values()):
            running.shutdown()


@graded(points=2, after=("test_defaults", "test_prefix_reaches_the_running_system", "test_robot_controller_choice",
                         "test_update_rate_is_injected", "test_use_mock_hardware_is_injected"), hint=(
    "Task 12.2: for any prefix, robot controller, rate and hardware choice, start_rrbot must bring the same "
    "system as the launch file would: the grader compares yours with the library's bringup of the same "
    "arguments and shows the smallest set of arguments where they differ.",
    "Each argument goes to exactly one place: prefix to the xacro AND the YAML substitutions, robot_controller to "
    "spawn (the other one to inactive), update_rate to an override of controller_manager, use_mock_hardware to "
    "the xacro.",
    "Call your start_rrbot with the arguments the reason names and print list_controllers(), "
    "list_hardware_components() and get_update_rate(): compare them with what the docstring promises.",
))
def test_any_arguments_match_the_launch_file(bringup_module: ModuleType) -> None:
    found: list[tuple[int, str]] = []  # (number of arguments, reason) of every difference found
    cache: dict[tuple[Any, ...], tuple[Any, Any]] = {}
    budget = [BRINGUP_PAIRS]  # once spent, the smallest difference found so far is reported

    @settings(derandomize=True, database=None, deadline=None, max_examples=BRINGUP_PAIRS,
              suppress_health_check=list(HealthCheck))
    @given(_ARGUMENTS)
    @example({})  # the simplest calls first, one argument each: a slip in one argument shows at its own call
    @example({"prefix": "r2_"})
    @example({"robot_controller": JTC})
    @example({"update_rate": 50})
    @example({"use_mock_hardware": False})
    def scenario(kwargs: dict[str, Any]) -> None:
        key = tuple(sorted(kwargs.items()))
        if key not in cache:
            if budget[0] <= 0:
                return
            budget[0] -= 1
            cache[key] = (_outcome(bringup_module.start_rrbot, kwargs), _outcome(reference_start, kwargs))
        mine, want = cache[key]
        if mine == want:
            return
        if isinstance(mine, dict) and isinstance(want, dict):
            found.append((len(kwargs), f"{_call(kwargs)} differs from the launch file's system: "
                                       f"{_differences(mine, want)}"))
        else:
            found.append((len(kwargs), f"{_call(kwargs)}: {mine}"))
        raise AssertionError(found[-1][1])

    try:
        scenario()
    except (AssertionError, HypothesisException, ExceptionGroup):
        if not found:
            raise
        pytest.fail(f"smallest failing call: {min(found)[1]}", pytrace=False)
