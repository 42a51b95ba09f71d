"""Grader of task 6: the lifecycle of controllers and hardware, driven through the controller manager.

The specification (``lifecycle.py`` of the task folder and notebook 06), each function run on a fresh mock RRBot:

* ``switch_to_trajectory_controller(cm)``: with the broadcaster and the forward position controller active and the
  trajectory controller not loaded, load and configure the trajectory controller, then deactivate the forward
  controller and activate the trajectory controller in ONE strict switch, so that no cycle runs with neither active
  and the forward controller ends inactive (still loaded);
* ``recover(cm, component, controllers)``: after ``component`` failed in ``read`` (unconfigured, the controllers using
  it inactive), make it active again and reactivate exactly the given controllers, in one switch; other components and
  controllers are left as they were (tried on one RRBot, with the controllers in any order and a subset of them, and on
  the second of two RRBots);
* ``remove_controller(cm, name)``: unload a controller from whatever state it is in (active, inactive, unconfigured),
  leaving the others as they were;
* ``PREDICTIONS``: for each request of :data:`REQUESTS`, whether it is accepted and every state right after (a
  controller's state may be ``"unloaded"``); one check per prediction, run against the running system; a failed check
  says which parts are wrong, never the answer.

One slip costs the rule it breaks: the checks of one function judge separate rules (the end states, one strict switch,
no cycle without a controller; the hardware, the controllers, the arguments), and a check that builds on another
(``after=``) says so when that one fails. No hint states an outcome the learner has not predicted: a prediction not
made yet fails without a hint; the checks of 6.3, whose hints would tell what unload and cleanup do, show theirs only
once those requests are predicted; the hints of a wrong prediction ask and point at the rule, never at the result.
:func:`show_predictions` (notebook 06's prediction cell) seals the predictions before it shows any outcome
(:mod:`rrbot_workshop.course.grading.sealed`): a prediction changed after that earns nothing, and the reason says so.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop.controller_manager.switch import normalize_strictness
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded, sealed
from rrbot_workshop.course.grading.rubric import fail_without_hint
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.middleware.lifecycle import ReturnType
from rrbot_workshop.msgs import Float64MultiArray

TASK = 6
FILE = "lifecycle.py"
JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"
#: What a prediction may say of a controller (``"unloaded"``: no longer loaded) or of the hardware component.
STATES = ("unconfigured", "inactive", "active", "finalized", "unloaded")
#: The controllers every prediction gives a state for.
CONTROLLERS = (JSB, FWD, JTC)

#: name -> the request, made on a fresh system with JSB and forward active and the JTC inactive
REQUESTS: dict[str, Callable[[Any], Any]] = {
    "activate_next_to_forward": lambda cm: cm.switch_controllers(activate=[JTC], strictness="strict"),
    "activate_next_to_forward_best_effort": lambda cm: cm.switch_controllers(activate=[JTC], strictness="best_effort"),
    "configure_an_active_controller": lambda cm: cm.configure_controller(FWD),
    "unload_an_active_controller": lambda cm: cm.unload_controller(FWD),
    "deactivate_the_hardware": lambda cm: cm.set_hardware_component_state("rrbot", "inactive"),
    "switch_on_unconfigured_hardware": lambda cm: (cm.set_hardware_component_state("rrbot", "unconfigured"),
                                                   cm.switch_controllers([JTC], [FWD], "strict")),
    "cleanup_an_inactive_controller": lambda cm: cm.cleanup_controller(JTC),
}

#: name -> the three hint levels of its check, shown only for a prediction that is made and wrong: the question, where
#: the rule is (without applying it here), how to reason it through. None states what the request does.
PREDICTION_HINTS: dict[str, tuple[str, str, str]] = {
    "activate_next_to_forward": (
        "Which command interfaces does each robot controller claim, and can two active controllers hold the same one?",
        "Look at how a switch checks the command interfaces of a controller to activate against those the active "
        "controllers hold, and at what a strict switch does when one of its requests cannot be done.",
        "List the interfaces the trajectory controller needs and who holds them during the request; then apply "
        "strict: all of the switch, or none of it.",
    ),
    "activate_next_to_forward_best_effort": (
        "best_effort drops the parts of a switch that cannot be done: which of the switch's checks does that apply to?",
        "Look at the order of Jazzy's switch checks: the name and state checks, for which best_effort may drop a "
        "request, and the check of the command interfaces claimed.",
        "Decide which of those checks this request meets, and whether best_effort can drop a part of it or not.",
    ),
    "configure_an_active_controller": (
        "configure is a transition of the lifecycle: from which states does the controller manager allow it?",
        "Look at Jazzy's configure_controller: what it does for an unconfigured, an inactive, an active and a "
        "finalized controller.",
        "Find the forward controller's state before the request, then what configure_controller does in that state; a "
        "request that is refused changes nothing.",
    ),
    "unload_an_active_controller": (
        "Can a controller that is running in the control loop be taken out of the manager?",
        "Look at the states in which Jazzy's unload_controller accepts a controller, and what it does on the way out "
        "in each.",
        "Find the forward controller's state before the request, then what unload_controller does with a controller "
        "in that state.",
    ),
    "deactivate_the_hardware": (
        "Does set_hardware_component_state change the controllers, or only the component?",
        "Look at what Jazzy's set_hardware_component_state drives, and whether the controller manager changes the "
        "controllers that use the component when it is set inactive by hand.",
        "The component: is the transition allowed from its state? Each controller: does anything ask it to change?",
    ),
    "switch_on_unconfigured_hardware": (
        "Two requests: the first takes the component to unconfigured; can a controller then claim its interfaces?",
        "Look at whether an unconfigured component's interfaces are available, and what a strict switch does with a "
        "request that needs interfaces that are not.",
        "Take the requests one at a time: is the first accepted, and where does it leave the component? Then which "
        "controllers would the switch change, and does STRICT allow a part of it?",
    ),
    "cleanup_an_inactive_controller": (
        "cleanup is a transition of the lifecycle: from which state, to which?",
        "Look at Jazzy's cleanup_controller: in which state it accepts a controller, and where it takes it.",
        "Find the trajectory controller's state before the request, then where cleanup takes a controller from there.",
    ),
}

#: name -> why the request does what it does (shown by :func:`show_predictions`, only once every prediction is made).
EXPLANATIONS: dict[str, str] = {
    "activate_next_to_forward": "the forward controller holds joint1/position and joint2/position; a strict switch "
    "that does not deactivate it in the same request is rejected as a whole.",
    "activate_next_to_forward_best_effort": "in Jazzy an interface conflict rejects the switch whatever the "
    "strictness; best_effort drops only requests that fail the name and state checks (unknown, wrong state).",
    "configure_an_active_controller": "configure refuses an active controller (an inactive one would be cleaned up "
    "and configured again).",
    "unload_an_active_controller": "unload refuses an active controller: deactivate it first.",
    "deactivate_the_hardware": "set_hardware_component_state drives the component only: the controllers stay active "
    "(an inactive component is read, not written).",
    "switch_on_unconfigured_hardware": "the hardware request succeeds, but an unconfigured component's interfaces are "
    "unavailable, so the strict switch is rejected and nothing changes; the controllers keep their states.",
    "cleanup_an_inactive_controller": "cleanup takes an inactive controller back to unconfigured.",
}


@pytest.fixture(scope="module")
def loaded(task_file: Callable[[int, str], Path]) -> ModuleType | None:
    task_file(TASK, FILE)
    return rw.course.load_module(TASK, FILE, quiet=True)


@contextmanager
def _hints_wait_for(learner: ModuleType, names: tuple[str, ...]) -> Iterator[None]:
    """A failure in the block shows no hint while the predictions ``names`` are not made: the hints would answer them."""
    try:
        yield
    except (Exception, pytest.fail.Exception) as exc:  # pytest.fail's exception is no Exception
        predictions = getattr(learner, "PREDICTIONS", None)
        unmade = [n for n in names if missing_parts(predictions.get(n) if isinstance(predictions, dict) else None)]
        if not unmade:
            raise
        text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip() and not line.startswith(
            "assert ")) or type(exc).__name__
        fail_without_hint(text, note=f"its hints come once you have predicted {', '.join(unmade)} in 6.4: they would "
                          "tell what those requests do")


@pytest.fixture(scope="module")
def learner(loaded: ModuleType | None) -> Iterator[ModuleType]:
    if loaded is None:
        pytest.fail(f"your {FILE} does not import", pytrace=False)
    yield loaded


@graded(points=1, given=True, hint=(
    "Task 6: lifecycle.py must import on its own: the self-check calls its functions and reads PREDICTIONS.",
    "Open lifecycle.py in notebook 06 (its first cell loads it): the first error it shows is the one to fix.",
    "A half-written function can raise NotImplementedError when called; the file itself must still import.",
))
def test_lifecycle_file_loads(loaded: ModuleType | None) -> None:
    """lifecycle.py imports."""
    assert loaded is not None, f"your {FILE} does not import: open it in notebook 06 to see the error"


def _in(learner: ModuleType, name: str) -> str:
    """``"your lifecycle.py, line N, name()"``: where the learner's function starts."""
    fn = getattr(learner, name, None)
    code = getattr(fn, "__code__", None)
    return f"your {FILE}, line {code.co_firstlineno}, {name}()" if code is not None else f"your {FILE}, {name}()"


