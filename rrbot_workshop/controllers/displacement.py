"""The task-8 controller: move joints by *displacements* (``control_msgs/JointJog``), each applied once.

Reference solution of the ROSCon 2022 workshop's ``controlko_controllers/DisplacementController``, with
the original's bugs fixed:

* displacements are matched to joints **by name** (the original assumed the message's order); as in the
  original, a message must carry one displacement per joint of the controller; unknown or repeated names
  reject the message, with the reason logged;
* the tests of the original expected ``command == displacement``; the behaviour kept here is the one
  its code implemented and its README described: ``command = current state + displacement``.

Parameters: ``joints`` (commanded), ``state_joints`` (read; default ``joints``; same size), and
``interface_name`` (``position``, ``velocity``, ``acceleration`` or ``effort``; the custom validator
``forbidden_interface_name_prefix`` rejects names starting with ``blup_``, as the workshop's example of a
hand-written generate_parameter_library validator).

Topics and services: ``~/reference`` (``JointJog``, displacements in the interface's units),
``~/set_slow_control_mode`` (``SetBool``: true halves every displacement), ``~/state``
(``JointControllerState`` of the first joint).
"""

from __future__ import annotations

import math
from typing import ClassVar

from rrbot_workshop.controller_interface.base import (
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.params import register_validator
from rrbot_workshop.middleware.topics import Publisher, Service, Subscription
from rrbot_workshop.msgs import Header, JointControllerState, JointJog, SetBoolRequest, SetBoolResponse

__all__ = ["DisplacementController", "forbidden_interface_name_prefix"]


def forbidden_interface_name_prefix(value: str, prefix: str = "blup_") -> str | None:
    """Custom parameter validator: reject interface names that start with ``prefix``.

    Args:
        value: The ``interface_name`` parameter.
        prefix: The forbidden prefix.

    Returns:
        None if the value is allowed, else the reason.
    """
    if value.startswith(prefix):
        return f"'{value}' starts with the forbidden prefix '{prefix}'; use a plain interface name such as 'position'"
    return None


# Registered under the library's own name: a learner's task-8 file registers its version as
# displacement_controller::forbidden_interface_name_prefix, and neither replaces the other.
register_validator("rrbot_workshop::forbidden_interface_name_prefix", forbidden_interface_name_prefix)


class DisplacementController(ControllerInterface):
    """Applies each received joint displacement once: ``command = state + displacement`` (halved in slow mode).

    Attributes:
        slow_mode: True after ``~/set_slow_control_mode`` was called with ``data=True``.
        displacements: Pending displacement per joint (NaN = none), in the order of ``joints``.
    """

    PARAMETERS: ClassVar[str | None] = """
displacement_controller:
  joints:
    type: string_array
    default_value: []
    description: "Joints to command."
    read_only: true
    validation:
      unique<>: []
      not_empty<>: []
  state_joints:
    type: string_array
    default_value: []
    description: "Joints whose state is read (default: 'joints'); for use behind a following controller."
    read_only: true
    validation:
      unique<>: []
  interface_name:
    type: string
    default_value: ""
    description: "Interface commanded and read on every joint."
    read_only: true
    validation:
      not_empty<>: []
      rrbot_workshop::forbidden_interface_name_prefix: ["blup_"]
      one_of<>: [["position", "velocity", "acceleration", "effort"]]
"""

    def __init__(self) -> None:
        super().__init__()
        self.slow_mode = False
        self.displacements: list[float] = []
        self._joints: list[str] = []
        self._state_joints: list[str] = []
        self._interface = ""
        self._sub: Subscription | None = None
        self._srv: Service | None = None
        self._pub: Publisher | None = None

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<joint>/<interface_name>`` for each joint."""
        return InterfaceConfiguration(
            InterfaceConfigurationType.INDIVIDUAL, [f"{j}/{self._interface}" for j in self._joints])

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<state_joint>/<interface_name>`` for each state joint."""
        return InterfaceConfiguration(
            InterfaceConfigurationType.INDIVIDUAL, [f"{j}/{self._interface}" for j in self._state_joints])

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters; create ``~/reference``, ``~/set_slow_control_mode`` and ``~/state``."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        self._joints = list(params.joints)
        self._state_joints = list(params.state_joints) or list(self._joints)
        if len(self._state_joints) != len(self._joints):
            self.logger.error(
                "'%s': parameter 'state_joints' has %d entries %s but 'joints' has %d %s; they must have the "
                "same size (or leave 'state_joints' empty to use 'joints')", self.get_name(),
                len(self._state_joints), self._state_joints, len(self._joints), self._joints,
            )
            return CallbackReturn.FAILURE
        self._interface = params.interface_name
        self.displacements = [math.nan] * len(self._joints)
        self.slow_mode = False
        node = self.get_node()
        if self._sub is None:
            self._sub = node.create_subscription(JointJog, "~/reference", self._on_reference)
        if self._srv is None:
            self._srv = node.create_service(SetBoolRequest, "~/set_slow_control_mode", self._on_set_slow_mode)
        if self._pub is None:
            self._pub = node.create_publisher(JointControllerState, "~/state")
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the subscription (the service and publisher live with the node)."""
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- non-real-time callbacks
    def _reject(self, why: str) -> None:
        self.logger.error("'%s': rejected a message on ~/reference: %s", self.get_name(), why)

    def _on_reference(self, msg: JointJog) -> None:
        names = list(msg.joint_names)
        values = list(msg.displacements)
        if not names:
            if len(values) != len(self._joints):
                self._reject(f"field 'joint_names' is empty and field 'displacements' has {len(values)} values; "
                             f"name the joints, or give one value per joint of {self._joints}")
                return
            self.logger.warning("'%s': JointJog without 'joint_names'; assuming the order %s",
                                self.get_name(), self._joints)
            names = list(self._joints)
        if len(values) != len(names):
            self._reject(f"field 'displacements' has {len(values)} values but field 'joint_names' has "
                         f"{len(names)} names; they must match")
            return
        if len(names) != len(self._joints):
            self._reject(f"it names {len(names)} joint(s) {names}, the controller has {len(self._joints)}: give one "
                         f"displacement for each of {self._joints} (0.0 for a joint that should stay)")
            return
        unknown = [n for n in names if n not in self._joints]
        if unknown:
            self._reject(f"field 'joint_names' has unknown joints {unknown} (valid: {self._joints})")
            return
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            self._reject(f"field 'joint_names' repeats {repeated}")
            return
        if any(math.isinf(v) for v in values):
            self._reject(f"field 'displacements' has infinite values {values}")
            return
        pending = [math.nan] * len(self._joints)
        for name, value in zip(names, values, strict=True):
            pending[self._joints.index(name)] = float(value)
        self.displacements = pending

    def _on_set_slow_mode(self, request: SetBoolRequest) -> SetBoolResponse:
        self.slow_mode = bool(request.data)
        mode = "slow (displacements halved)" if self.slow_mode else "fast"
        self.logger.info("'%s': control mode set to %s", self.get_name(), mode)
        return SetBoolResponse(success=True, message=f"control mode: {mode}")

    # ----------------------------------------------------------------- lifecycle and cycle
    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Forget displacements received before activation."""
        self.displacements = [math.nan] * len(self._joints)
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Command NaN, so the hardware holds nothing from this controller."""
        for loan in self.command_interfaces:
            loan.set_value(math.nan)
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        """Apply each pending displacement once, then publish ``~/state``."""
        factor = 0.5 if self.slow_mode else 1.0
        for i, displacement in enumerate(self.displacements):
            if math.isnan(displacement):
                continue
            state = float(self.state_interfaces[i].get_value())
            self.command_interfaces[i].set_value(state + factor * displacement)
            self.displacements[i] = math.nan
        if self._pub is not None and self.command_interfaces:
            set_point = float(self.command_interfaces[0].get_value())
            process_value = float(self.state_interfaces[0].get_value())
            self._pub.publish(JointControllerState(
                header=Header(stamp=time, frame_id=self._joints[0]),
                set_point=set_point,
                process_value=process_value,
                error=set_point - process_value,
                time_step=period,
                command=set_point,
            ))
        return ReturnType.OK
