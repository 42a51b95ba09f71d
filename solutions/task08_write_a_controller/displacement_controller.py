"""Task 8: the DisplacementController, a ros2_control controller written from scratch.

It moves joints by *displacements*: each ``control_msgs/JointJog`` received on ``~/reference`` says how far each
joint should move from where it is now; the controller applies each displacement once, in the next update, as
``command = current state + displacement`` (halved in slow mode, switched with the ``~/set_slow_control_mode``
service), and publishes ``~/state``. Plugin names: ``controlko_controllers/DisplacementController`` and
``displacement_controller/DisplacementController``, both resolving to the class in this file.

The life of a controller, as the controller manager drives it:

* load: ``on_init`` declares the parameters (here from ``PARAMETERS``, as generate_parameter_library would);
* configure: ``on_configure`` reads them and creates topics and services;
* the manager asks which interfaces to claim (``command_interface_configuration`` and
  ``state_interface_configuration``), and loans them in that order;
* activate: ``on_activate``; then ``update`` every cycle, the only method that runs in the real-time loop;
* deactivate: ``on_deactivate`` leaves the commanded interfaces in a safe state.

The rules hold for any joints, interface, controller name and rate the parameters and the manager give (the
grader tries others than the notebook's). Commands and ``~/state`` are compared to 1e-9: the arithmetic is exact.
"""

from __future__ import annotations

import math
from typing import ClassVar

from rrbot_workshop.controller_interface import (
    CallbackReturn,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
    ReturnType,
)
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.params import register_validator
from rrbot_workshop.msgs import Header, JointControllerState, JointJog, SetBoolRequest, SetBoolResponse

__all__ = ["DisplacementController", "forbidden_interface_name_prefix"]


# ------------------------------------------------------------------------------------------ 8.1 parameters


def forbidden_interface_name_prefix(value: str, prefix: str) -> str | None:
    """A custom parameter validator: None if ``value`` is fine, else the reason it is refused."""
    if value.startswith(prefix):
        return f"'{value}' must not start with '{prefix}'"
    return None


# The schema below names it as displacement_controller::forbidden_interface_name_prefix.
register_validator("displacement_controller::forbidden_interface_name_prefix", forbidden_interface_name_prefix)


class DisplacementController(ControllerInterface):
    """Applies each received joint displacement once: ``command = state + displacement``."""

    # generate_parameter_library's YAML: names, types, defaults and validation of every parameter
    PARAMETERS: ClassVar[str | None] = """
displacement_controller:
  joints:
    type: string_array
    default_value: []
    description: "Joints to command, in the order the commands are claimed."
    read_only: true
    validation:
      unique<>: []
      not_empty<>: []
  state_joints:
    type: string_array
    default_value: []
    description: "Joints whose state is read; empty: the same as 'joints'."
    read_only: true
    validation:
      unique<>: []
  interface_name:
    type: string
    default_value: ""
    description: "The interface commanded and read on every joint."
    read_only: true
    validation:
      not_empty<>: []
      displacement_controller::forbidden_interface_name_prefix: ["blup_"]
      one_of<>: [["position", "velocity", "acceleration", "effort"]]
"""

    def __init__(self) -> None:
        super().__init__()
        self.joints: list[str] = []
        self.state_joints: list[str] = []
        self.interface_name = ""
        self.slow_mode = False
        #: The displacement waiting for the next update, per joint (NaN: none).
        self.displacements: list[float] = []
        self._state_publisher = None

    # -------------------------------------------------------------------------------------- 8.2 configure

    def on_configure(self, previous_state: State) -> CallbackReturn:
        params = self.param_listener.get_params()
        self.joints = list(params.joints)
        self.state_joints = list(params.state_joints) or list(self.joints)
        if len(self.state_joints) != len(self.joints):
            self.logger.error("'state_joints' has %d joints and 'joints' %d: they must have the same size",
                              len(self.state_joints), len(self.joints))
            return CallbackReturn.FAILURE
        self.interface_name = params.interface_name
        self.displacements = [math.nan] * len(self.joints)
        self.slow_mode = False
        node = self.get_node()
        node.create_subscription(JointJog, "~/reference", self._on_reference)
        node.create_service(SetBoolRequest, "~/set_slow_control_mode", self._on_set_slow_control_mode)
        self._state_publisher = node.create_publisher(JointControllerState, "~/state")
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self) -> InterfaceConfiguration:
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL,
                                      [f"{joint}/{self.interface_name}" for joint in self.joints])

    def state_interface_configuration(self) -> InterfaceConfiguration:
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL,
                                      [f"{joint}/{self.interface_name}" for joint in self.state_joints])

    # --------------------------------------------------------------------- 8.3 topic and service callbacks

    def _on_reference(self, msg: JointJog) -> None:
        if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints):
            self.logger.error("rejected a JointJog with %d joint names and %d displacements: %s needs one "
                              "displacement for each of %s", len(msg.joint_names), len(msg.displacements),
                              self.get_name(), self.joints)
            return
        if sorted(msg.joint_names) != sorted(self.joints):
            self.logger.error("rejected a JointJog for joints %s: this controller moves %s", msg.joint_names,
                              self.joints)
            return
        # matched by name: the message may list the joints in any order
        by_name = dict(zip(msg.joint_names, msg.displacements, strict=True))
        self.displacements = [float(by_name[joint]) for joint in self.joints]

    def _on_set_slow_control_mode(self, request: SetBoolRequest) -> SetBoolResponse:
        self.slow_mode = bool(request.data)
        return SetBoolResponse(success=True, message="slow mode" if self.slow_mode else "fast mode")

    # ------------------------------------------------------------------------- 8.4 activate, update, deactivate

    def on_activate(self, previous_state: State) -> CallbackReturn:
        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation is applied
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        for i, displacement in enumerate(self.displacements):
            if math.isnan(displacement):
                continue
            current = self.state_interfaces[i].get_value()
            self.command_interfaces[i].set_value(current + factor * displacement)
            self.displacements[i] = math.nan  # used once
        if self._state_publisher is not None:
            set_point = self.command_interfaces[0].get_value()
            process_value = self.state_interfaces[0].get_value()
            self._state_publisher.publish(JointControllerState(
                header=Header(stamp=time, frame_id=self.joints[0]), set_point=set_point,
                process_value=process_value, error=set_point - process_value, time_step=period, command=set_point))
        return ReturnType.OK

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        for interface in self.command_interfaces:
            interface.set_value(math.nan)  # no stale command is left for the next controller
        return CallbackReturn.SUCCESS