def _system(inactive: tuple[str, ...] = (), spawn: tuple[str, ...] = (JSB, FWD)) -> rw.System:
    return rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=list(spawn), inactive=list(inactive),
                      name="task06_grader")


def _states(system: rw.System) -> tuple[dict[str, str], dict[str, str]]:
    cm = system.controller_manager
    return ({c.name: c.state for c in cm.list_controllers()},
            {h.name: h.state.label for h in cm.list_hardware_components()})


def _call(learner: ModuleType, name: str, *args: Any) -> None:
    fn = getattr(learner, name, None)
    if not callable(fn):
        pytest.fail(f"your {FILE} has no function {name}()", pytrace=False)
    try:
        fn(*args)
    except NotImplementedError as exc:
        pytest.fail(f"{name}() in your {FILE} is not written yet ({exc})", pytrace=False)


def _shown(args: tuple[Any, ...]) -> str:
    return ", ".join(repr(a) for a in args)


def _fail_read_once(system: rw.System, component: str) -> None:
    hardware = system.resource_manager.get_component(component).impl
    original = hardware.read
    failed = [False]

    def read_once_error(time: float, period: float) -> ReturnType:
        if not failed[0]:
            failed[0] = True
            return ReturnType.ERROR
        return original(time, period)

    hardware.read = read_once_error


