"""Configuring a controller with bad parameters, or bringing up one that fails, gives errors that name it."""

from __future__ import annotations

import pytest

import rrbot_workshop as rw


def _controllers(fpc_params: dict) -> dict:
    return {
        "controller_manager": {
            "ros__parameters": {
                "update_rate": 100,
                "forward_position_controller": {"type": "forward_command_controller/ForwardCommandController"},
            }
        },
        "forward_position_controller": {"ros__parameters": fpc_params},
    }


def test_load_with_invalid_parameter_raises_parameter_error_naming_it() -> None:
    """An empty 'joints' list fails validation when the controller is loaded, as generate_parameter_library does."""
    system = rw.bringup("rrbot", _controllers({"joints": [], "interface_name": "position"}))
    try:
        with pytest.raises(rw.ParameterError) as info:
            system.controller_manager.load_controller("forward_position_controller")
        assert info.value.parameter == "joints"
        assert "forward_position_controller" in str(info.value)
        assert system.controller_manager.list_controllers() == []
    finally:
        system.shutdown()


def test_configure_after_a_bad_parameter_change_raises_and_stays_unconfigured() -> None:
    """A parameter set wrong between load and configure (like ``ros2 param set``) fails configure, naming it."""
    system = rw.bringup("rrbot", _controllers({"joints": ["joint1"], "interface_name": "position"}))
    try:
        cm = system.controller_manager
        ctrl = cm.load_controller("forward_position_controller")
        ctrl.get_node().set_parameters({"interface_name": ""})
        with pytest.raises(rw.ParameterError) as info:
            cm.configure_controller("forward_position_controller")
        assert info.value.parameter == "interface_name"
        states = {c.name: c.state for c in cm.list_controllers()}
        assert states["forward_position_controller"] == "unconfigured"
    finally:
        system.shutdown()


def test_bringup_of_a_controller_claiming_a_missing_interface_raises() -> None:
    """Spawning a controller whose command interface does not exist fails and names the interface."""
    with pytest.raises(rw.RRBotWorkshopError) as info:
        rw.bringup("rrbot", _controllers({"joints": ["joint7"], "interface_name": "position"}),
                   spawn=["forward_position_controller"])
    assert "joint7/position" in str(info.value)
