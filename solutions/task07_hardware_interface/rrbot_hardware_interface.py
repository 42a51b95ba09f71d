"""Task 7: the driver of the RRBot device, ``controlko_hardware_interface/RRBotHardwareInterface``.

A hardware component is the only part of ros2_control that talks to the robot. The controller manager drives it
through its lifecycle and calls ``read`` and ``write`` every control cycle; controllers only ever see the state and
command interfaces it exports. The device is :class:`rrbot_workshop.hardware.rrbot_device.RRBotDevice`, with the
contract of the original workshop's comms library: ``init()``/``stop()``, ``set_control_mode``,
``write_joint_commands(positions, velocities, dt)``, ``read_joint_states()``, ``read_sensor_values(n)``,
``write_gpios(outputs)`` and ``read_gpio()``.

The lifecycle, as the resource manager drives it:

* ``on_init(info)``: the ``<ros2_control>`` tag, parsed; refuse what the device cannot do;
* ``on_configure``: open the device (the robot is reachable, its motors are off);
* ``on_activate``: enable movement; ``on_deactivate``: disable it;
* ``read``/``write`` every cycle while active (``read`` also while inactive);
* ``prepare_command_mode_switch``/``perform_command_mode_switch`` when controllers start or stop claiming
  command interfaces.

How it is checked: every state must carry the device's own value, unchanged (compared to 1e-9); the joints' motion
through a running controller manager is compared within 0.01 rad (one cycle at the device's 0.5 rad/s).
"""

from __future__ import annotations

import math

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware import SystemInterface
from rrbot_workshop.hardware.rrbot_device import ControlMode, RRBotDevice
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["RRBotHardwareInterface"]


class RRBotHardwareInterface(SystemInterface):
    """The RRBot driver."""

    def __init__(self) -> None:
        super().__init__()
        self.device: RRBotDevice | None = None
        self.joints: list[str] = []
        self.claimed: set[str] = set()  # joint command interfaces controllers hold now
        self.next_mode = ControlMode.POSITION

    # ------------------------------------------------------------------------------------------ 7.1 on_init

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        if super().on_init(info) is not CallbackReturn.SUCCESS:
            return CallbackReturn.ERROR
        for joint in info.joints:
            commands = sorted(i.name for i in joint.command_interfaces)
            states = [i.name for i in joint.state_interfaces]
            if commands != ["position", "velocity"]:
                self.logger.error("joint '%s' has command interfaces %s; the RRBot device takes exactly position "
                                  "and velocity", joint.name, commands)
                return CallbackReturn.ERROR
            if "position" not in states or "velocity" not in states:
                self.logger.error("joint '%s' has state interfaces %s; it needs position and velocity",
                                  joint.name, states)
                return CallbackReturn.ERROR
        if len(info.sensors) > 1 or len(info.gpios) > 1:
            self.logger.error("the RRBot device has one sensor and one set of I/Os, not %d and %d",
                              len(info.sensors), len(info.gpios))
            return CallbackReturn.ERROR
        self.joints = [joint.name for joint in info.joints]
        return CallbackReturn.SUCCESS

    # ---------------------------------------------------------------------------- 7.2 configure, activate

    def on_configure(self, previous_state: State) -> CallbackReturn:
        self.device = RRBotDevice(len(self.joints), seed=int(self.info.hardware_parameters.get("seed", "0")))
        self.claimed = set()
        for joint in self.joints:
            if f"{joint}/effort" in self.state_interface_names:
                self.set_state(f"{joint}/effort", math.nan)  # the device measures no torque
        self.read(0.0, 0.0)
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        self.device.init()
        positions, velocities, _ = self.device.read_joint_states()
        for joint, position, velocity in zip(self.joints, positions, velocities, strict=True):
            self.set_command(f"{joint}/position", position)  # a controller taking over starts where the joint is
            self.set_command(f"{joint}/velocity", velocity)
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        self.device.stop()
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        self.device = None
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------------------------- 7.3 read, write

    def read(self, time: float, period: float) -> ReturnType:
        positions, velocities, accelerations = self.device.read_joint_states()
        for joint, p, v, a in zip(self.joints, positions, velocities, accelerations, strict=True):
            self.set_state(f"{joint}/position", p)
            self.set_state(f"{joint}/velocity", v)
            if f"{joint}/acceleration" in self.state_interface_names:
                self.set_state(f"{joint}/acceleration", a)
        for sensor in self.info.sensors:
            values = self.device.read_sensor_values(len(sensor.state_interfaces))
            for interface, value in zip(sensor.state_interfaces, values, strict=True):
                self.set_state(f"{sensor.name}/{interface.name}", value)
        for gpio in self.info.gpios:
            inputs, outputs = self.device.read_gpio()
            for interface in gpio.state_interfaces:  # digital_in_N from the inputs, digital_out_N read back
                kind, _, number = interface.name.rpartition("_")
                bits = inputs if kind == "digital_in" else outputs
                self.set_state(f"{gpio.name}/{interface.name}", 1.0 if bits[int(number) - 1] else 0.0)
        return ReturnType.OK

    def write(self, time: float, period: float) -> ReturnType:
        positions = [self.get_command(f"{joint}/position") for joint in self.joints]
        velocities = [self.get_command(f"{joint}/velocity") for joint in self.joints]
        self.device.write_joint_commands(positions, velocities, period)
        for gpio in self.info.gpios:
            _, outputs = self.device.read_gpio()
            for interface in gpio.command_interfaces:
                value = self.get_command(f"{gpio.name}/{interface.name}")
                if not math.isnan(value):
                    outputs[int(interface.name.rpartition("_")[2]) - 1] = value > 0.5
            self.device.write_gpios(outputs)
        return ReturnType.OK

    # ---------------------------------------------------------------------------------- 7.4 control modes

    def _after(self, start_interfaces: list[str], stop_interfaces: list[str]) -> set[str]:
        """The joint command interfaces claimed once the switch is done."""
        started = {name for name in start_interfaces if name.rpartition("/")[0] in self.joints}
        return (self.claimed - set(stop_interfaces)) | started

    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        modes = {name.rpartition("/")[2] for name in self._after(start_interfaces, stop_interfaces)}
        if len(modes) > 1:
            self.mode_switch_rejection = ("the RRBot device runs all joints in one mode; this switch would command "
                                          "them in position and in velocity at once")
            self.logger.error("%s", self.mode_switch_rejection)
            return ReturnType.ERROR
        if modes == {"position"}:
            self.next_mode = ControlMode.POSITION
        elif modes == {"velocity"}:
            self.next_mode = ControlMode.VELOCITY
        return ReturnType.OK

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        self.claimed = self._after(start_interfaces, stop_interfaces)
        self.device.set_control_mode(self.next_mode)
        return ReturnType.OK