# --------------------------------------------------------------------------------------------- 6.1


def _switch_run(learner: ModuleType) -> tuple[dict[str, str], list[dict[str, Any]], list[int]]:
    """Run switch_to_trajectory_controller on a fresh RRBot: (states after, the switches made, active count per cycle)."""
    with _system() as system:
        cm = system.controller_manager
        commanded: list[int] = []
        cm.add_cycle_hook(lambda t, p: commanded.append(
            sum(c.state == "active" for c in cm.list_controllers() if c.name in (FWD, JTC))))
        system.spin(0.05)
        switches = _spy_switches(cm)
        _call(learner, "switch_to_trajectory_controller", cm)
        system.spin(0.05)
        return _states(system)[0], switches, commanded


@pytest.fixture(scope="module")
def switch_run(learner: ModuleType) -> Callable[[], tuple[dict[str, str], list[dict[str, Any]], list[int]]]:
    """The learner's 6.1 run once for the three checks of 6.1; each gets its outcome, or the learner's exception."""
    try:
        outcome: Any = _switch_run(learner)
    except BaseException as exc:  # noqa: BLE001 - given to each check, which fails with it
        outcome = exc

    def run() -> tuple[dict[str, str], list[dict[str, Any]], list[int]]:
        if isinstance(outcome, BaseException):
            raise outcome
        return outcome

    return run


def _spy_switches(cm: Any) -> list[dict[str, Any]]:
    """Record every switch the learner asks of ``cm``: activate, deactivate and strictness, however they are passed."""
    switches: list[dict[str, Any]] = []
    original = cm.switch_controllers
    signature = inspect.signature(original)

    def recorded(*args: Any, **kwargs: Any) -> Any:
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        switches.append({"activate": list(bound.arguments["activate"] or ()),
                         "deactivate": list(bound.arguments["deactivate"] or ()),
                         "strictness": _effective(cm, bound.arguments["strictness"])})
        return original(*bound.args, **bound.kwargs)

    cm.switch_controllers = recorded
    return switches


def _effective(cm: Any, strictness: Any) -> str:
    """The strictness a switch runs with: the manager's default for None or 0, else the name of the value given."""
    if strictness is None or strictness == 0:
        return str(cm.default_strictness)
    try:
        return normalize_strictness(strictness)
    except RRBotWorkshopError:
        return repr(strictness)


