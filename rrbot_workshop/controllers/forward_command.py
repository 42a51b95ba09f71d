"""``forward_command_controller``: write the numbers of a ``Float64MultiArray`` straight to command interfaces.

Two controllers and three aliases, as in ros2_controllers (Jazzy):

* ``ForwardCommandController``: parameters ``joints`` and ``interface_name``; one command interface per
  joint, ``<joint>/<interface_name>``;
* ``MultiInterfaceForwardCommandController``: parameters ``joint`` and ``interface_names``; several
  interfaces of one joint;
* ``JointGroupPositionController`` / ``JointGroupVelocityController`` / ``JointGroupEffortController``
  (packages ``position_controllers``, ``velocity_controllers``, ``effort_controllers``): a
  ``ForwardCommandController`` whose ``interface_name`` is fixed.

Commands arrive on ``~/commands``. The buffer starts as NaN on activation and deactivation; while every
entry is NaN nothing is written.

A message of the wrong size is kept as the latest command, as in Jazzy: the next ``update`` logs the expected and
received sizes and returns ERROR, so the controller manager deactivates the controller (a later message of the
right size, before that update, replaces it). Messages with non-finite values are dropped.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import ClassVar

from rrbot_workshop.controller_interface.base import (
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.hardware_interface.handles import value_writer
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import Subscription
from rrbot_workshop.msgs import Float64MultiArray

__all__ = [
    "ForwardControllersBase",
    "ForwardCommandController",
    "MultiInterfaceForwardCommandController",
    "JointGroupPositionController",
    "JointGroupVelocityController",
    "JointGroupEffortController",
]


class ForwardControllersBase(ControllerInterface):
    """Shared logic: subscription, NaN buffer, writing. Subclasses fill :attr:`command_interface_types`.

    Attributes:
        command_interface_types: Full names of the command interfaces, in the order of the array.
        rejected_messages: Number of messages dropped (wrong size or non-finite values).
    """

    def __init__(self) -> None:
        super().__init__()
        self.command_interface_types: list[str] = []
        self.rejected_messages = 0
        self._command: list[float] = []
        self._received = False  # a valid command arrived since activation
        self._write: Callable[[Sequence[float]], None] = _write_nothing
        self._size_error: str | None = None  # set by a wrong-size message until the next update
        self._subscription: Subscription | None = None

    def read_parameters(self) -> bool:
        """Fill :attr:`command_interface_types` from the parameters; False (logged) if they are unusable."""
        raise NotImplementedError

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """The configured command interfaces, individually."""
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, list(self.command_interface_types))

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """No state interfaces."""
        return InterfaceConfiguration(InterfaceConfigurationType.NONE)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters and subscribe to ``~/commands``."""
        if not self.read_parameters():
            return CallbackReturn.FAILURE
        self._command = [math.nan] * len(self.command_interface_types)
        if self._subscription is None:
            self._subscription = self.get_node().create_subscription(
                Float64MultiArray, "~/commands", self._on_commands
            )
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription."""
        if self._subscription is not None:
            self._subscription.destroy()
            self._subscription = None
        return CallbackReturn.SUCCESS

    def _on_commands(self, msg: Float64MultiArray) -> None:
        expected = len(self.command_interface_types)
        if len(msg.data) != expected:
            self.rejected_messages += 1
            self._size_error = (
                f"'{self.get_name()}': the command on ~/commands has {len(msg.data)} values in field 'data', "
                f"expected {expected} (one per interface in {self.command_interface_types}); update() returns "
                "ERROR and the controller manager deactivates this controller"
            )
            return
        self._size_error = None
        bad = [i for i, v in enumerate(msg.data) if not _is_finite(v)]
        if bad:
            self.rejected_messages += 1
            self.logger.warning(
                "'%s': dropped a command on ~/commands: field 'data' has non-finite values at indices %s (%s)",
                self.get_name(), bad, [msg.data[i] for i in bad],
            )
            return
        self._command = [float(v) for v in msg.data]
        self._received = True

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Start from an empty (NaN) command: nothing is written until a message arrives."""
        self._command = [math.nan] * len(self.command_interface_types)
        self._received = False
        self._size_error = None
        self._write = value_writer(self.command_interfaces)  # the loans, in the order of the data array
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Forget the last command."""
        self._command = [math.nan] * len(self.command_interface_types)
        self._received = False
        self._size_error = None
        self._write = _write_nothing
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        """Write the latest command, unless none has arrived since activation; ERROR if it had the wrong size."""
        if self._size_error is not None:
            self.logger.error("%s", self._size_error)
            return ReturnType.ERROR
        if self._received:  # nothing is written before the first valid command
            self._write(self._command)
        return ReturnType.OK


def _write_nothing(values: object) -> None:
    """The writer of an inactive controller."""


def _is_finite(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


class ForwardCommandController(ForwardControllersBase):
    """One command interface per joint: ``<joint>/<interface_name>``."""

    PARAMETERS: ClassVar[str | None] = """
