"""``gpio_controllers/GpioCommandController``: write GPIO command interfaces, publish GPIO states.

Parameters as in Jazzy's ``gpio_controllers``::

    gpios: [flange_vacuum, flange_analog_IOs]
    command_interfaces:
      flange_vacuum: {interfaces: [vacuum]}
    state_interfaces:
      flange_analog_IOs: {interfaces: [analog_output1, analog_input1]}

A GPIO whose ``state_interfaces.<gpio>.interfaces`` is empty publishes every state interface that the
robot description's ``<gpio name="...">`` declares (none if there is no description).

Commands arrive on ``~/commands`` (``control_msgs/DynamicInterfaceGroupValues``: ``interface_groups`` are
GPIO names, ``interface_values[i]`` their interface names and values). The last accepted message is
written every cycle until the controller is deactivated. States are published on ``~/gpio_states``.

As in Jazzy, a message whose names and values do not pair up makes the next ``update`` log why and return ERROR,
so the controller manager deactivates the controller; entries naming an interface this controller does not command
are skipped with a logged warning.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import ClassVar

from rrbot_workshop.controller_interface.base import (
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import Publisher, Subscription
from rrbot_workshop.msgs import DynamicInterfaceGroupValues, Header, InterfaceValue

__all__ = ["GpioCommandController", "urdf_gpio_state_interfaces"]


def urdf_gpio_state_interfaces(urdf: str) -> dict[str, list[str]]:
    """State interface names of every ``<gpio>`` in the ``<ros2_control>`` tags of a URDF.

    Args:
        urdf: URDF text (may be empty).

    Returns:
        GPIO name -> state interface names in order; empty if the text cannot be parsed.
    """
    if not urdf.strip():
        return {}
    try:
        root = ET.fromstring(urdf)
    except ET.ParseError:
        return {}
    out: dict[str, list[str]] = {}
    for tag in root.iter("ros2_control"):
        for gpio in tag.findall("gpio"):
            name = gpio.get("name", "")
            out.setdefault(name, []).extend(s.get("name", "") for s in gpio.findall("state_interface"))
    return out


class GpioCommandController(ControllerInterface):
    """Forwards ``DynamicInterfaceGroupValues`` to GPIO command interfaces and publishes GPIO states."""

    PARAMETERS: ClassVar[str | None] = """
gpio_command_controller_parameters:
  gpios:
    type: string_array
    description: "GPIO names (the <gpio name=...> of the description)."
    read_only: true
    validation:
      size_gt<>: [0]
      unique<>: []
  command_interfaces:
    __map_gpios:
      interfaces:
        type: string_array
        default_value: []
        description: "Command interfaces of this GPIO."
        read_only: true
        validation:
          unique<>: []
  state_interfaces:
    __map_gpios:
      interfaces:
        type: string_array
        default_value: []
        description: "State interfaces of this GPIO; empty means all that the description declares."
        read_only: true
        validation:
          unique<>: []
"""

    def __init__(self) -> None:
        super().__init__()
        self.command_interface_types: list[str] = []
        self.state_interface_types: list[str] = []
        self._state_layout: list[tuple[str, list[str]]] = []
        self._command: dict[str, float] | None = None
        self._message_error: str | None = None  # set by a malformed message until the next update
        self._sub: Subscription | None = None
        self._pub: Publisher | None = None

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Collect command and state interface names; create the topics."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        from_urdf = urdf_gpio_state_interfaces(self.get_robot_description())
        self.command_interface_types = []
        self.state_interface_types = []
        self._state_layout = []
        for gpio in params.gpios:
            self.command_interface_types += [f"{gpio}/{i}" for i in params.command_interfaces.gpios_map[gpio].interfaces]
            states = list(params.state_interfaces.gpios_map[gpio].interfaces) or from_urdf.get(gpio, [])
            if states:
                self._state_layout.append((gpio, states))
                self.state_interface_types += [f"{gpio}/{i}" for i in states]
        if not self.command_interface_types and not self.state_interface_types:
            self.logger.error(
                "'%s': no interfaces: give 'command_interfaces.<gpio>.interfaces' or "
                "'state_interfaces.<gpio>.interfaces' for at least one of %s", self.get_name(), list(params.gpios))
            return CallbackReturn.FAILURE
        node = self.get_node()
        if self.command_interface_types and self._sub is None:
            self._sub = node.create_subscription(DynamicInterfaceGroupValues, "~/commands", self._on_commands)
        if self._pub is None:
            self._pub = node.create_publisher(DynamicInterfaceGroupValues, "~/gpio_states")
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription."""
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<gpio>/<interface>`` for each configured command interface."""
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, list(self.command_interface_types))

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<gpio>/<interface>`` for each configured (or described) state interface."""
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, list(self.state_interface_types))

    def _on_commands(self, msg: DynamicInterfaceGroupValues) -> None:
        name = self.get_name()
        if len(msg.interface_groups) != len(msg.interface_values):
            self._message_error = (
                f"'{name}': the message on ~/commands has {len(msg.interface_groups)} entries in 'interface_groups' "
                f"but {len(msg.interface_values)} in 'interface_values'; one list of values per GPIO is needed")
            return
        command: dict[str, float] = {}
        for gpio, group in zip(msg.interface_groups, msg.interface_values, strict=True):
            if len(group.interface_names) != len(group.values):
                self._message_error = (
                    f"'{name}': in the message on ~/commands, GPIO '{gpio}' has {len(group.interface_names)} entries in "
                    f"'interface_names' but {len(group.values)} in 'values'")
                return
            for itf, value in zip(group.interface_names, group.values, strict=True):
                full = f"{gpio}/{itf}"
                if full in self.command_interface_types:
                    command[full] = value
                else:
                    self.logger.warning(
                        "'%s': ~/commands names '%s', which this controller does not command (valid: %s); "
                        "that value is skipped", name, full, self.command_interface_types)
        self._message_error = None
        self._command = command

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Forget commands received before activation."""
        self._command = None
        self._message_error = None
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Forget the last command."""
        self._command = None
        self._message_error = None
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        """Publish the GPIO states, then write the last accepted command (ERROR after a malformed message)."""
        if self._pub is not None:
            msg = DynamicInterfaceGroupValues(header=Header(stamp=time))
            start = 0
            for gpio, itfs in self._state_layout:
                loans = self.state_interfaces[start:start + len(itfs)]
                start += len(itfs)
                values = [float(loan.get_value()) for loan in loans]
                msg.interface_groups.append(gpio)
                msg.interface_values.append(InterfaceValue(interface_names=list(itfs), values=values))
            self._pub.publish(msg)
        if self._message_error is not None:
            self.logger.error("%s; update() returns ERROR", self._message_error)
            return ReturnType.ERROR
        if self._command:
            for loan in self.command_interfaces:
                if loan.name in self._command:
                    loan.set_value(self._command[loan.name])
        return ReturnType.OK