def _strict(strictness: str) -> bool:
    return strictness == "strict"


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.1: afterwards the trajectory controller is active, the forward controller inactive (still loaded, not "
    "unloaded) and the broadcaster still active.",
    "cm.load_controller(name), then cm.configure_controller(name) (or cm.set_controller_state(name, 'inactive')), then "
    "a switch that activates the trajectory controller and deactivates the forward controller.",
    "cm.load_controller('joint_trajectory_controller'); cm.configure_controller('joint_trajectory_controller'); "
    "cm.switch_controllers(activate=['joint_trajectory_controller'], deactivate=['forward_position_controller'], "
    "strictness='strict')",
))
def test_switch_end_states(learner: ModuleType, switch_run: Callable[[], Any]) -> None:
    controllers, _, _ = switch_run()
    wanted = {JSB: "active", FWD: "inactive", JTC: "active"}
    shown = {n: controllers.get(n, "unloaded") for n in CONTROLLERS}
    assert shown == wanted, (f"{_in(learner, 'switch_to_trajectory_controller')} leaves the controllers "
                             f"{_differences(wanted, shown, 'should be')}")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.1: ONE switch deactivates the forward controller and activates the trajectory controller, and it is "
    "strict: all or nothing.",
    "cm.switch_controllers(activate=[...], deactivate=[...], strictness='strict'); the default strictness is "
    "best_effort (Jazzy's defaults.switch_controller.strictness).",
    "cm.switch_controllers(activate=['joint_trajectory_controller'], deactivate=['forward_position_controller'], "
    "strictness='strict')",
))
def test_one_strict_switch(learner: ModuleType, switch_run: Callable[[], Any]) -> None:
    _, switches, _ = switch_run()
    where = _in(learner, "switch_to_trajectory_controller")
    both = [s for s in switches if JTC in s["activate"] and FWD in s["deactivate"]]
    assert both, (f"{where} made the switches {[(s['activate'], s['deactivate']) for s in switches]} (activate, "
                  "deactivate): deactivate the forward controller and activate the trajectory controller in the same "
                  "switch")
    assert all(_strict(s["strictness"]) for s in both), (
        f"{where}: the switch that exchanges the controllers has strictness {both[0]['strictness']!r}; the task asks "
        "for a strict switch (all or nothing)")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.1: no control cycle may run with neither robot controller active: the arm would be left without a "
    "command.",
    "Do not deactivate the forward controller in one request and activate the trajectory controller in a later one; "
    "and do not run cycles (cm.update) inside your function.",
    "cm.switch_controllers(activate=['joint_trajectory_controller'], deactivate=['forward_position_controller'], "
    "strictness='strict')",
))
def test_no_cycle_without_a_robot_controller(learner: ModuleType, switch_run: Callable[[], Any]) -> None:
    _, _, commanded = switch_run()
    where = _in(learner, "switch_to_trajectory_controller")
    assert 0 not in commanded, f"during {where} a control cycle ran with neither robot controller active"
    assert 2 not in commanded, f"during {where} a control cycle ran with both robot controllers active"


# --------------------------------------------------------------------------------------------- 6.2


def _recover_single(learner: ModuleType, controllers: list[str], spawn: tuple[str, ...]) -> None:
    """recover() after rrbot failed in read: exactly ``controllers`` active again, in one switch, and the robot moves."""
    with _system(spawn=spawn) as system:
        cm = system.controller_manager
        _fail_read_once(system, "rrbot")
        system.spin(0.05)
        before = _states(system)
        assert before[1] == {"rrbot": "unconfigured"}, f"the grader's read error did not take effect: {before}"
        call = f"{_in(learner, 'recover')} called as recover(cm, 'rrbot', {controllers})"
        switches = _spy_switches(cm)
        _call(learner, "recover", cm, "rrbot", list(controllers))
        after = _states(system)
        if after[1] != {"rrbot": "active"}:
            return  # the hardware's own rule (test_recover_the_hardware): no controller can be active without it
        wanted = {n: ("active" if n in controllers else s) for n, s in before[0].items()}
        assert after[0] == wanted, f"{call} leaves the controllers {_differences(wanted, after[0], 'should be')}"
        together = [s for s in switches if set(controllers) <= set(s["activate"])]
        assert together, (f"{call} made the switches {[s['activate'] for s in switches]}; the task asks to activate "
                          f"{controllers} in one switch")
        if FWD in controllers:
            system.publish(f"/{FWD}/commands", Float64MultiArray(data=[0.4, -0.2]))
            system.spin(0.05)
            position = list(system.latest("/joint_states").position)
            assert all(abs(q - g) < 1e-6 for q, g in zip(position, [0.4, -0.2], strict=False)), (
                f"after {call} a command [0.4, -0.2] left the joints at {position}: the robot does not move again")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.2: after a read error the component is unconfigured (Jazzy's on_error succeeded) and the controllers "
    "using it inactive; first the component goes back to active.",
    "cm.set_hardware_component_state(component, 'active') goes through configure and activate.",
    "cm.set_hardware_component_state(component, 'active')",
))
def test_recover_the_hardware(learner: ModuleType) -> None:
    with _system() as system:
        cm = system.controller_manager
        _fail_read_once(system, "rrbot")
        system.spin(0.05)
        _call(learner, "recover", cm, "rrbot", [JSB, FWD])
        hardware = _states(system)[1]
        assert hardware == {"rrbot": "active"}, (f"{_in(learner, 'recover')} called as recover(cm, 'rrbot', [...]) "
                                                 f"leaves the hardware {hardware['rrbot']}, not active")


