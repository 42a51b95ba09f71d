"""Tests for gpio_controllers/GpioCommandController (Jazzy parameters)."""

from __future__ import annotations

import logging

import pytest

from rrbot_workshop.controller_interface.base import ReturnType
from rrbot_workshop.controllers.gpio_command import GpioCommandController, urdf_gpio_state_interfaces
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import DynamicInterfaceGroupValues, InterfaceValue
from rrbot_workshop.testing import ControllerHarness

PARAMS = {
    "gpios": ["gpio1", "gpio2"],
    "command_interfaces": {"gpio1": {"interfaces": ["dig.1", "dig.2"]}, "gpio2": {"interfaces": ["ana.1"]}},
    "state_interfaces": {"gpio1": {"interfaces": ["dig.1", "dig.2"]}, "gpio2": {"interfaces": ["ana.1"]}},
}
VALUES = {"gpio1/dig.1": 1.0, "gpio1/dig.2": 0.0, "gpio2/ana.1": 3.1}

URDF = """<robot name="r"><link name="l"/>
  <ros2_control name="io" type="system">
    <gpio name="gpio1"><command_interface name="dig.1"/><state_interface name="dig.1"/>
      <state_interface name="dig.2"/></gpio>
  </ros2_control></robot>"""


def _harness(params=PARAMS, urdf="") -> ControllerHarness:
    return ControllerHarness(GpioCommandController(), "gpio_command_controller", params,
                             state_values=VALUES, command_values=dict(VALUES), robot_description=urdf)


def _active(params=PARAMS, urdf="") -> ControllerHarness:
    h = _harness(params, urdf)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    return h


def _cmd(groups: dict[str, dict[str, float]]) -> DynamicInterfaceGroupValues:
    return DynamicInterfaceGroupValues(
        interface_groups=list(groups),
        interface_values=[InterfaceValue(list(v), list(v.values())) for v in groups.values()])


def _commands(h):
    return [h.commands[n].get_value() for n in VALUES]


def test_interface_configuration_from_parameters():
    h = _harness()
    h.configure()
    assert h.controller.command_interface_configuration().names == list(VALUES)
    assert h.controller.state_interface_configuration().names == list(VALUES)


def test_command_message_is_written():
    h = _active()
    h.publish("~/commands", _cmd({"gpio1": {"dig.1": 0.0, "dig.2": 1.0}, "gpio2": {"ana.1": 30.0}}))
    h.update()
    assert _commands(h) == [0.0, 1.0, 30.0]


def test_partial_command_writes_only_named_interfaces():
    h = _active()
    h.publish("~/commands", _cmd({"gpio2": {"ana.1": 7.0}}))
    h.update()
    assert _commands(h) == [1.0, 0.0, 7.0]


def test_no_write_before_a_message():
    h = _active()
    h.update()
    assert _commands(h) == [1.0, 0.0, 3.1]


def test_states_published_per_gpio():
    h = _active()
    h.update()
    msg = h.latest("~/gpio_states")
    assert isinstance(msg, DynamicInterfaceGroupValues)
    assert msg.interface_groups == ["gpio1", "gpio2"]
    assert msg.interface_values[0].interface_names == ["dig.1", "dig.2"]
    assert msg.interface_values[0].values == [1.0, 0.0]
    assert msg.interface_values[1].values == [3.1]
    assert msg.header.stamp == pytest.approx(0.01)


def test_names_values_mismatch_makes_update_return_error_with_reason(caplog):
    """Jazzy (gpio_command_controller.cpp): a malformed command makes update() return ERROR; nothing is written."""
    h = _active()
    bad = DynamicInterfaceGroupValues(interface_groups=["gpio1"],
                                      interface_values=[InterfaceValue(["dig.1", "dig.2"], [1.0])])
    h.publish("~/commands", bad)
    with caplog.at_level(logging.ERROR):
        assert h.update() is ReturnType.ERROR
    assert _commands(h) == [1.0, 0.0, 3.1]
    assert "GPIO 'gpio1' has 2 entries in 'interface_names' but 1 in 'values'" in caplog.text


def test_groups_values_mismatch_makes_update_return_error(caplog):
    h = _active()
    h.publish("~/commands", DynamicInterfaceGroupValues(interface_groups=["gpio1", "gpio2"], interface_values=[]))
    with caplog.at_level(logging.ERROR):
        assert h.update() is ReturnType.ERROR
    assert "has 2 entries in 'interface_groups' but 0 in 'interface_values'" in caplog.text


def test_unknown_interface_skipped_with_warning(caplog):
    h = _active()
    with caplog.at_level(logging.WARNING):
        h.publish("~/commands", _cmd({"gpio1": {"dig.9": 5.0, "dig.1": 0.0}}))
    h.update()
    assert _commands(h) == [0.0, 0.0, 3.1]
    assert "'gpio1/dig.9'" in caplog.text


def test_deactivate_forgets_command():
    h = _active()
    h.publish("~/commands", _cmd({"gpio2": {"ana.1": 7.0}}))
    h.update()
    h.deactivate()
    h.set("gpio2/ana.1", 0.5)
    h.commands["gpio2/ana.1"].set_value(0.5)
    h.activate()
    h.update()
    assert h.commands["gpio2/ana.1"].get_value() == 0.5


def test_empty_state_interfaces_taken_from_description():
    params = {"gpios": ["gpio1"], "command_interfaces": {"gpio1": {"interfaces": ["dig.1"]}}}
    h = _active(params, urdf=URDF)
    assert h.controller.state_interface_configuration().names == ["gpio1/dig.1", "gpio1/dig.2"]
    h.update()
    assert h.latest("~/gpio_states").interface_values[0].values == [1.0, 0.0]


def test_state_only_controller_has_no_command_interfaces():
    h = _active({"gpios": ["gpio2"], "state_interfaces": {"gpio2": {"interfaces": ["ana.1"]}}})
    assert h.controller.command_interface_configuration().names == []
    h.update()
    assert h.latest("~/gpio_states").interface_values[0].values == [3.1]


def test_no_interfaces_at_all_fails_configure(caplog):
    h = _harness({"gpios": ["gpio1"]})
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "no interfaces" in caplog.text


def test_empty_gpios_rejected_at_load():
    with pytest.raises(ParameterError, match="'gpios'"):
        _harness({"gpios": []})


def test_repeated_interfaces_rejected_at_load():
    with pytest.raises(ParameterError, match=r"command_interfaces\.gpio1\.interfaces"):
        _harness({"gpios": ["gpio1"], "command_interfaces": {"gpio1": {"interfaces": ["a", "a"]}}})


def test_urdf_gpio_state_interfaces_parser():
    assert urdf_gpio_state_interfaces(URDF) == {"gpio1": ["dig.1", "dig.2"]}
    assert urdf_gpio_state_interfaces("") == {}
    assert urdf_gpio_state_interfaces("<robot") == {}


def test_plugin_name_resolves():
    assert plugins.resolve("controller", "gpio_controllers/GpioCommandController") is GpioCommandController
