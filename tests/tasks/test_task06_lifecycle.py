"""Grader of task 6: the lifecycle of controllers and hardware, driven through the controller manager.

The specification (``lifecycle.py`` of the task folder), each function run on a fresh mock RRBot:

* ``switch_to_trajectory_controller(cm)``: with the broadcaster and the forward position controller active and the
  trajectory controller not loaded, load and configure the trajectory controller and switch to it in one switch, so
  that no cycle runs with neither controller active;
* ``recover(cm, component, controllers)``: after the component failed in ``read`` (unconfigured, its controllers
  inactive), make it active again and reactivate the given controllers;
* ``remove_controller(cm, name)``: unload a controller from whatever state it is in (active, inactive, unconfigured);
* ``PREDICTIONS``: for each request of :data:`REQUESTS`, whether it is accepted and every state right after; checked
  against the running system without the right answer being shown.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.middleware.lifecycle import ReturnType
from rrbot_workshop.msgs import Float64MultiArray

TASK = 6
FILE = "lifecycle.py"
JSB, FWD, JTC = "joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"

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


@pytest.fixture(scope="module")
def learner(task_file: Callable[[int, str], Path]) -> Iterator[ModuleType]:
    task_file(TASK, FILE)
    module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        pytest.fail(f"{FILE} does not import", pytrace=False)
    yield module


def _system(inactive: tuple[str, ...] = ()) -> rw.System:
    return rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FWD], inactive=list(inactive), name="task06_grader")


def _states(system: rw.System) -> tuple[dict[str, str], dict[str, str]]:
    cm = system.controller_manager
    return ({c.name: c.state for c in cm.list_controllers()},
            {h.name: h.state.label for h in cm.list_hardware_components()})


def _call(learner: ModuleType, name: str, *args: Any) -> None:
    fn = getattr(learner, name, None)
    if not callable(fn):
        pytest.fail(f"{FILE} has no function {name}()", pytrace=False)
    try:
        fn(*args)
    except NotImplementedError as exc:
        pytest.fail(f"{name}() is not written yet ({exc})", pytrace=False)
    except RRBotWorkshopError as exc:
        pytest.fail(f"{name}() made a request the controller manager refused: {str(exc).splitlines()[0]}",
                    pytrace=False)


# --------------------------------------------------------------------------------------------- 6.1


@graded(points=3, hint=(
    "Task 6.1: load, configure, then ONE switch that deactivates the forward controller and activates the trajectory "
    "controller: no cycle may run with neither, and the forward controller must end inactive (not unloaded).",
    "cm.load_controller(name), cm.set_controller_state(name, 'inactive') (or configure_controller), then "
    "cm.switch_controllers(activate=[...], deactivate=[...], strictness='strict').",
    "cm.switch_controllers(activate=['joint_trajectory_controller'], deactivate=['forward_position_controller'], "
    "strictness='strict')",
))
def test_switch_to_trajectory_controller(learner: ModuleType) -> None:
    with _system() as system:
        cm = system.controller_manager
        commanded: list[int] = []
        system.controller_manager.add_cycle_hook(lambda t, p: commanded.append(
            sum(c.state == "active" for c in cm.list_controllers() if c.name in (FWD, JTC))))
        system.spin(0.05)
        switches: list[tuple[list[str], list[str]]] = []
        original = cm.switch_controllers

        def recorded(activate: Any = (), deactivate: Any = (), *args: Any, **kwargs: Any) -> Any:
            switches.append((list(activate), list(deactivate)))
            return original(activate, deactivate, *args, **kwargs)

        cm.switch_controllers = recorded  # type: ignore[method-assign]
        _call(learner, "switch_to_trajectory_controller", cm)
        system.spin(0.05)
        controllers, _ = _states(system)
        assert controllers == {JSB: "active", FWD: "inactive", JTC: "active"}, f"states after: {controllers}"
        assert switches and any(JTC in a and FWD in d for a, d in switches), (
            f"the switches made were {switches}: deactivate the forward controller and activate the trajectory "
            "controller in the same switch"
        )
        assert 0 not in commanded, "a control cycle ran with neither robot controller active"


# --------------------------------------------------------------------------------------------- 6.2


@graded(points=3, hint=(
    "Task 6.2: after a read error the component is unconfigured (Jazzy's on_error) and its controllers inactive; "
    "bring the component back to active first, then the controllers.",
    "cm.set_hardware_component_state(component, 'active') goes through configure and activate; then one switch "
    "activates the controllers.",
    "cm.set_hardware_component_state(component, 'active'); cm.switch_controllers(activate=controllers, strictness='strict')",
))
def test_recover_after_a_read_error(learner: ModuleType) -> None:
    with _system() as system:
        cm = system.controller_manager
        hardware = system.resource_manager.get_component("rrbot").impl
        original = hardware.read
        failed = [False]

        def read_once_error(time: float, period: float) -> ReturnType:
            if not failed[0]:
                failed[0] = True
                return ReturnType.ERROR
            return original(time, period)

        hardware.read = read_once_error
        system.spin(0.05)
        assert _states(system) == ({JSB: "inactive", FWD: "inactive"}, {"rrbot": "unconfigured"})
        _call(learner, "recover", cm, "rrbot", [JSB, FWD])
        assert _states(system) == ({JSB: "active", FWD: "active"}, {"rrbot": "active"}), _states(system)
        system.publish(f"/{FWD}/commands", Float64MultiArray(data=[0.4, -0.2]))
        system.spin(0.05)
        assert system.latest("/joint_states").position == pytest.approx([0.4, -0.2]), "the robot does not move again"


# --------------------------------------------------------------------------------------------- 6.3


@graded(points=3, hint=(
    "Task 6.3: a controller can be unloaded only when it is not active; an inactive one is cleaned up on the way. "
    "Your function must work from active, inactive and unconfigured.",
    "Look up its state with cm.list_controllers(); deactivate an active one with a switch, cleanup_controller an "
    "inactive one, then unload_controller.",
    "if state == 'active': cm.switch_controllers(deactivate=[name], strictness='strict'); ...; cm.unload_controller(name)",
))
def test_remove_a_controller_from_any_state(learner: ModuleType) -> None:
    for name, setup in ((FWD, None), (JTC, "inactive"), (JTC, "unconfigured")):
        with _system(inactive=(JTC,)) as system:
            cm = system.controller_manager
            if setup == "unconfigured":
                cm.cleanup_controller(JTC)
            _call(learner, "remove_controller", cm, name)
            controllers, _ = _states(system)
            assert name not in controllers, f"{name} ({setup or 'active'}) is still loaded: {controllers}"
            assert controllers.get(JSB) == "active", "removing one controller must leave the others as they were"
            topics = [t for t, _ in system.bus.topic_names_and_types() if t.startswith(f"/{name}/")]
            assert not topics, f"{name}'s topics are still there: {topics}"


# --------------------------------------------------------------------------------------------- 6.4


def _run_request(name: str) -> dict[str, Any]:
    with _system(inactive=(JTC,)) as system:
        try:
            REQUESTS[name](system.controller_manager)
            accepted = True
        except RRBotWorkshopError:
            accepted = False
        controllers, hardware = _states(system)
    return {"accepted": accepted, "controllers": controllers, "hardware": hardware}


def _differences(predicted: Any, actual: dict[str, Any]) -> list[str]:
    if not isinstance(predicted, dict):
        return ["no prediction (a dict with 'accepted', 'controllers' and 'hardware')"]
    wrong = []
    if predicted.get("accepted") is not actual["accepted"]:
        wrong.append("whether it is accepted")
    for part in ("controllers", "hardware"):
        given = predicted.get(part) or {}
        for name in actual[part]:
            if given.get(name) != actual[part][name]:
                wrong.append(f"the state of {name}")
    return wrong


@graded(points=6, hint=(
    "Task 6.4: predict each request in notebook 06 before running it; the self-check says which parts of a prediction "
    "are wrong, never the right answer.",
    "Rules to use: interface conflicts are errors whatever the strictness; only an unconfigured controller can be "
    "configured and only a non-active one unloaded; hardware state changes do not touch the controllers; an "
    "unconfigured component's interfaces are unavailable; cleanup takes an inactive controller to unconfigured.",
    "Run each request in the notebook's last section and read the states it prints.",
))
def test_predictions(learner: ModuleType) -> None:
    predictions = getattr(learner, "PREDICTIONS", None)
    if not isinstance(predictions, dict):
        pytest.fail(f"{FILE} has no PREDICTIONS dict", pytrace=False)
    wrong = {}
    for name in REQUESTS:
        problems = _differences(predictions.get(name), _run_request(name))
        if problems:
            wrong[name] = problems
    assert not wrong, "these predictions are wrong in: " + "; ".join(f"{n}: {', '.join(p)}" for n, p in wrong.items())