@graded(points=1, after=("recover_the_hardware",), hint=(
    "Task 6.2: once the component is active, exactly the controllers you are given are activated again, in one switch "
    "(a controller not in the list stays inactive), whatever order they come in; the robot then moves again.",
    "cm.switch_controllers(activate=controllers, strictness='strict'), once the component is active again.",
    "cm.set_hardware_component_state(component, 'active'); cm.switch_controllers(activate=controllers, "
    "strictness='strict')",
))
def test_recover_the_controllers(learner: ModuleType) -> None:
    _recover_single(learner, [JSB, FWD], (JSB, FWD))
    _recover_single(learner, [FWD, JSB], (JSB, FWD))
    _recover_single(learner, [JSB], (JSB, FWD))
    _recover_single(learner, [JSB, JTC], (JSB, JTC))


@graded(points=1, after=("recover_the_hardware",), hint=(
    "Task 6.2: use the arguments: the component and the controllers are whatever the caller names (here the second of "
    "two RRBots, r2_rrbot); the other robot keeps running untouched.",
    "No fixed 'rrbot' or controller names in recover(): component and controllers come in as arguments.",
    "cm.set_hardware_component_state(component, 'active'); cm.switch_controllers(activate=controllers, "
    "strictness='strict')",
))
def test_recover_another_robot(learner: ModuleType) -> None:
    """The component named is the one recovered, and nothing outside the arguments changes (whether every controller
    given is active again is test_recover_the_controllers' rule)."""
    r1, r2 = "r1_forward_position_controller", "r2_forward_position_controller"
    with rw.bringup("multi_rrbot", "multi_rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                    spawn=[JSB, r1, r2], name="task06_grader_two") as system:
        cm = system.controller_manager
        _fail_read_once(system, "r2_rrbot")
        system.spin(0.05)
        before = _states(system)
        assert before[1]["r1_rrbot"] == "active", "the grader's read error touched r1_rrbot"
        call = f"{_in(learner, 'recover')} called as recover(cm, 'r2_rrbot', [{JSB!r}, {r2!r}])"
        _call(learner, "recover", cm, "r2_rrbot", [JSB, r2])
        controllers, hardware = _states(system)
        assert hardware == {"r1_rrbot": "active", "r2_rrbot": "active"}, (
            f"two RRBots, r2_rrbot failed in read: {call} leaves the hardware "
            f"{_differences({'r1_rrbot': 'active', 'r2_rrbot': 'active'}, hardware, 'should be')}")
        others = {n: s for n, s in before[0].items() if n not in (JSB, r2)}
        changed = {n: controllers.get(n, "unloaded") for n in others}
        assert changed == others, f"{call} changed controllers it was not given: {_differences(others, changed)}"


# --------------------------------------------------------------------------------------------- 6.3


def _setup_controllers(cm: Any, states: dict[str, str]) -> None:
    """Bring FWD and JTC (loaded by the caller where wanted) to the given states; both cannot be active."""
    for name, state in states.items():
        if state == "unloaded":
            continue
        cm.load_controller(name)
        if state in ("inactive", "active"):
            cm.configure_controller(name)
        if state == "active":
            cm.switch_controllers(activate=[name], strictness="strict")


def _differences(before: dict[str, str], after: dict[str, str], word: str = "was") -> str:
    """What differs from ``before`` in ``after``, controller by controller ("x inactive (was active)")."""
    changed = [f"{n} {after.get(n, 'unloaded')} ({word} {s})" for n, s in before.items()
               if after.get(n, "unloaded") != s]
    changed += [f"{n} {s} ({word} not loaded)" for n, s in after.items() if n not in before]
    return ", ".join(changed) or "nothing changed"


def _remove_case(learner: ModuleType, name: str, states: dict[str, str]) -> str:
    """'' if remove_controller(name) did right from these states, else what went wrong (in the learner's terms).

    An exception of the learner's code goes through to the check, which shows it first.
    """
    with rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB], name="task06_grader") as system:
        cm = system.controller_manager
        _setup_controllers(cm, states)
        before, _ = _states(system)
        _call(learner, "remove_controller", cm, name)
        after, _ = _states(system)
        call = f"{_in(learner, 'remove_controller')} called as remove_controller(cm, {name!r}) with {name} {before[name]}"
        if name in after:
            return f"{call} left it loaded ({after[name]})"
        others = {n: s for n, s in before.items() if n != name}
        if {n: s for n, s in after.items()} != others:
            return f"{call} changed the others: {_differences(others, after)}; they must stay as they were"
        topics = [t for t, _ in system.bus.topic_names_and_types() if t.startswith(f"/{name}/")]
        if topics:
            return f"{call} left its topics {topics}"
        return ""


