"""``passthrough_controller/PassthroughController``: the smallest chainable controller.

It owns one command interface per entry of its parameter ``interfaces`` (full names such as ``joint1/position``,
or another controller's reference interface such as ``joint1_position_controller/joint1/position``) and exports
one reference interface per entry, named ``<controller name>/<entry>``. Each cycle it copies every reference that
is not NaN to the command interface of the same index; nothing else.

* **Chained** (a preceding controller claims its references): the preceding controller writes the references
  earlier in the same cycle.
* **Not chained**: the references come from ``~/commands`` (``std_msgs/Float64MultiArray``, one value per entry of
  ``interfaces``). A message of the wrong size is dropped with an error; the last complete, finite message is
  written every cycle until another arrives. Activation and deactivation clear it (NaN: nothing is written).

This is the controller of ros2_control_demos' example 12, where two levels of it sit between a forward command
controller and the hardware. It is registered under that example's name and as
``rrbot_workshop/PassthroughController``.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.hardware_interface.handles import CommandInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import Subscription
from rrbot_workshop.msgs import Float64MultiArray

__all__ = ["PassthroughController", "PASSTHROUGH_CONTROLLER_PARAMETERS"]

#: generate_parameter_library YAML of :class:`PassthroughController` (example 12's declaration, our wording).
PASSTHROUGH_CONTROLLER_PARAMETERS = """
passthrough_controller:
  interfaces:
    type: string_array
    default_value: []
    description: "Full names of the interfaces to forward: each is a command interface and, prefixed with the
      controller name, an exported reference interface."
    validation:
      not_empty<>: []
      unique<>: []
"""


class PassthroughController(ChainableControllerInterface):
    """Copies each reference interface to the command interface of the same index.

    Attributes:
        interface_names: The ``interfaces`` parameter as read at configure: command interface names, and the
            reference interface names without the ``<controller name>/`` prefix.
    """

    PARAMETERS: ClassVar[str | None] = PASSTHROUGH_CONTROLLER_PARAMETERS

    def __init__(self) -> None:
        super().__init__()
        self.interface_names: list[str] = []
        self._command: list[float] = []  # the latest complete message from ~/commands (NaN: none)
        self._subscription: Subscription | None = None

    # ----------------------------------------------------------------- configuration
    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read ``interfaces`` and subscribe to ``~/commands``."""
        assert self.param_listener is not None
        self.interface_names = list(self.param_listener.get_params().interfaces)
        self._command = [math.nan] * len(self.interface_names)
        if self._subscription is None:
            self._subscription = self.get_node().create_subscription(Float64MultiArray, "~/commands", self._on_commands)
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription."""
        if self._subscription is not None:
            self._subscription.destroy()
            self._subscription = None
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """Every entry of ``interfaces``, individually."""
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, list(self.interface_names))

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """None: a pass-through reads no state."""
        return InterfaceConfiguration(InterfaceConfigurationType.NONE)

    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        """``<controller name>/<entry>`` for each entry of ``interfaces``, NaN until written."""
        name = self.get_name()
        return [CommandInterface(name, itf, initial_value=math.nan) for itf in self.interface_names]

    def on_set_chained_mode(self, chained_mode: bool) -> bool:
        """Any mode is fine: in both the references are simply copied."""
        return True

    # ----------------------------------------------------------------- lifecycle
    def _clear(self) -> None:
        self._command = [math.nan] * len(self.interface_names)
        for ref in self.reference_interfaces:
            ref.set_value(math.nan)

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Forget commands received while inactive: nothing is written until a new one comes."""
        self._clear()
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Forget the last command."""
        self._clear()
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- topic (non-real-time side)
    def _on_commands(self, msg: Float64MultiArray) -> None:
        expected = len(self.interface_names)
        if len(msg.data) != expected:
            self.logger.error(
                "'%s': dropped a command on ~/commands: field 'data' has %d values, expected %d (one per entry of "
                "parameter 'interfaces': %s)", self.get_name(), len(msg.data), expected, self.interface_names)
            return
        self._command = [_as_float(v) for v in msg.data]

    # ----------------------------------------------------------------- cycle
    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """Not chained: the last message becomes the references, if all its values are finite."""
        command = self._command
        if command and all(math.isfinite(v) for v in command):
            for ref, value in zip(self.reference_interfaces, command):  # noqa: B905 - same length by construction
                ref.set_value(value)
        return ReturnType.OK

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Copy every reference that is not NaN to its command interface."""
        for ref, cmd in zip(self.reference_interfaces, self.command_interfaces):  # noqa: B905
            value = ref.get_value()
            if not math.isnan(value):
                cmd.set_value(value)
        return ReturnType.OK


def _as_float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan
