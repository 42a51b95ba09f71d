# ruff: noqa  (written as a learner would, not to the library's lint rules)
"""Task 8, written differently: pending displacements kept by joint name (None: none), loops, slow mode as a factor."""

from __future__ import annotations

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


def forbidden_interface_name_prefix(value, prefix):
    if value[: len(prefix)] == prefix:
        return "interface names beginning with " + prefix + " are not allowed (got " + value + ")"
    return None


register_validator("displacement_controller::forbidden_interface_name_prefix", forbidden_interface_name_prefix)


class DisplacementController(ControllerInterface):
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
    description: "Joints read."
    read_only: true
    validation:
      unique<>: []
  interface_name:
    type: string
    default_value: ""
    description: "Interface."
    read_only: true
    validation:
      not_empty<>: []
      displacement_controller::forbidden_interface_name_prefix:
        - "blup_"
      one_of<>: [["position", "velocity", "acceleration", "effort"]]
"""

    def __init__(self):
        super().__init__()
        self.names = []
        self.readers = []
        self.itf = ""
        self.gain = 1.0
        self.waiting = {}
        self.pub = None

    def on_configure(self, previous_state):
        p = self.param_listener.get_params()
        self.names = []
        for j in p.joints:
            self.names.append(j)
        if len(p.state_joints) == 0:
            self.readers = list(self.names)
        else:
            self.readers = list(p.state_joints)
        if len(self.readers) != len(self.names):
            self.logger.error("state_joints and joints differ in size")
            return CallbackReturn.FAILURE
        self.itf = p.interface_name
        self.gain = 1.0
        self.waiting = {}
        n = self.get_node()
        n.create_subscription(JointJog, "~/reference", self._on_reference)
        n.create_service(SetBoolRequest, "~/set_slow_control_mode", self._on_set_slow_control_mode)
        self.pub = n.create_publisher(JointControllerState, "~/state")
        return CallbackReturn.SUCCESS

    def command_interface_configuration(self):
        names = []
        for j in self.names:
            names.append(j + "/" + self.itf)
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def state_interface_configuration(self):
        names = []
        for j in self.readers:
            names.append(j + "/" + self.itf)
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def _on_reference(self, msg):
        names = list(msg.joint_names)
        values = list(msg.displacements)
        if len(values) != len(names):
            self.logger.warning("%d names but %d displacements", len(names), len(values))
            return
        for j in self.names:
            if names.count(j) != 1:
                self.logger.warning("joint %s must appear exactly once in %s", j, names)
                return
        if len(names) != len(self.names):
            self.logger.warning("message names %s, expected %s", names, self.names)
            return
        new = {}
        for name, value in zip(names, values):
            new[name] = float(value)
        self.waiting = new

    def _on_set_slow_control_mode(self, request):
        if request.data:
            self.gain = 0.5
        else:
            self.gain = 1.0
        return SetBoolResponse(success=True, message="gain %g" % self.gain)

    def on_activate(self, previous_state):
        self.waiting = {}
        self.gain = 1.0  # start every activation fast
        return CallbackReturn.SUCCESS

    def update(self, time, period):
        waiting, self.waiting = self.waiting, {}
        for k, name in enumerate(self.names):
            if name in waiting:
                self.command_interfaces[k].set_value(self.state_interfaces[k].get_value() + self.gain * waiting[name])
        cmd = self.command_interfaces[0].get_value()
        meas = self.state_interfaces[0].get_value()
        msg = JointControllerState()
        msg.header = Header(stamp=time, frame_id=self.names[0])
        msg.set_point = cmd
        msg.command = cmd
        msg.process_value = meas
        msg.error = cmd - meas
        msg.time_step = period
        self.pub.publish(msg)
        return ReturnType.OK

    def on_deactivate(self, previous_state):
        for k in range(len(self.command_interfaces)):
            self.command_interfaces[k].set_value(float("nan"))
        return CallbackReturn.SUCCESS