def _remove_from(learner: ModuleType, state: str) -> None:
    cases = {"active": [(FWD, {FWD: "active", JTC: "inactive"}), (JTC, {JTC: "active", FWD: "unconfigured"}),
                        (JSB, {FWD: "active"})],
             "inactive": [(JTC, {FWD: "active", JTC: "inactive"}), (FWD, {FWD: "inactive"})],
             "unconfigured": [(JTC, {FWD: "active", JTC: "unconfigured"}), (FWD, {FWD: "unconfigured", JTC: "active"})]}
    for name, states in cases[state]:
        problem = _remove_case(learner, name, states)
        if problem:
            pytest.fail(problem, pytrace=False)


#: The predictions whose outcomes the hints of 6.3 would tell: those hints wait until they are made.
REMOVE_PREDICTIONS = ("unload_an_active_controller", "cleanup_an_inactive_controller")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.3: remove_controller() must take an active controller out of the manager too, and leave the other "
    "controllers as they were.",
    "Look the controller's state up in cm.list_controllers(); an active controller is first deactivated, in a switch: "
    "cm.switch_controllers(deactivate=[name], strictness='strict'); then cm.unload_controller(name).",
    "if state == 'active': cm.switch_controllers(deactivate=[name], strictness='strict')",
))
def test_remove_an_active_controller(learner: ModuleType) -> None:
    with _hints_wait_for(learner, REMOVE_PREDICTIONS):
        _remove_from(learner, "active")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.3: remove_controller() must take an inactive controller (configured, not running) out of the manager, "
    "and leave the other controllers as they were.",
    "An inactive controller can be unloaded as it is (Jazzy cleans it up on the way); cm.unload_controller(name), "
    "optionally after cm.cleanup_controller(name).",
    "if state == 'inactive': cm.cleanup_controller(name)  # optional; then cm.unload_controller(name)",
))
def test_remove_an_inactive_controller(learner: ModuleType) -> None:
    with _hints_wait_for(learner, REMOVE_PREDICTIONS):
        _remove_from(learner, "inactive")


@graded(points=1, after=("lifecycle_file_loads",), hint=(
    "Task 6.3: remove_controller() must take an unconfigured controller (loaded, not configured) out of the "
    "manager, and leave the other controllers as they were.",
    "An unconfigured controller is unloaded as it is: cleanup refuses a controller that is not inactive. Only call "
    "cm.cleanup_controller(name) when it is inactive; then cm.unload_controller(name).",
    "if state in ('active', 'inactive'): cm.cleanup_controller(name)\ncm.unload_controller(name)",
))
def test_remove_an_unconfigured_controller(learner: ModuleType) -> None:
    with _hints_wait_for(learner, REMOVE_PREDICTIONS):
        _remove_from(learner, "unconfigured")


@graded(points=1, after=("remove_an_active_controller", "remove_an_inactive_controller",
                         "remove_an_unconfigured_controller"), hint=(
    "Task 6.3: remove_controller() must work whichever controller it is given and whatever state it and the others "
    "are in.",
    "Read the state of the named controller (not of a fixed one) from cm.list_controllers() and walk it down: "
    "deactivate if active, then unload.",
    "state = next(c.state for c in cm.list_controllers() if c.name == name)",
))
def test_remove_controller_generated(learner: ModuleType) -> None:
    with _hints_wait_for(learner, REMOVE_PREDICTIONS):
        _remove_generated(learner)


