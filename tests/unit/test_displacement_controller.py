"""Tests for the task-8 DisplacementController (reference solution)."""

from __future__ import annotations

import logging
import math

import pytest

from rrbot_workshop.controllers.displacement import DisplacementController, forbidden_interface_name_prefix
from rrbot_workshop.exceptions import ParameterError, UnfinishedExercise
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import JointControllerState, JointJog, SetBoolRequest, SetBoolResponse
from rrbot_workshop.testing import ControllerHarness

NAME = "test_displacement_controller"
STATES = {"joint1/position": 1.1, "joint2/position": 2.2}
CMDS = {"joint1/position": 0.0, "joint2/position": 0.0}


def _harness(params=None, states=STATES, commands=CMDS) -> ControllerHarness:
    return ControllerHarness(
        DisplacementController(), NAME,
        params if params is not None else {"joints": ["joint1", "joint2"], "interface_name": "position"},
        state_values=states, command_values=commands,
    )


def _active(params=None, **kw) -> ControllerHarness:
    h = _harness(params, **kw)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    return h


def _cmds(h):
    return h.values(["joint1/position", "joint2/position"])


def test_command_is_state_plus_displacement():
    h = _active()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, -0.2]))
    h.update()
    assert _cmds(h) == pytest.approx([1.6, 2.0])


def test_displacement_applied_only_once():
    h = _active()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, -0.2]))
    h.update()
    h.set("joint1/position", 1.6)
    h.update(3)
    assert h.value("joint1/position") == pytest.approx(1.6)
    assert all(math.isnan(d) for d in h.controller.displacements)


def test_displacements_matched_by_name_not_order():
    h = _active()
    h.publish("~/reference", JointJog(joint_names=["joint2", "joint1"], displacements=[10.0, 20.0]))
    h.update()
    assert _cmds(h) == pytest.approx([21.1, 12.2])


def test_a_message_for_fewer_joints_is_rejected_and_the_commands_stay(caplog):
    """As the original: one displacement per joint of the controller, or the message is refused (reason logged)."""
    h = _active(commands={"joint1/position": 5.0, "joint2/position": 6.0})
    with caplog.at_level("ERROR"):
        h.publish("~/reference", JointJog(joint_names=["joint2"], displacements=[1.0]))
        h.update()
    assert _cmds(h) == pytest.approx([5.0, 6.0])
    assert "names 1 joint(s) ['joint2'], the controller has 2" in caplog.text


def test_unknown_joint_rejected_with_reason(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", JointJog(joint_names=["joint1", "elbow"], displacements=[1.0, 1.0]))
    h.update()
    assert _cmds(h) == [0.0, 0.0]
    assert "'joint_names' has unknown joints ['elbow']" in caplog.text


def test_size_mismatch_rejected_with_reason(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[1.0]))
    h.update()
    assert _cmds(h) == [0.0, 0.0]
    assert "'displacements' has 1 values but field 'joint_names' has 2" in caplog.text


def test_repeated_joint_rejected(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", JointJog(joint_names=["joint1", "joint1"], displacements=[1.0, 2.0]))
    assert "repeats ['joint1']" in caplog.text


def test_infinite_displacement_rejected(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[math.inf, 0.0]))
    h.update()
    assert h.value("joint1/position") == 0.0
    assert "infinite" in caplog.text


def test_unnamed_message_with_full_size_uses_joint_order(caplog):
    h = _active()
    with caplog.at_level(logging.WARNING):
        h.publish("~/reference", JointJog(displacements=[1.0, 1.0]))
    h.update()
    assert _cmds(h) == pytest.approx([2.1, 3.2])
    assert "without 'joint_names'" in caplog.text


def test_unnamed_message_with_wrong_size_rejected(caplog):
    h = _active()
    with caplog.at_level(logging.ERROR):
        h.publish("~/reference", JointJog(displacements=[1.0]))
    assert "'joint_names' is empty" in caplog.text


def test_slow_mode_halves_displacements():
    h = _active()
    response = h.bus.call_service(f"/{NAME}/set_slow_control_mode", SetBoolRequest(data=True))
    assert isinstance(response, SetBoolResponse) and response.success
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[23.24, 23.24]))
    h.update()
    assert _cmds(h) == pytest.approx([1.1 + 11.62, 2.2 + 11.62])


