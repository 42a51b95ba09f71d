"""Grader of task 14: the learner's predictions of what ros2_control does on each fault of the fault lab.

The specification (``predictions.py`` and notebook 14): ``PREDICTIONS`` is a dict with one entry per fault of
:data:`rrbot_workshop.course.fault_lab.FAULTS`; each entry gives the lifecycle state of every controller and of the
hardware component after the fault (labels such as ``"active"``, in any letter case), and the joint positions of the
last ``/joint_states`` message, in rad, to 2 decimals (within 0.005 rad). Each fault's prediction is two checks, one
point each: the states, and the joint positions. Each is compared with the fault run live on a fresh system, here, in
the grader: the answer is what the controller manager does, not a stored list. A failed check names what is wrong,
never the right answer. ``predictions.py`` must predict: the fault lab cannot run while it is imported.

No hint states an outcome the learner has not predicted: a part not predicted yet (or not a prediction: a label that is
no lifecycle state, positions that are not two numbers) fails without a hint, and the hints of a wrong prediction ask
questions and point at the rule, never at the result. Notebook 14 seals a fault's prediction when it shows its outcome
(:mod:`rrbot_workshop.course.grading.sealed`): a part changed after that earns nothing, and the reason says so. Every
check builds on ``predictions_file_loads``: a file that does not import is one cause, with one hint.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course import fault_lab, tracks
from rrbot_workshop.course.grading import graded, sealed
from rrbot_workshop.course.grading.rubric import fail_without_hint

TASK = 14
FILE = "predictions.py"

#: Three levels per fault and part, shown only for a prediction that is made and wrong: the question to ask, where the
#: rule is (without applying it to this fault), then how to reason it through. None states what happens: the learner
#: predicts it, and notebook 14 shows it once they have.
HINTS: dict[str, dict[str, tuple[str, str, str]]] = {
    "read_error": {
        "states": (
            "A read() returning ERROR makes the component run on_error; what decides the state it ends in, and what can "
            "a controller do without the interfaces of a component that failed?",
            "Look up what on_error returns by default (rclcpp_lifecycle's LifecycleNode) and which state each return "
            "value of on_error leads to; then what the controller manager does with the controllers using a failed "
            "component's interfaces, state interfaces included.",
            "Reason in order: the component's end state from on_error's default; then each controller: did it use "
            "rrbot's interfaces (commands or states), and was it active before the fault?"),
        "joints": (
            "The joints are read from the last /joint_states message: who publishes it, and when does it stop?",
            "The broadcaster publishes only while it is active; where had the joints got to before the fault?",
            "Find the last cycle in which /joint_states was published, and the positions the joints had then."),
    },
    "update_exception": {
        "states": (
            "The controller manager runs every controller's update() in its loop; what may it do when one raises?",
            "Look at how Jazzy's controller manager treats an exception from update() (it compares it with a return "
            "value of update()), and whom that concerns: the controller, the others, the hardware.",
            "Go through each controller and the component: did anything it needs fail? Only then can its state change."),
        "joints": (
            "After the fault, does anything write new commands to the joints?",
            "Mock hardware (mock_components/GenericSystem) mirrors into its states what was last written to its command "
            "interfaces.",
            "Find the last command written to the joints before the fault, and ask whether anything wrote one since."),
    },
    "wrong_size_command": {
        "states": (
            "What does the forward controller do in update() with a message whose size is not its number of joints?",
            "Look at ForwardCommandController's update() in Jazzy for a command of the wrong size, and at what the "
            "controller manager does with the value update() returns.",
            "Compare it with the update_exception fault: is the controller's update() successful here?"),
        "joints": (
            "Was anything of the wrong-size message ever written to the joints?",
            "update() checks the message's size before it writes the command interfaces.",
            "Find the last command that was written, and whether the wrong-size one ever got as far as write()."),
    },
    "beyond_limits": {
        "states": (
            "Is a command beyond the URDF's limit an error for any controller or component?",
            "Look at what in the controller manager or the mock hardware changes a lifecycle state, and whether a "
            "command's value is among those things.",
            "Go through each controller and the component: does any of them fail, or get asked to change state?"),
        "joints": (
            "Jazzy's default is enforce_command_limits: false; does anything apply the URDF's limits then?",
            "Without enforcement the controller manager writes commands as they are; mock hardware follows what it is "
            "written.",
            "Follow the command from ~/commands through the forward controller and the mock hardware to /joint_states."),
    },
    "beyond_limits_enforced": {
        "states": (
            "Is limiting a command an error for anyone?",
            "enforce_command_limits changes the values written to the hardware; look at whether it changes anything "
            "else.",
            "Go through each controller and the component: does any of them fail, or get asked to change state?"),
        "joints": (
            "With enforcement, each cycle's position step is limited by the URDF velocity and the position by the URDF "
            "range; is 2 s enough for each joint to get where it may go?",
            "joint2's URDF range is [-60, 240] degrees and its velocity limit 180 deg/s; joint1's range is [-380, 380] "
            "degrees. Positions are in rad, to 2 decimals.",
            "For each joint: the command, clipped to its range; then check that the velocity limit gets it there "
            "within 2 s."),
    },
    "nan_command": {
        "states": (
            "A NaN in a command is an event, not a crash: does any controller or component fail?",
            "Look at where Jazzy's forward controller checks the values of a message on ~/commands, and what it does "
            "with one that holds a non-finite number.",
            "Go through each controller and the component: does any of them fail, or get asked to change state?"),
        "joints": (
            "What does the forward controller do with a message holding a non-finite number?",
            "Look at ros2_controllers 4.29.0 (the July 2025 Jazzy release) and later: how the forward controller "
            "treats a message with NaN in it, as a whole or number by number.",
            "Decide whether any value of the message reaches a command interface, then where each joint ends."),
    },
    "hardware_inactive": {
        "states": (
            "Does setting a component inactive by hand change the controllers that use it, in Jazzy?",
            "Look at what set_hardware_component_state does to the controllers (ros2_control issue #3444 discusses "
            "it).",
            "The component: the state you asked for. Each controller: does anything deactivate it?"),
        "joints": (
            "An inactive component is read but not written; what does mock hardware do when it reads?",
            "mock_components/GenericSystem copies commands into states in read(), not in write().",
            "Follow the command sent after the switch: does it reach the command interfaces, and does read() copy it?"),
    },
    "double_claim": {
        "states": (
            "What does a strict switch do when one of its requests cannot be done?",
            "Look at how a switch checks the command interfaces to be claimed against the ones active controllers "
            "hold, and what strictness STRICT means for the rest of the switch.",
            "Which interfaces does the trajectory controller need, who holds them, and what does STRICT do with the "
            "whole request then?"),
        "joints": (
            "Was any new command sent, or any controller changed?",
            "The joints follow whatever controller commands them; look at which one does after the switch request.",
            "Find the last command written to the joints, and whether anything wrote another since."),
    },
}

#: The parts of a prediction each check grades, and the keys of the prediction they are.
PARTS = {"states": ("controllers", "hardware"), "joints": ("joints",)}
#: Lifecycle state labels a prediction may use (any letter case).
STATES = ("unconfigured", "inactive", "active", "finalized")


def _load() -> tuple[Any, str]:
    """The learner's PREDICTIONS, or None and why not."""
    def unavailable(*_args: Any, **_kwargs: Any) -> Any:
        raise RuntimeError("predictions.py must predict, not run the faults (the fault lab is unavailable while it is "
                           "imported)")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(fault_lab, "run_fault", unavailable)
        patch.setattr(fault_lab, "reveal", unavailable)
        module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        return None, f"your {FILE} does not import (or it runs the faults): open it in notebook 14 to see the error"
    found = getattr(module, "PREDICTIONS", None)
    if not isinstance(found, dict):
        return None, f"your {FILE} must define PREDICTIONS as a dict, fault name -> prediction"
    return found, ""