forward_command_controller:
  joints:
    type: string_array
    default_value: []
    description: "Joints to command, in the order of the data array."
    validation:
      not_empty<>: []
  interface_name:
    type: string
    default_value: ""
    description: "Command interface written on every joint."
    validation:
      not_empty<>: []
"""

    def read_parameters(self) -> bool:
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        self.command_interface_types = [f"{j}/{params.interface_name}" for j in params.joints]
        return True


class MultiInterfaceForwardCommandController(ForwardControllersBase):
    """Several command interfaces of one joint: ``<joint>/<interface_names[i]>``."""

    PARAMETERS: ClassVar[str | None] = """
multi_interface_forward_command_controller:
  joint:
    type: string
    default_value: ""
    description: "The joint to command."
    validation:
      not_empty<>: []
  interface_names:
    type: string_array
    default_value: []
    description: "Command interfaces of the joint, in the order of the data array."
    validation:
      not_empty<>: []
"""

    def read_parameters(self) -> bool:
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        self.command_interface_types = [f"{params.joint}/{i}" for i in params.interface_names]
        return True


def _group_parameters(interface: str) -> str:
    return f"""
forward_command_controller:
  joints:
    type: string_array
    default_value: []
    description: "Joints to command, in the order of the data array."
    validation:
      not_empty<>: []
  interface_name:
    type: string
    default_value: "{interface}"
    description: "Fixed to '{interface}' by this controller type."
"""


class _JointGroupController(ForwardCommandController):
    """A ``ForwardCommandController`` whose ``interface_name`` is fixed by the class."""

    INTERFACE: ClassVar[str] = ""

    def on_init(self) -> CallbackReturn:
        """Force ``interface_name`` (a value given in the YAML is overridden, as in ros2_controllers)."""
        node = self.get_node()
        given = node.get_parameter("interface_name")
        if given not in (None, self.INTERFACE):
            self.logger.warning(
                "'%s': parameter 'interface_name' = '%s' is ignored; %s always uses '%s'",
                self.get_name(), given, type(self).__name__, self.INTERFACE,
            )
        node.set_parameters({"interface_name": self.INTERFACE})
        return CallbackReturn.SUCCESS


class JointGroupPositionController(_JointGroupController):
    """``position_controllers/JointGroupPositionController``: forwards positions [rad or m]."""

    INTERFACE = "position"
    PARAMETERS = _group_parameters("position")


class JointGroupVelocityController(_JointGroupController):
    """``velocity_controllers/JointGroupVelocityController``: forwards velocities [rad/s or m/s]."""

    INTERFACE = "velocity"
    PARAMETERS = _group_parameters("velocity")


class JointGroupEffortController(_JointGroupController):
    """``effort_controllers/JointGroupEffortController``: forwards efforts [N m or N]."""

    INTERFACE = "effort"
    PARAMETERS = _group_parameters("effort")
