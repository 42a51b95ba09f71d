"""Grader of task 14: the learner's predictions of what ros2_control does on each fault of the fault lab.

The specification: ``predictions.py`` defines ``PREDICTIONS``, a dict with one entry per fault of
:data:`rrbot_workshop.course.fault_lab.FAULTS`; each entry gives the state of every controller and of the hardware
component after the fault, and the joint positions of the last ``/joint_states`` message (within 1 mrad). Each
prediction is checked against the fault run live on a fresh system, here, in the grader: the answer is what the
controller manager does, not a stored list. The module must not run the faults itself (the fault lab is not
available while it is imported).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course import fault_lab
from rrbot_workshop.course.grading import graded

TASK = 14
FILE = "predictions.py"
HINTS = {
    "read_error": "A hardware error is handled by the component's on_error, whose default returns SUCCESS; and a "
                  "controller cannot keep interfaces of hardware that failed.",
    "update_exception": "The controller manager catches what update() raises and treats it as ERROR: what does it do "
                        "with a controller whose update returns ERROR? The others are not its business.",
    "wrong_size_command": "A command of the wrong size is not ignored in Jazzy: the controller's update() returns ERROR.",
    "beyond_limits": "Jazzy's default is enforce_command_limits: false, and mock hardware follows its commands exactly.",
    "beyond_limits_enforced": "With enforcement, each cycle's position step is limited by the URDF velocity (180 deg/s) "
                              "and the position by the URDF range; 2 s is enough to reach the end of the range.",
    "nan_command": "What does the forward controller do with a message holding a non-finite number?",
    "hardware_inactive": "Setting hardware inactive by hand does not deactivate controllers in Jazzy; and mock hardware "
                         "reads (mirrors commands into states) while inactive, it only stops writing.",
    "double_claim": "A strict switch that would claim an interface twice is rejected as a whole.",
}


@pytest.fixture(scope="module")
def predictions(task_file: Callable[[int, str], Path]) -> dict[str, Any]:
    task_file(TASK, FILE)
    real = fault_lab.run_fault

    def unavailable(*_args: Any, **_kwargs: Any) -> Any:
        raise RuntimeError("predictions.py must predict, not run the faults")

    fault_lab.run_fault = unavailable  # type: ignore[assignment]
    try:
        module: ModuleType | None = rw.course.load_module(TASK, FILE, quiet=True)
    finally:
        fault_lab.run_fault = real  # type: ignore[assignment]
    if module is None:
        pytest.fail(f"{FILE} does not import", pytrace=False)
    found = getattr(module, "PREDICTIONS", None)
    if not isinstance(found, dict):
        pytest.fail(f"{FILE} must define PREDICTIONS as a dict, fault name -> prediction", pytrace=False)
    return found


@pytest.fixture(scope="module")
def outcomes() -> Iterator[dict[str, fault_lab.Outcome]]:
    yield {name: fault_lab.run_fault(name) for name in fault_lab.FAULTS}


def _check(name: str, predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
    if name not in predictions:
        pytest.fail(f"PREDICTIONS has no entry '{name}'", pytrace=False)
    problems = fault_lab.compare(predictions[name], outcomes[name], reveal=False)
    assert not problems, f"{name}: not what happens: " + "; ".join(problems)


def _make(name: str) -> Callable[..., None]:
    @graded(points=1, hint=f"Task 14, {name}: {HINTS[name]}")
    def check(predictions: dict[str, Any], outcomes: dict[str, fault_lab.Outcome]) -> None:
        _check(name, predictions, outcomes)

    check.__name__ = f"test_{name}"
    return check


for _name in fault_lab.FAULTS:
    globals()[f"test_{_name}"] = _make(_name)