def test_fast_mode_after_slow_mode_uses_full_displacement():
    h = _active()
    h.bus.call_service(f"/{NAME}/set_slow_control_mode", SetBoolRequest(data=True))
    h.bus.call_service(f"/{NAME}/set_slow_control_mode", SetBoolRequest(data=False))
    assert not h.controller.slow_mode
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[23.24, 0.0]))
    h.update()
    assert h.value("joint1/position") == pytest.approx(24.34)


def test_state_topic_reports_first_joint():
    h = _active()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.4, 0.0]))
    h.update()
    msg = h.latest("~/state")
    assert isinstance(msg, JointControllerState)
    assert msg.header.frame_id == "joint1"
    assert msg.header.stamp == pytest.approx(0.01)
    assert msg.set_point == pytest.approx(1.5)
    assert msg.process_value == 1.1


def test_deactivate_sets_commands_to_nan():
    h = _active()
    h.publish("~/reference", JointJog(joint_names=["joint1"], displacements=[0.4]))
    h.update()
    h.deactivate()
    assert all(math.isnan(v) for v in _cmds(h))


def test_message_before_activation_is_forgotten():
    h = _harness()
    h.configure()
    h.publish("~/reference", JointJog(joint_names=["joint1"], displacements=[0.4]))
    h.activate()
    h.update()
    assert h.value("joint1/position") == 0.0


def test_state_joints_are_read_instead_of_joints():
    h = _active({"joints": ["joint1"], "state_joints": ["joint1state"], "interface_name": "acceleration"},
                states={"joint1state/acceleration": 1.1}, commands={"joint1/acceleration": 0.0})
    assert h.controller.state_interface_configuration().names == ["joint1state/acceleration"]
    h.publish("~/reference", JointJog(joint_names=["joint1"], displacements=[23.24]))
    h.update()
    assert h.value("joint1/acceleration") == pytest.approx(24.34)


def test_state_joints_size_mismatch_fails_configure(caplog):
    h = _harness({"joints": ["joint1", "joint2"], "state_joints": ["s1"], "interface_name": "position"})
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "'state_joints' has 1 entries" in caplog.text and "'joints' has 2" in caplog.text


def test_empty_joints_rejected():
    with pytest.raises(ParameterError, match="'joints'.*must not be empty"):
        _harness({"joints": [], "interface_name": "position"})


def test_repeated_joints_rejected():
    with pytest.raises(ParameterError, match="'joints'.*unique"):
        _harness({"joints": ["joint1", "joint1"], "interface_name": "position"})


def test_repeated_state_joints_rejected():
    with pytest.raises(ParameterError, match="'state_joints'.*unique"):
        _harness({"joints": ["a", "b"], "state_joints": ["s", "s"], "interface_name": "position"})


def test_missing_interface_name_rejected():
    with pytest.raises(ParameterError, match="'interface_name'.*must not be empty"):
        _harness({"joints": ["joint1"]})


def test_interface_name_not_in_list_rejected():
    with pytest.raises(ParameterError, match="'interface_name'.*must be one of"):
        _harness({"joints": ["joint1"], "interface_name": "torque"})


def test_blup_prefix_rejected_by_custom_validator():
    with pytest.raises(ParameterError, match="forbidden prefix 'blup_'"):
        _harness({"joints": ["joint1"], "interface_name": "blup_position"})


def test_forbidden_prefix_validator_function():
    assert forbidden_interface_name_prefix("position") is None
    assert "blup_" in forbidden_interface_name_prefix("blup_x")
    assert forbidden_interface_name_prefix("abc_x", "abc_") is not None


def test_plugin_names_resolve():
    """The library's own name is pinned to this class; the original's two names follow the course track (the
    learner's task-8 class when it is finished, else UnfinishedExercise naming task 8)."""
    assert plugins.resolve("controller", "rrbot_workshop/DisplacementController") is DisplacementController
    for name in ("displacement_controller/DisplacementController", "controlko_controllers/DisplacementController"):
        try:
            assert plugins.resolve("controller", name).__name__ == "DisplacementController"
        except UnfinishedExercise as exc:
            assert exc.task == 8 and "your task 8 class DisplacementController" in str(exc)