def _remove_generated(learner: ModuleType) -> None:
    problems: list[str] = []
    pairs = [(f, j) for f in ("unloaded", "unconfigured", "inactive", "active")
             for j in ("unloaded", "unconfigured", "inactive", "active") if not (f == j == "active")]

    @settings(derandomize=True, database=None, deadline=None, max_examples=12,
              suppress_health_check=list(HealthCheck))
    @given(pair=st.sampled_from(pairs), which=st.sampled_from([JSB, FWD, JTC]))
    def scenario(pair: tuple[str, str], which: str) -> None:
        states = {FWD: pair[0], JTC: pair[1]}
        if which != JSB and states[which] == "unloaded":
            states[which] = "inactive"
        try:
            problem = _remove_case(learner, which, states)
        except pytest.fail.Exception as exc:
            problem = str(exc)
        except Exception as exc:  # noqa: BLE001 - reported below with the smallest case that raises it
            before = ", ".join(f"{n} {s}" for n, s in {JSB: "active", **states}.items() if s != "unloaded")
            message = " ".join(line.strip() for line in str(exc).splitlines())
            problem = (f"remove_controller(cm, {which!r}) with {before} raised {type(exc).__name__}"
                       + (f": {message}" if message else " (with no message)"))
        if problem:
            problems[:] = [problem]
        assert not problem

    first = _remove_case(learner, FWD, {FWD: "active", JTC: "unloaded"})
    if first:
        pytest.fail(first, pytrace=False)
    try:
        scenario()
    except AssertionError:
        pytest.fail(f"the smallest case that tells your remove_controller() from the task: {problems[0]}", pytrace=False)


# --------------------------------------------------------------------------------------------- 6.4


def run_request(name: str) -> dict[str, Any]:
    """What request ``name`` really does on a fresh RRBot: accepted, and every state right after."""
    with _system(inactive=(JTC,)) as system:
        try:
            REQUESTS[name](system.controller_manager)
            accepted = True
        except RRBotWorkshopError:
            accepted = False
        controllers, hardware = _states(system)
    return {"accepted": accepted, "controllers": {n: controllers.get(n, "unloaded") for n in CONTROLLERS},
            "hardware": hardware}


def _label(value: Any) -> Any:
    return value.strip().lower() if isinstance(value, str) else value


def missing_parts(predicted: Any) -> list[str]:
    """The parts of a prediction still to be made (``None`` or absent)."""
    if not isinstance(predicted, dict):
        return ["the whole prediction (a dict with 'accepted', 'controllers' and 'hardware')"]
    missing = [] if isinstance(predicted.get("accepted"), bool) else ["accepted (True or False)"]
    for part, names in (("controllers", CONTROLLERS), ("hardware", ("rrbot",))):
        given_part = predicted.get(part) if isinstance(predicted.get(part), dict) else {}
        missing += [f"the state of {n}" + (" (a controller no longer loaded is 'unloaded')" if part == "controllers"
                                           and n not in given_part else "")
                    for n in names if given_part.get(n) is None]
    return missing


def unknown_states(predicted: dict[str, Any]) -> list[str]:
    """The states of a complete prediction that are not states at all (``'running'``)."""
    return [f"{n} {v!r}" for part in ("controllers", "hardware") for n, v in predicted[part].items()
            if _label(v) not in STATES]


def wrong_parts(predicted: Any, actual: dict[str, Any]) -> list[str]:
    """The parts of a prediction that differ from what happened, named without giving the right value."""
    if not isinstance(predicted, dict):
        return ["no prediction (a dict with 'accepted', 'controllers' and 'hardware')"]
    wrong = []
    if predicted.get("accepted") is not actual["accepted"]:
        wrong.append("whether it is accepted")
    for part in ("controllers", "hardware"):
        given_part = predicted.get(part) if isinstance(predicted.get(part), dict) else {}
        for name in actual[part]:
            value = given_part.get(name)
            if _label(value) != actual[part][name]:
                wrong.append(f"the state of {name}" + (f" ({value!r} is not a state)" if value is not None
                                                       and _label(value) not in STATES else ""))
    return wrong


def _prediction_line(name: str) -> str:
    """``"your lifecycle.py, line N"``: where PREDICTIONS['name'] starts in the learner's file, if found."""
    try:
        lines = (tracks.task_dir(TASK) / FILE).read_text().splitlines()
    except OSError:
        return f"your {FILE}"
    for number, line in enumerate(lines, start=1):
        if f'"{name}"' in line or f"'{name}'" in line:
            return f"your {FILE}, line {number}"
    return f"your {FILE}"


def _prediction_check(learner: ModuleType, name: str) -> None:
    predictions = getattr(learner, "PREDICTIONS", None)
    if not isinstance(predictions, dict):
        fail_without_hint(f"your {FILE} has no PREDICTIONS dict")
    predicted = predictions.get(name)
    where = _prediction_line(name)
    changed = sealed.changed_since_sealed(TASK, name, predicted, notebook="notebook 06")
    if changed:
        fail_without_hint(f"{where}: {changed}")
    missing = missing_parts(predicted)
    if missing:  # any hint would state the outcome of a request the learner has not predicted
        fail_without_hint(f"{where}: PREDICTIONS['{name}'] is not made yet: {', '.join(missing)}")
    unknown = unknown_states(predicted)
    if unknown:
        fail_without_hint(f"{where}: PREDICTIONS['{name}'] gives {', '.join(unknown)}, which "
                          f"{'is' if len(unknown) == 1 else 'are'} not a state; a state is one of {', '.join(STATES)}")
    wrong = wrong_parts(predicted, run_request(name))
    assert not wrong, f"{where}: PREDICTIONS['{name}'] is wrong in: {', '.join(wrong)}"


