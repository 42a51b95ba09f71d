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


# --------------------------------------------------------------------------------------------- helpers of these tests

TWO = ["joint1/position", "joint2/position"]


def started(controller_class: type, **kwargs: object) -> ControllerHarness:
    """A controller configured and activated in a harness (see make_harness for the arguments)."""
    h = make_harness(controller_class, **kwargs)  # type: ignore[arg-type]
    assert h.configure() is State.INACTIVE, "configure did not succeed"
    assert h.activate() is State.ACTIVE, "activate did not succeed"
    return h


def jog(h: ControllerHarness, names: Sequence[str], displacements: Sequence[float]) -> None:
    h.publish("~/reference", JointJog(joint_names=list(names), displacements=list(displacements)))


def slow(h: ControllerHarness, on: bool) -> object:
    return h.bus.call_service(f"/{h.name}/set_slow_control_mode", SetBoolRequest(data=on))


# --------------------------------------------------------------------------------------------- parameters, configure


def test_interface_name_must_be_one_of_four(controller_class):
    for bad in ("torque", "Position", ""):
        with pytest.raises(ParameterError):
            make_harness(controller_class, interface=bad)
    for good in ("position", "velocity", "acceleration", "effort"):
        assert make_harness(controller_class, interface=good).configure() is State.INACTIVE


def test_interface_name_with_the_blup_prefix_is_refused_by_the_custom_validator(controller_class):
    with pytest.raises(ParameterError, match="blup_"):
        make_harness(controller_class, interface="blup_position")


def test_empty_or_repeated_joints_are_refused_at_load(controller_class):
    with pytest.raises(ParameterError):
        make_harness(controller_class, joints=[])
    with pytest.raises(ParameterError):
        make_harness(controller_class, joints=["joint1", "joint1"])


def test_state_joints_of_another_size_fail_configure(controller_class):
    for state_joints in (["s1"], ["s1", "s2", "s3"]):
        h = make_harness(controller_class, state_joints=state_joints)
        assert h.configure() is State.UNCONFIGURED, f"configure with state_joints {state_joints} must fail"
    assert make_harness(controller_class, state_joints=["s1", "s2"]).configure() is State.INACTIVE


def test_states_are_read_from_the_state_joints(controller_class):
    h = make_harness(controller_class, joints=["j1", "j2"], state_joints=["s1", "s2"], states=[0.5, -0.5])
    assert h.configure() is State.INACTIVE
    assert h.controller.command_interface_configuration().names == ["j1/position", "j2/position"]
    assert h.controller.state_interface_configuration().names == ["s1/position", "s2/position"]
    assert h.activate() is State.ACTIVE
    jog(h, ["j1", "j2"], [0.1, 0.2])
    h.update()
    assert h.values(["j1/position", "j2/position"]) == pytest.approx([0.6, -0.3])


def test_claims_the_joints_and_interface_it_is_given(controller_class):
    joints = ["shoulder", "elbow", "wrist"]
    h = make_harness(controller_class, joints=joints, interface="velocity")
    assert h.configure() is State.INACTIVE
    assert h.controller.command_interface_configuration().names == [f"{j}/velocity" for j in joints]
    assert h.controller.state_interface_configuration().names == [f"{j}/velocity" for j in joints]
    assert h.activate() is State.ACTIVE
    jog(h, joints, [0.1, 0.2, 0.3])
    h.update()
    assert h.values([f"{j}/velocity" for j in joints]) == pytest.approx([1.2, 2.4, 3.6])


def test_topics_and_service_follow_the_controller_name(controller_class):
    h = make_harness(controller_class, name="arm_jog")
    assert h.configure() is State.INACTIVE
    assert h.bus.subscription_count("/arm_jog/reference") == 1
    assert "/arm_jog/set_slow_control_mode" in h.bus.service_names()
    assert h.bus.publisher_count("/arm_jog/state") == 1
    assert h.activate() is State.ACTIVE
    jog(h, ["joint1", "joint2"], [1.0, 1.0])
    h.update()
    assert h.values(TWO) == pytest.approx([2.1, 3.2])
    assert h.latest("/arm_jog/state") is not None


# --------------------------------------------------------------------------------------------- messages, slow mode


def test_displacements_are_matched_by_name(controller_class):
    h = started(controller_class)
    jog(h, ["joint2", "joint1"], [1.0, 10.0])
    h.update()
    assert h.values(TWO) == pytest.approx([1.1 + 10.0, 2.2 + 1.0])


@pytest.mark.parametrize("names, displacements", [
    (["joint1"], [5.0]), (["joint1", "joint2", "joint3"], [1.0, 1.0, 1.0]), (["joint1", "joint2"], [1.0]),
    (["joint1", "elbow"], [1.0, 1.0]), (["joint1", "joint1"], [1.0, 2.0]), ([], []),
])
def test_a_message_without_one_displacement_per_joint_is_refused(controller_class, names, displacements):
    h = started(controller_class)
    jog(h, names, displacements)
    h.update()
    assert h.values(TWO) == [0.0, 0.0], f"a JointJog naming {names} with {displacements} moved a joint"
    jog(h, ["joint1", "joint2"], [0.5, 0.5])  # the controller still takes a valid one
    h.update()
    assert h.values(TWO) == pytest.approx([1.6, 2.7])


