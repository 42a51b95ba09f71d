"""Grader of task 14: the learner's predictions of what ros2_control does on each fault of the fault lab.

The specification (``predictions.py`` and notebook 14): ``PREDICTIONS`` is a dict with one entry per fault of
:data:`rrbot_workshop.course.fault_lab.FAULTS`; each entry gives the lifecycle state of every controller and of the
hardware component after the fault (labels such as ``"active"``, in any letter case), and the joint positions of the
last ``/joint_states`` message, in rad, to 2 decimals (within 0.005 rad). Each fault's prediction is two checks, one
point each: the states, and the joint positions. Each is compared with the fault run live on a fresh system, here, in
the grader: the answer is what the controller manager does, not a stored list. A failed check names what is wrong,
never the right answer. ``predictions.py`` must predict: the fault lab cannot run while it is imported.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course import fault_lab
from rrbot_workshop.course.grading import graded

TASK = 14
FILE = "predictions.py"

#: Three levels per fault and part: the idea, where to look (the API or the rule), then how to reason to the answer.
HINTS: dict[str, dict[str, tuple[str, str, str]]] = {
    "read_error": {
        "states": (
            "A read() returning ERROR makes the component run on_error; what its return value decides, and what a "
            "controller can do without the interfaces of a component that failed.",
            "on_error's default (rclcpp_lifecycle's) returns SUCCESS. SUCCESS from on_error leads to unconfigured, "
            "FAILURE or ERROR to finalized; the controller manager then deactivates every controller that uses the "
            "failed component's interfaces, state interfaces included.",
            "The component: the state that on_error's SUCCESS leads to. Each controller: was it using rrbot's "
            "interfaces, and was it active to begin with?"),
        "joints": (
            "After the error, who still publishes /joint_states? The last message is the one before the fault.",
            "The broadcaster publishes only while it is active; the joints had reached their command before the fault.",
            "The joints were commanded to [0.2, 0.2] before the fault."),
    },
    "update_exception": {
        "states": (
            "The controller manager catches what update() raises; the others are not its business.",
            "An exception from update() is handled as update() returning ERROR: the manager deactivates that "
            "controller (and activates its fallback_controllers, if it has any).",
            "Only the controller whose update() raised changes state; the broadcaster and the hardware go on."),
        "joints": (
            "A deactivated forward controller writes nothing more; what does mock hardware keep?",
            "Mock hardware mirrors the last command it was written into its states.",
            "The last command written was [0.2, 0.2]."),
    },
    "wrong_size_command": {
        "states": (
            "A command of the wrong size is not ignored in Jazzy.",
            "The forward controller's update() returns ERROR when a message's size is not its number of joints, and the "
            "controller manager deactivates a controller whose update() returns ERROR.",
            "Treat it as the update_exception fault: one controller changes state."),
        "joints": (
            "Was anything of the wrong-size message ever written to the joints?",
            "update() returns ERROR before writing: the command interfaces keep their last values.",
            "The last command written was [0.2, 0.2]."),
    },
    "beyond_limits": {
        "states": (
            "A command beyond the URDF's limit is not an error for any controller or component.",
            "Nothing in the controller manager or the mock hardware changes state over a command's value.",
            "Everything stays as it was before the fault."),
        "joints": (
            "Jazzy's default is enforce_command_limits: false; does anything apply the URDF's limits then?",
            "Without enforcement, commands are written as they are, and mock hardware follows its commands exactly.",
            "The joints end where they were commanded."),
    },
    "beyond_limits_enforced": {
        "states": (
            "Limiting a command is not an error: nobody changes state.",
            "enforce_command_limits only changes the values written to the hardware.",
            "Everything stays as it was before the fault."),
        "joints": (
            "With enforcement, each cycle's position step is limited by the URDF velocity (180 deg/s) and the position "
            "by the URDF range; 2 s is enough to reach the end of the range.",
            "joint2's URDF range is [-60, 240] degrees; joint1's is [-380, 380] degrees.",
            "joint1 reaches its command; joint2 stops at its upper limit, in rad, to 2 decimals."),
    },
    "nan_command": {
        "states": (
            "A NaN in a command is an event, not a crash: does any controller or component fail?",
            "The forward controller checks each message on ~/commands for non-finite numbers before it keeps it.",
            "Nobody changes state."),
        "joints": (
            "What does the forward controller do with a message holding a non-finite number?",
            "Jazzy's forward controller (ros2_controllers 4.29.0 and later) drops such a message as a whole and keeps "
            "its last command.",
            "Neither joint takes a value from the dropped message."),
    },
    "hardware_inactive": {
        "states": (
            "Setting hardware inactive by hand does not deactivate controllers in Jazzy.",
            "set_hardware_component_state changes only the component (ros2_control issue #3444 describes it).",
            "The component is in the state you asked for; the controllers are as before."),
        "joints": (
            "An inactive component is still read but not written; what does mock hardware do when it reads?",
            "mock_components/GenericSystem copies commands into states in read().",
            "The joints follow the command sent after the switch."),
    },
    "double_claim": {
        "states": (
            "A strict switch that would claim an interface twice is rejected as a whole.",
            "The forward controller holds joint1/position and joint2/position; the trajectory controller needs the "
            "same interfaces. With strictness STRICT, nothing of a rejected switch happens.",
            "Nothing changes state."),
        "joints": (
            "Was any new command sent?",
            "A rejected switch changes no controller, so the forward controller keeps its last command.",
            "The joints stay at the command sent before the fault."),
    },
}


@pytest.fixture(scope="module")
def predictions(task_file: Callable[[int, str], Path]) -> dict[str, Any]:
    task_file(TASK, FILE)

    def unavailable(*_args: Any, **_kwargs: Any) -> Any:
        raise RuntimeError("predictions.py must predict, not run the faults (the fault lab is unavailable while it is "
                           "imported)")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(fault_lab, "run_fault", unavailable)
        patch.setattr(fault_lab, "reveal", unavailable)
        module = rw.course.load_module(TASK, FILE, quiet=True)
    if module is None:
        pytest.fail(f"your {FILE} does not import (or it runs the faults): open it in notebook 14 to see the error",
                    pytrace=False)
    found = getattr(module, "PREDICTIONS", None)
    if not isinstance(found, dict):
        pytest.fail(f"your {FILE} must define PREDICTIONS as a dict, fault name -> prediction", pytrace=False)
    return found


@pytest.fixture(scope="module")
def outcomes() -> Iterator[dict[str, fault_lab.Outcome]]:
    yield {name: fault_lab.run_fault(name) for name in fault_lab.FAULTS}


def _check(name: str, part: str, predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
    if name not in predictions:
        pytest.fail(f"PREDICTIONS in your {FILE} has no entry '{name}'", pytrace=False)
    problems = fault_lab.compare(predictions[name], outcomes[name], reveal=False, part=part)
    if problems:
        what = "states" if part == "states" else "joint positions"
        pytest.fail(f"{name}, {what}: not what happens: " + "; ".join(problems) + ".", pytrace=False)


def _make(name: str, part: str) -> Callable[..., None]:
    @graded(points=1, hint=tuple(f"Task 14, {name} ({part}): {level}" for level in HINTS[name][part]))
    def check(predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
        _check(name, part, predictions, outcomes)

    check.__name__ = f"test_{name}_{part}"
    check.__doc__ = f"The {part} predicted for fault {name} are what happens."
    return check


for _name in fault_lab.FAULTS:
    for _part in ("states", "joints"):
        globals()[f"test_{_name}_{_part}"] = _make(_name, _part)