def _prediction_test(name: str, points: float = 1) -> Callable[[ModuleType], None]:
    def test(learner: ModuleType) -> None:
        _prediction_check(learner, name)

    test.__name__ = f"test_prediction_{name}"
    test.__doc__ = f"PREDICTIONS['{name}']: accepted, and every state right after."
    return graded(points=points, hint=PREDICTION_HINTS[name], after=("lifecycle_file_loads",))(test)


test_prediction_activate_next_to_forward = _prediction_test("activate_next_to_forward")
test_prediction_activate_next_to_forward_best_effort = _prediction_test("activate_next_to_forward_best_effort")
test_prediction_configure_an_active_controller = _prediction_test("configure_an_active_controller")
test_prediction_unload_an_active_controller = _prediction_test("unload_an_active_controller")
test_prediction_deactivate_the_hardware = _prediction_test("deactivate_the_hardware")
test_prediction_switch_on_unconfigured_hardware = _prediction_test("switch_on_unconfigured_hardware")
test_prediction_cleanup_an_inactive_controller = _prediction_test("cleanup_an_inactive_controller")


# --------------------------------------------------------------------------------------------- notebook 06


def _file_predictions() -> Any:
    """PREDICTIONS of the learner's lifecycle.py on the current track, read afresh (None if it does not load)."""
    module = rw.course.load_module(TASK, FILE, quiet=True)
    return getattr(module, "PREDICTIONS", None) if module is not None else None


def _still_to_predict(predictions: Any) -> dict[str, list[str]]:
    table = predictions if isinstance(predictions, dict) else {}
    todo = {name: missing_parts(table.get(name)) for name in REQUESTS}
    return {name: parts for name, parts in todo.items() if parts}


def outcomes_may_show() -> bool:
    """For a notebook 06 cell that shows what some of the predicted requests do: True once every prediction in the
    learner's file is made (they are sealed then, as :func:`show_predictions` seals them); else say so, and False."""
    predictions = _file_predictions()
    todo = _still_to_predict(predictions)
    if todo:
        print(f"This cell shows what some of the requests of 6.4 do: it runs once you have predicted them all "
              f"({len(REQUESTS) - len(todo)} of {len(REQUESTS)} made).")
        return False
    sealed.seal(TASK, predictions, REQUESTS)
    return True


def show_predictions(predictions: Any = None) -> None:
    """Notebook 06's prediction cell: grade the predictions; only once every one is made, show the outcomes and why.

    Until then it names the predictions still to make and shows no outcome, so nothing can be copied before predicting.
    The predictions of the learner's file are sealed before any outcome is shown: the self-check grades them as they
    are then.

    Args:
        predictions: The predictions to grade (default: ``PREDICTIONS`` read afresh from the learner's file).
    """
    in_file = _file_predictions()
    predictions = in_file if predictions is None else predictions
    predictions = predictions if isinstance(predictions, dict) else {}
    todo = _still_to_predict(predictions)
    if todo:
        print(f"Predict every request first ({len(REQUESTS) - len(todo)} of {len(REQUESTS)} made); still to make:")
        for name, parts in todo.items():
            print(f"  {name:<38} {', '.join(parts)}")
        print("The outcomes and their explanations appear here once every prediction is made.")
        return
    if sealed.seal(TASK, in_file if isinstance(in_file, dict) else None, REQUESTS):
        print("Your predictions are sealed as they are now: the self-check grades these, and a prediction changed "
              "after the outcomes below earns nothing.\n")
    right = 0
    for name in REQUESTS:
        actual = run_request(name)
        wrong = wrong_parts(predictions[name], actual)
        right += not wrong
        print(f"{name:<38} " + ("right" if not wrong else "wrong in: " + ", ".join(wrong)))
        print(f"    it was {'accepted' if actual['accepted'] else 'refused'}; controllers {actual['controllers']}, "
              f"hardware {actual['hardware']}")
        print(f"    why: {EXPLANATIONS[name]}")
    print(f"{right} of {len(REQUESTS)} predictions right.")