@pytest.fixture(scope="module")
def loaded(task_file: Callable[[int, str], Path]) -> tuple[Any, str]:
    task_file(TASK, FILE)
    return _load()


@pytest.fixture(scope="module")
def predictions(loaded: tuple[Any, str]) -> dict[str, Any]:
    found, why = loaded
    if found is None:
        pytest.fail(why, pytrace=False)
    return found


@pytest.fixture(scope="module")
def outcomes() -> Iterator[dict[str, fault_lab.Outcome]]:
    yield {name: fault_lab.run_fault(name) for name in fault_lab.FAULTS}


@graded(points=1, given=True, hint=(
    "Task 14: predictions.py must import on its own and define PREDICTIONS, a dict from each fault's name to its "
    "prediction.",
    "Open predictions.py in notebook 14 (or run it with python): the first error it shows is the one to fix; it must "
    "not run the faults itself.",
    "PREDICTIONS = {\"read_error\": {\"controllers\": {...}, \"hardware\": {\"rrbot\": ...}, \"joints\": [..., ...]}, ...}",
))
def test_predictions_file_loads(loaded: tuple[Any, str]) -> None:
    """predictions.py imports, without running the faults, and defines PREDICTIONS as a dict."""
    found, why = loaded
    assert found is not None, why


def _not_yet(name: str, part: str, prediction: Any) -> str:
    """What of the part is not predicted yet, or is not a prediction at all ("" when it is complete)."""
    if not isinstance(prediction, dict):
        return f"PREDICTIONS['{name}'] is not a dict with 'controllers', 'hardware' and 'joints'"
    if part == "states":
        gaps = [g for g in fault_lab.missing(prediction) if g != "joints"]
        if gaps:
            return f"{name}, states: not predicted yet: {', '.join(gaps)}"
        labels = [f"{key}[{n!r}] = {v!r}" for key in ("controllers", "hardware") for n, v in prediction[key].items()
                  if not (isinstance(v, str) and v.strip().lower() in STATES)]
        if labels:
            return (f"{name}, states: {', '.join(labels)} is not a lifecycle state; a state is one of "
                    f"{', '.join(STATES)} (any letter case)")
        return ""
    joints = prediction.get("joints")
    if not isinstance(joints, list | tuple) or len(joints) != len(fault_lab.JOINTS):
        return f"{name}, joints: 'joints' must list {len(fault_lab.JOINTS)} positions in rad, got {joints!r}"
    if any(j is None for j in joints):
        return f"{name}, joints: not predicted yet ({joints!r})"
    if not all(isinstance(j, int | float) and not isinstance(j, bool) and math.isfinite(j) for j in joints):
        return f"{name}, joints: {joints!r}: each position is a finite number of rad"
    return ""


