"""Task 16: pytest tests of the task-8 DisplacementController, as ros2_controllers would ask of a first contribution.

Each test takes the fixture ``controller_class`` and builds the controller with ``controller_class()``, through
``make_harness`` below: it plays the controller manager (it owns the interfaces the controller borrows, a topic bus and
a clock) as the fixture of a ros2_controllers test does. Run by you, ``controller_class`` is your own task-8 class
(``pytest exercises/task16_test_your_controller -q``, or the cell of notebook 16). The grader gives your tests other
controllers in its place:

* a correct controller: every test must pass on it (a test that fails on a correct controller is a wrong test);
* wrong controllers, each written as a learner would, each breaking one rule of notebook 08: your score is the share
  of them that at least one of your tests fails on; for each one your tests let through, the reason names the rule;
* a controller that does nothing: a test counts only if it checks something (an ``assert`` that runs, or
  ``pytest.raises``); one that only shows that nothing raised earns nothing.

The rules are in notebook 08 and in the TODOs of ``exercises/task08_write_a_controller/displacement_controller.py``.
A test of a rule sets up the situation where the rule matters, acts, and asserts what the rule says must happen;
vary what the notebook kept fixed (joint names and counts, the interface, the controller's name, the rate).
``rrbot-workshop grade 16`` (or ``check(16)`` in notebook 16) runs the grading.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import pytest

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.msgs import JointJog, SetBoolRequest
from rrbot_workshop.testing import ControllerHarness

__all__ = ["make_harness"]


def make_harness(controller_class: type, joints: Sequence[str] = ("joint1", "joint2"), interface: str = "position",
                 *, name: str = "displacement_controller", state_joints: Sequence[str] = (),
                 states: Sequence[float] | None = None, update_rate: int = 100) -> ControllerHarness:
    """A new controller of ``controller_class`` in a harness, loaded (its parameters checked), not configured yet.

    The harness owns ``<joint>/<interface>`` command interfaces (0.0 each) and ``<state joint>/<interface>`` state
    interfaces (1.1, 2.2, 3.3, ... unless ``states`` says otherwise); the state joints are ``state_joints``, or the
    joints when it is empty. Parameters the schema refuses raise ``ParameterError`` here, as a controller manager
    refuses to load the controller.

    Args:
        controller_class: The class under test (the fixture).
        joints: The parameter ``joints``.
        interface: The parameter ``interface_name``.
        name: The controller's name: its topics are ``/<name>/...``.
        state_joints: The parameter ``state_joints`` (left out when empty).
        states: Initial state values, one per state joint.
        update_rate: The controller manager's rate in [Hz]; ``update`` gets ``1 / update_rate`` as its period.
    """
    read = list(state_joints) or list(joints)
    values = list(states) if states is not None else [round(1.1 * (i + 1), 10) for i in range(len(read))]
    parameters: dict[str, object] = {"joints": list(joints), "interface_name": interface}
    if state_joints:
        parameters["state_joints"] = list(state_joints)
    return ControllerHarness(controller_class(), name, parameters,
                             state_values={f"{j}/{interface}": v for j, v in zip(read, values, strict=True)},
                             command_values={f"{j}/{interface}": 0.0 for j in joints}, update_rate=update_rate)


# What the harness gives you (h = make_harness(controller_class, ...)):
#   h.configure(), h.activate(), h.deactivate()      -> the lifecycle State reached (State.INACTIVE, State.ACTIVE, ...)
#   h.publish("~/reference", JointJog(joint_names=[...], displacements=[...]))     a message, delivered at once
#   h.bus.call_service(f"/{h.name}/set_slow_control_mode", SetBoolRequest(data=True))     the service's response
#   h.update()                                        -> the ReturnType of update (the clock moves one period first)
#   h.value("joint1/position"), h.values([...])       a command (or state) interface's value now
#   h.set("joint1/position", 0.7)                     a state moves, as the hardware would move it
#   h.latest("~/state")                               the last message the controller published there (or None)
#   h.controller.command_interface_configuration().names     what the controller claims
# and pytest's: assert, pytest.approx (floats), pytest.raises(ParameterError), math.isnan, the caplog fixture (logs).

# TODO(task 16): write one test function per rule of notebook 08, each named for its rule, each taking
#   controller_class (directly or through a fixture of yours). Cover the parameters and their validation, configure
#   and the interfaces claimed, the topics and the service, which messages are taken and which refused (and what a
#   refused message changes), how update computes the commands and how often a displacement is used, slow mode,
#   ~/state, activation, deactivation and activating again.
