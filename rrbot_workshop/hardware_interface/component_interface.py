"""Base classes every hardware component derives from: System, Actuator, Sensor.

A component is written like a ros2_control hardware interface: ``on_init(info)`` checks the
description, lifecycle callbacks (``on_configure``, ``on_activate``, ...) open and close the device,
``read`` fills state interfaces, ``write`` sends command interfaces. As in ROS 2 Jazzy, the base class
creates one handle per interface declared in the ``<ros2_control>`` tag, and the component reaches
them with ``get_state`` / ``set_state`` / ``get_command`` / ``set_command`` by full name
(``"joint1/position"``). A component that needs other handles overrides
``export_state_interfaces`` / ``export_command_interfaces``.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo
from rrbot_workshop.hardware_interface.handles import CommandInterface, Handle, StateInterface, parse_value
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["HardwareComponentInterface", "SystemInterface", "ActuatorInterface", "SensorInterface"]


class HardwareComponentInterface:
    """Common base of hardware components. Subclass :class:`SystemInterface`, not this.

    Attributes:
        info: The parsed ``<ros2_control>`` description, set by :meth:`on_init`.
        logger: Logger named after the component.
    """

    #: ``"system"``, ``"actuator"`` or ``"sensor"``; set by the subclasses below.
    component_type: str = ""

    def __init__(self) -> None:
        self.info: HardwareInfo = HardwareInfo(name="", type=self.component_type)
        self.logger = logging.getLogger(f"rrbot_workshop.hardware.{type(self).__name__}")
        self._lifecycle_state: State = State.UNKNOWN
        self._state_handles: dict[str, StateInterface] = {}
        self._command_handles: dict[str, CommandInterface] = {}
        #: Why the last ``prepare_command_mode_switch`` returned ERROR; the controller manager shows it to the
        #: user in the switch error. Set it before returning ERROR.
        self.mode_switch_rejection: str = ""

    # ----------------------------------------------------------------- identity
    def get_name(self) -> str:
        """Component name, the ``name`` of its ``<ros2_control>`` tag."""
        return self.info.name

    def get_group_name(self) -> str:
        """``<hardware><group>`` name, or ``""``."""
        return self.info.group

    def get_lifecycle_state(self) -> State:
        """Current lifecycle state (maintained by the resource manager)."""
        return self._lifecycle_state

    # ----------------------------------------------------------------- lifecycle callbacks
    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Store the description. Override to validate it; call ``super().on_init(info)`` first.

        Args:
            info: Parsed ``<ros2_control>`` tag of this component.
        """
        self.info = info
        self.logger = logging.getLogger(f"rrbot_workshop.hardware.{info.name or type(self).__name__}")
        return CallbackReturn.SUCCESS

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Open communication, set initial values. Default: success."""
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Undo ``on_configure``. Default: success."""
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Enable the device (e.g. power the motors). Default: success."""
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Disable the device. Default: success."""
        return CallbackReturn.SUCCESS

    def on_shutdown(self, previous_state: State) -> CallbackReturn:
        """Release everything before the component is destroyed. Default: success."""
        return CallbackReturn.SUCCESS

    def on_error(self, previous_state: State) -> CallbackReturn:
        """Recover after ``read``/``write`` or a transition failed.

        Returning SUCCESS brings the component back to ``unconfigured`` (it can be configured and activated again);
        anything else finalizes it. The default is rclcpp_lifecycle's ``LifecycleNodeInterface::on_error``: SUCCESS.
        """
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- interfaces
    def _make_handles(self, components: Sequence[ComponentInfo], kind: str) -> list[Handle]:
        cls = StateInterface if kind == "state" else CommandInterface
        out: list[Handle] = []
        for comp in components:
            itfs = comp.state_interfaces if kind == "state" else comp.command_interfaces
            for itf in itfs:
                value = parse_value(itf.initial_value, itf.data_type, where=f"{comp.name}/{itf.name}")
                out.append(cls(comp.name, itf.name, itf.data_type, value))
        return out

    def export_state_interfaces(self) -> list[StateInterface]:
        """State interfaces of this component. Default: one per declared ``<state_interface>``."""
        handles = self._make_handles([*self.info.joints, *self.info.sensors, *self.info.gpios], "state")
        return [h for h in handles if isinstance(h, StateInterface)]

    def export_command_interfaces(self) -> list[CommandInterface]:
        """Command interfaces of this component. Default: one per declared ``<command_interface>``."""
        handles = self._make_handles([*self.info.joints, *self.info.gpios], "command")
        return [h for h in handles if isinstance(h, CommandInterface)]

    def _register_handles(self, states: Sequence[StateInterface], commands: Sequence[CommandInterface]) -> None:
        """Called by the resource manager with the exported handles, so get/set by name work."""
        self._state_handles = {h.name: h for h in states}
        self._command_handles = {h.name: h for h in commands}

    def get_state(self, name: str) -> Any:
        """Value of the state interface ``name`` (``"joint1/position"``)."""
        return self._state_handles[name].get_value()

    def set_state(self, name: str, value: Any) -> None:
        """Set the state interface ``name``."""
        self._state_handles[name].set_value(value)

    def get_command(self, name: str) -> Any:
        """Value of the command interface ``name``."""
        return self._command_handles[name].get_value()

    def set_command(self, name: str, value: Any) -> None:
        """Set the command interface ``name`` (e.g. to seed it from the state on activation)."""
        self._command_handles[name].set_value(value)

    @property
    def state_interface_names(self) -> list[str]:
        """Names of the exported state interfaces, in export order."""
        return list(self._state_handles)

    @property
    def command_interface_names(self) -> list[str]:
        """Names of the exported command interfaces, in export order."""
        return list(self._command_handles)

    # ----------------------------------------------------------------- mode switching
    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Check that the new set of claimed command interfaces is possible. Default: OK.

        Args:
            start_interfaces: Command interfaces of this component about to be claimed.
            stop_interfaces: Command interfaces of this component about to be released.
        """
        return ReturnType.OK

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Switch the device to the new mode (real-time side). Default: OK."""
        return ReturnType.OK

    # ----------------------------------------------------------------- cyclic
    def read(self, time: float, period: float) -> ReturnType:
        """Fill the state interfaces from the device.

        Args:
            time: Current time in [s].
            period: Time since the last read in [s].
        """
        raise NotImplementedError(f"{type(self).__name__}.read() is not implemented")

    def write(self, time: float, period: float) -> ReturnType:
        """Send the command interfaces to the device.

        Args:
            time: Current time in [s].
            period: Time since the last write in [s].
        """
        raise NotImplementedError(f"{type(self).__name__}.write() is not implemented")


class SystemInterface(HardwareComponentInterface):
    """A multi-joint device that reads and writes (a robot arm, a mobile base)."""

    component_type = "system"


class ActuatorInterface(HardwareComponentInterface):
    """A single-joint device (one motor)."""

    component_type = "actuator"


class SensorInterface(HardwareComponentInterface):
    """A read-only device (a force-torque sensor, an IMU). Sensors never write."""

    component_type = "sensor"

    def export_command_interfaces(self) -> list[CommandInterface]:
        """Sensors have no command interfaces."""
        return []

    def write(self, time: float, period: float) -> ReturnType:
        """Sensors do not write; always OK."""
        return ReturnType.OK