def _where(name: str) -> str:
    """``"your predictions.py, line N"``: where the learner's prediction of ``name`` starts (its key), if found."""
    try:
        lines = (tracks.task_dir(TASK) / FILE).read_text().splitlines()
    except OSError:
        return f"your {FILE}"
    for number, line in enumerate(lines, start=1):
        if f'"{name}"' in line or f"'{name}'" in line:
            return f"your {FILE}, line {number}"
    return f"your {FILE}"


def _check(name: str, part: str, predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
    if name not in predictions:
        fail_without_hint(f"your {FILE}: PREDICTIONS has no entry '{name}'")
    prediction = predictions[name]
    changed = sealed.changed_since_sealed(TASK, name, prediction, keys=PARTS[part], notebook="notebook 14")
    if changed:
        fail_without_hint(f"{_where(name)}: {changed}")
    unmade = _not_yet(name, part, prediction)
    if unmade:  # any hint would state the outcome of something the learner has not predicted
        fail_without_hint(f"{_where(name)}: {unmade}")
    problems = fault_lab.compare(prediction, outcomes[name], reveal=False, part=part)
    if problems:
        what = "states" if part == "states" else "joint positions"
        pytest.fail(f"{_where(name)}: {name}, {what}: not what happens: " + "; ".join(problems) + ".",
                    pytrace=False)


def _make(name: str, part: str) -> Callable[..., None]:
    @graded(points=1, hint=tuple(f"Task 14, {name} ({part}): {level}" for level in HINTS[name][part]),
            after=("predictions_file_loads",))
    def check(predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
        _check(name, part, predictions, outcomes)

    check.__name__ = f"test_{name}_{part}"
    check.__doc__ = f"The {part} predicted for fault {name} are what happens."
    return check


for _name in fault_lab.FAULTS:
    for _part in ("states", "joints"):
        globals()[f"test_{_name}_{_part}"] = _make(_name, _part)
