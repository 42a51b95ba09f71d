"""A hardware component's reason for refusing a mode switch reaches the learner in the SwitchError."""

from __future__ import annotations

import pytest

import rrbot_workshop as rw

CONTROLLERS = {
    "controller_manager": {
        "ros__parameters": {
            "update_rate": 100,
            "position_controller": {"type": "position_controllers/JointGroupPositionController"},
            "velocity_controller": {"type": "velocity_controllers/JointGroupVelocityController"},
        }
    },
    "position_controller": {"ros__parameters": {"joints": ["joint1"]}},
    "velocity_controller": {"ros__parameters": {"joints": ["joint1"]}},
}


def test_two_control_modes_on_one_joint_are_rejected_with_the_reason() -> None:
    """GenericSystem with dynamics refuses position and velocity on joint1 at once, and says why."""
    system = rw.bringup("rrbot", CONTROLLERS, xacro_args={"calculate_dynamics": True},
                        inactive=["position_controller", "velocity_controller"])
    try:
        cm = system.controller_manager
        with pytest.raises(rw.SwitchError) as info:
            cm.switch_controllers(activate=["position_controller", "velocity_controller"])
        assert "joint 'joint1' got 2 control modes at once" in str(info.value)
        states = {c.name: c.state for c in cm.list_controllers()}
        assert states == {"position_controller": "inactive", "velocity_controller": "inactive"}
    finally:
        system.shutdown()