def test_a_refused_message_keeps_the_pending_one(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [0.4, -0.4])
    jog(h, ["joint1"], [9.0])
    h.update()
    assert h.values(TWO) == pytest.approx([1.5, 1.8])


def test_a_refused_message_is_logged(controller_class, caplog):
    h = started(controller_class)
    with caplog.at_level(logging.WARNING):
        jog(h, ["joint1"], [5.0])
    assert any(r.levelno >= logging.WARNING for r in caplog.records), "the refusal left nothing in the log"


def test_a_newer_message_replaces_the_pending_one(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [0.5, 0.5])
    jog(h, ["joint2", "joint1"], [-0.2, 0.3])
    h.update()
    assert h.values(TWO) == pytest.approx([1.1 + 0.3, 2.2 - 0.2])


def test_slow_mode_halves_every_displacement(controller_class):
    h = started(controller_class)
    assert slow(h, True).success is True
    jog(h, ["joint1", "joint2"], [1.0, -2.0])
    h.update()
    assert h.values(TWO) == pytest.approx([1.1 + 0.5, 2.2 - 1.0])


def test_slow_mode_is_set_not_flipped(controller_class):
    h = started(controller_class)
    for on, factor in ((False, 1.0), (True, 0.5), (True, 0.5), (False, 1.0), (False, 1.0)):
        slow(h, on)
        h.set("joint1/position", 0.0)
        jog(h, ["joint1", "joint2"], [1.0, 0.0])
        h.update()
        assert h.value("joint1/position") == pytest.approx(factor), f"after data={on}"


def test_the_mode_at_the_update_counts(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [1.0, 1.0])
    slow(h, True)
    h.update()
    assert h.values(TWO) == pytest.approx([1.6, 2.7])
    jog(h, ["joint1", "joint2"], [1.0, 1.0])
    slow(h, False)
    h.update()
    assert h.values(TWO) == pytest.approx([2.1, 3.2])


# --------------------------------------------------------------------------------------------- update, ~/state


def test_command_is_the_state_plus_the_displacement(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [23.24, 1.0])
    assert h.update() is ReturnType.OK
    assert h.values(TWO) == pytest.approx([1.1 + 23.24, 2.2 + 1.0])


def test_the_state_is_read_at_the_update(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [0.1, 0.2])
    h.set("joint1/position", -1.0)
    h.set("joint2/position", 4.0)
    h.update()
    assert h.values(TWO) == pytest.approx([-0.9, 4.2])


def test_a_displacement_is_used_once(controller_class):
    h = started(controller_class)
    jog(h, ["joint1", "joint2"], [0.5, -0.5])
    h.update()
    first = h.values(TWO)
    h.set("joint1/position", 0.0)
    h.set("joint2/position", 0.0)
    h.update()
    h.update()
    assert h.values(TWO) == first


def test_state_is_published_after_every_update(controller_class):
    h = started(controller_class)
    h.update()
    msg = h.latest("~/state")
    assert msg is not None, "an update that applied nothing published nothing on ~/state"
    assert msg.set_point == 0.0 and msg.process_value == pytest.approx(1.1)


def test_state_reports_the_first_joint(controller_class):
    h = started(controller_class, joints=["elbow", "shoulder"], states=[0.75, -2.0])
    jog(h, ["shoulder", "elbow"], [1.0, 0.25])
    h.update()
    h.set("elbow/position", 0.5)
    h.update()
    msg = h.latest("~/state")
    assert msg.header.frame_id == "elbow"
    assert msg.header.stamp == pytest.approx(h.time)
    assert msg.set_point == pytest.approx(1.0) and msg.command == pytest.approx(1.0)
    assert msg.process_value == pytest.approx(0.5)
    assert msg.error == pytest.approx(1.0 - 0.5)


def test_state_time_step_is_the_period(controller_class):
    h = started(controller_class, update_rate=50)
    h.update()
    assert h.latest("~/state").time_step == pytest.approx(0.02)


# --------------------------------------------------------------------------------------------- lifecycle


def test_deactivation_leaves_nan_on_every_command(controller_class):
    h = started(controller_class, joints=["a", "b", "c"])
    jog(h, ["a", "b", "c"], [0.1, 0.1, 0.1])
    h.update()
    assert h.deactivate() is State.INACTIVE
    assert all(math.isnan(v) for v in h.values(["a/position", "b/position", "c/position"]))


def test_activation_forgets_earlier_messages(controller_class):
    h = make_harness(controller_class)
    assert h.configure() is State.INACTIVE
    jog(h, ["joint1", "joint2"], [3.0, 3.0])  # while inactive
    assert h.activate() is State.ACTIVE
    h.update()
    assert h.values(TWO) == [0.0, 0.0]
    jog(h, ["joint1", "joint2"], [1.0, 1.0])  # left pending at deactivation
    assert h.deactivate() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    h.update()
    assert all(math.isnan(v) for v in h.values(TWO)), "a displacement pending at deactivation was applied"


def test_a_reactivated_controller_works_as_before(controller_class):
    h = started(controller_class)
    assert h.deactivate() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    jog(h, ["joint1", "joint2"], [0.5, 0.25])
    h.update()
    assert h.values(TWO) == pytest.approx([1.6, 2.45])
