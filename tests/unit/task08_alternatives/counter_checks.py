# ruff: noqa  (written as a learner would, not to the library's lint rules)
"""Task 8, written differently: message checks with Counter, precomputed interface names, a regex validator."""

from __future__ import annotations

import math
import re
from collections import Counter
from typing import ClassVar

from rrbot_workshop.controller_interface import (
    CallbackReturn,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
    ReturnType,
)
from rrbot_workshop.middleware.params import register_validator
from rrbot_workshop.msgs import Header, JointControllerState, JointJog, SetBoolRequest, SetBoolResponse

NAN = float("nan")


def forbidden_interface_name_prefix(value: str, prefix: str) -> str | None:
    return f"{value!r} begins with the forbidden {prefix!r}" if re.match(re.escape(prefix), value) else None


register_validator("displacement_controller::forbidden_interface_name_prefix", forbidden_interface_name_prefix)


class DisplacementController(ControllerInterface):
    PARAMETERS: ClassVar[str | None] = """
displacement_controller:
  interface_name:
    type: string
    default_value: ""
    description: "Interface commanded and read."
    read_only: true
    validation:
      not_empty<>: []
      displacement_controller::forbidden_interface_name_prefix: ["blup_"]
      one_of<>: [["position", "velocity", "acceleration", "effort"]]
  joints:
    type: string_array
    default_value: []
    description: "Joints to command."
    read_only: true
    validation:
      not_empty<>: []
      unique<>: []
  state_joints:
    type: string_array
    default_value: []
    description: "Joints read; empty: joints."
    read_only: true
    validation:
      unique<>: []
"""

    def __init__(self) -> None:
        super().__init__()
        self.slow = False
        self.joints: list[str] = []
        self.command_names: list[str] = []
        self.state_names: list[str] = []
        self.displacements: list[float] = []
        self.state_pub = None

    def on_configure(self, previous_state):
        params = self.param_listener.get_params()
        joints, state_joints = list(params.joints), list(params.state_joints)
        if state_joints and len(state_joints) != len(joints):
            self.logger.error("joints %s and state_joints %s cannot be paired", joints, state_joints)
            return CallbackReturn.FAILURE
        self.joints = joints
        self.command_names = [f"{j}/{params.interface_name}" for j in joints]
        self.state_names = [f"{j}/{params.interface_name}" for j in (state_joints or joints)]
        self.displacements = [NAN for _ in joints]
        self.slow = False
        node = self.get_node()
        self.state_pub = node.create_publisher(JointControllerState, "~/state")
        node.create_service(SetBoolRequest, "~/set_slow_control_mode", self._on_set_slow_control_mode)
        node.create_subscription(JointJog, "~/reference", self._on_reference)
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self):
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, self.command_names)

    def state_interface_configuration(self):
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, self.state_names)

    def _on_reference(self, msg):
        if Counter(msg.joint_names) != Counter(self.joints) or len(msg.displacements) != len(msg.joint_names):
            self.logger.error("ignoring JointJog %s / %s", msg.joint_names, msg.displacements)
            return
        index = {name: k for k, name in enumerate(msg.joint_names)}
        self.displacements = [float(msg.displacements[index[j]]) for j in self.joints]

    def _on_set_slow_control_mode(self, request):
        self.slow = request.data is True
        return SetBoolResponse(True, "ok")

    def on_activate(self, previous_state):
        self.displacements = [NAN] * len(self.joints)
        return CallbackReturn.SUCCESS

    def update(self, time, period):
        pending, self.displacements = self.displacements, [NAN] * len(self.joints)
        for cmd, state, d in zip(self.command_interfaces, self.state_interfaces, pending):
            if d == d:  # not NaN
                cmd.set_value(state.get_value() + (d / 2 if self.slow else d))
        command = self.command_interfaces[0].get_value()
        state = self.state_interfaces[0].get_value()
        self.state_pub.publish(JointControllerState(
            command=command, set_point=command, process_value=state, error=command - state, time_step=period,
            header=Header(frame_id=self.joints[0], stamp=time)))
        return ReturnType.OK

    def on_deactivate(self, previous_state):
        for loan in self.command_interfaces:
            loan.set_value(math.nan)
        return CallbackReturn.SUCCESS
