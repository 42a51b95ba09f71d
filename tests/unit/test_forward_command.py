"""Tests for forward_command_controller and the joint group aliases."""

from __future__ import annotations

import logging
import math

import pytest

from rrbot_workshop.controllers.forward_command import (
    ForwardCommandController,
    JointGroupEffortController,
    JointGroupPositionController,
    JointGroupVelocityController,
    MultiInterfaceForwardCommandController,
)
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.msgs import Float64MultiArray
from rrbot_workshop.testing import ControllerHarness

CMDS = {"joint1/position": 1.1, "joint2/position": 2.1, "joint3/position": 3.1}
NAMES = list(CMDS)


def _active(params: dict | None = None, cls: type = ForwardCommandController) -> ControllerHarness:
    h = ControllerHarness(
        cls(), "fwd", params or {"joints": ["joint1", "joint2", "joint3"], "interface_name": "position"},
        command_values=CMDS,
    )
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    return h


def test_command_interfaces_are_joint_slash_interface_name():
    h = _active()
    assert h.controller.command_interface_types == NAMES


def test_no_write_before_any_message():
    """The buffer is NaN after activation, so the hardware keeps its values."""
    h = _active()
    assert h.update() is ReturnType.OK
    assert h.values(NAMES) == [1.1, 2.1, 3.1]


def test_message_is_written_in_joint_order():
    h = _active()
    h.publish("~/commands", Float64MultiArray(data=[10.0, 20.0, 30.0]))
    h.update()
    assert h.values(NAMES) == [10.0, 20.0, 30.0]


def test_last_command_is_written_every_cycle():
    h = _active()
    h.publish("~/commands", Float64MultiArray(data=[10.0, 20.0, 30.0]))
    h.update()
    h.set("joint1/position", -5.0)
    h.update()
    assert h.value("joint1/position") == 10.0


def test_size_mismatch_makes_update_return_error_with_sizes_logged(caplog):
    """Jazzy (forward_controllers_base.cpp): the wrong-size command is stored; update() logs and returns ERROR."""
    h = _active()
    h.publish("~/commands", Float64MultiArray(data=[10.0, 20.0]))
    with caplog.at_level(logging.ERROR):
        assert h.update() is ReturnType.ERROR
    assert "has 2 values in field 'data', expected 3" in caplog.text
    assert h.values(NAMES) == [1.1, 2.1, 3.1]  # nothing written
    assert h.controller.rejected_messages == 1


def test_a_right_size_message_replaces_a_wrong_one_before_the_update():
    h = _active()
    h.publish("~/commands", Float64MultiArray(data=[1.0, 2.0, 3.0, 4.0]))
    h.publish("~/commands", Float64MultiArray(data=[10.0, 20.0, 30.0]))
    assert h.update() is ReturnType.OK
    assert h.values(NAMES) == [10.0, 20.0, 30.0]


def test_wrong_size_command_deactivates_the_controller_in_the_manager(caplog):
    """End to end on the mock RRBot: the controller manager deactivates the forward controller; the joints keep
    their last command; re-activated, it waits for a new command."""
    import rrbot_workshop as rw

    with rw.bringup("rrbot", "rrbot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                    spawn=["joint_state_broadcaster", "forward_position_controller"]) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, 0.4]))
        system.spin(0.05)
        with caplog.at_level(logging.ERROR):
            system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.7]))
            system.spin(0.05)
        states = {c.name: c.state for c in system.controller_manager.list_controllers()}
        assert states["forward_position_controller"] == "inactive"
        assert "has 1 values in field 'data', expected 2" in caplog.text
        assert list(system.latest("/joint_states").position) == [0.3, 0.4]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_message_is_dropped_with_reason(caplog, bad):
    h = _active()
    with caplog.at_level(logging.WARNING):
        h.publish("~/commands", Float64MultiArray(data=[10.0, bad, 30.0]))
    h.update()
    assert h.values(NAMES) == [1.1, 2.1, 3.1]
    assert "non-finite values at indices [1]" in caplog.text


def test_deactivate_resets_buffer_to_nan():
    """After deactivate + activate, the old command is not written again."""
    h = _active()
    h.publish("~/commands", Float64MultiArray(data=[10.0, 20.0, 30.0]))
    h.update()
    h.deactivate()
    h.set("joint1/position", 0.5)
    h.activate()
    h.update()
    assert h.value("joint1/position") == 0.5


def test_message_before_activation_is_discarded_on_activate():
    h = ControllerHarness(ForwardCommandController(), "fwd", {"joints": ["joint1"], "interface_name": "position"},
                          command_values={"joint1/position": 0.0})
    h.configure()
    h.publish("~/commands", Float64MultiArray(data=[3.0]))
    h.activate()
    h.update()
    assert h.value("joint1/position") == 0.0


def test_empty_joints_is_rejected_at_load():
    with pytest.raises(ParameterError, match="joints"):
        ControllerHarness(ForwardCommandController(), "fwd", {"joints": [], "interface_name": "position"})


def test_missing_interface_name_is_rejected_at_load():
    with pytest.raises(ParameterError, match="interface_name"):
        ControllerHarness(ForwardCommandController(), "fwd", {"joints": ["joint1"]})


def test_multi_interface_controller_commands_several_interfaces_of_one_joint():
    h = ControllerHarness(
        MultiInterfaceForwardCommandController(), "multi",
        {"joint": "joint1", "interface_names": ["position", "velocity"]},
        command_values={"joint1/position": 0.0, "joint1/velocity": 0.0},
    )
    h.configure()
    h.activate()
    h.publish("~/commands", Float64MultiArray(data=[1.0, 2.0]))
    h.update()
    assert h.values(["joint1/position", "joint1/velocity"]) == [1.0, 2.0]


def test_multi_interface_controller_requires_interface_names():
    with pytest.raises(ParameterError, match="interface_names"):
        ControllerHarness(MultiInterfaceForwardCommandController(), "multi", {"joint": "joint1"})


@pytest.mark.parametrize(
    ("cls", "interface"),
    [(JointGroupPositionController, "position"), (JointGroupVelocityController, "velocity"),
     (JointGroupEffortController, "effort")],
)
def test_joint_group_aliases_fix_the_interface(cls, interface):
    h = ControllerHarness(cls(), "grp", {"joints": ["joint1"]}, command_values={f"joint1/{interface}": 0.0})
    h.configure()
    assert h.controller.command_interface_types == [f"joint1/{interface}"]
    h.activate()
    h.publish("~/commands", Float64MultiArray(data=[0.25]))
    h.update()
    assert h.value(f"joint1/{interface}") == 0.25


def test_joint_group_alias_overrides_given_interface_name(caplog):
    with caplog.at_level(logging.WARNING):
        h = ControllerHarness(JointGroupVelocityController(), "grp", {"joints": ["joint1"], "interface_name": "effort"})
    h.configure()
    assert h.controller.command_interface_types == ["joint1/velocity"]
    assert "'interface_name' = 'effort' is ignored" in caplog.text


@pytest.mark.parametrize(
    ("type_name", "cls"),
    [
        ("forward_command_controller/ForwardCommandController", ForwardCommandController),
        ("forward_command_controller/MultiInterfaceForwardCommandController", MultiInterfaceForwardCommandController),
        ("position_controllers/JointGroupPositionController", JointGroupPositionController),
        ("velocity_controllers/JointGroupVelocityController", JointGroupVelocityController),
        ("effort_controllers/JointGroupEffortController", JointGroupEffortController),
    ],
)
def test_plugin_names_resolve(type_name, cls):
    assert plugins.resolve("controller", type_name) is cls
