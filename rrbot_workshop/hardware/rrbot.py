"""``controlko_hardware_interface/RRBotHardwareInterface``: the driver of the simulated RRBot device (task 7).

Reference solution of the ROSCon 2022 workshop's task 7, used when a learner's task-7 file is not usable yet. It
talks to :class:`~rrbot_workshop.hardware.rrbot_device.RRBotDevice` (the comms library's contract) and fixes what the
original's solution got wrong:

* every interface is exported with its own value: joint ``effort`` is not the acceleration, the sensor's states carry
  the sensor values and the GPIO states the GPIO values (the original swapped them), and the GPIO command interfaces
  ``digital_out_*`` exist (the original looped over the sensor's, empty, command interfaces);
* ``prepare_command_mode_switch`` refuses a switch after which some joint would be commanded in position and another
  (or the same) in velocity: the device has one mode for all joints. The original had that check commented out and
  switched to POSITION in both branches.

The description it expects (RRBot's ``<ros2_control>`` tag with ``use_mock_hardware:=false``): each joint with the
command interfaces ``position`` and ``velocity`` and at least the state interfaces ``position`` and ``velocity``
(``acceleration`` and ``effort`` optional: the device measures no torque, so ``effort`` reads NaN); at most one
``<sensor>`` (its state interfaces are filled with the device's sensor values in order); at most one ``<gpio>`` whose
``digital_in_*`` states are the device's inputs and whose ``digital_out_*`` commands (with same-named states, the
read-back) are its outputs. Hardware parameter ``seed`` (default 0) seeds the device's random values.
"""

from __future__ import annotations

import math

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo
from rrbot_workshop.hardware.rrbot_device import ControlMode, RRBotDevice
from rrbot_workshop.hardware_interface.component_interface import SystemInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["RRBotHardwareInterface", "description_problems"]

_MODES = {"position": ControlMode.POSITION, "velocity": ControlMode.VELOCITY}


def _names(items: list) -> list[str]:
    return [i.name for i in items]


def description_problems(info: HardwareInfo) -> list[str]:
    """What in ``info`` the RRBot device cannot serve (empty if nothing): each problem names its element."""
    problems = []
    if not info.joints:
        problems.append(f"<ros2_control name='{info.name}'> has no <joint>; the RRBot device needs at least one")
    for joint in info.joints:
        commands, states = _names(joint.command_interfaces), _names(joint.state_interfaces)
        if sorted(commands) != ["position", "velocity"]:
            problems.append(f"<joint name='{joint.name}'> has command interfaces {commands}; the device takes exactly "
                            "'position' and 'velocity'")
        missing = [s for s in ("position", "velocity") if s not in states]
        extra = [s for s in states if s not in ("position", "velocity", "acceleration", "effort")]
        if missing or extra:
            problems.append(f"<joint name='{joint.name}'> has state interfaces {states}; it needs 'position' and "
                            "'velocity' and may have 'acceleration' and 'effort'")
    if len(info.sensors) > 1:
        problems.append(f"{len(info.sensors)} <sensor> elements {_names(info.sensors)}; the device has one sensor")
    if len(info.gpios) > 1:
        problems.append(f"{len(info.gpios)} <gpio> elements {_names(info.gpios)}; the device has one set of I/Os")
    for gpio in info.gpios:
        for itf in gpio.command_interfaces:
            if not itf.name.startswith("digital_out_"):
                problems.append(f"<gpio name='{gpio.name}'> commands '{itf.name}'; the device's outputs are "
                                "digital_out_1, digital_out_2, ...")
        for itf in gpio.state_interfaces:
            if not itf.name.startswith(("digital_in_", "digital_out_")):
                problems.append(f"<gpio name='{gpio.name}'> has state '{itf.name}'; the device reports digital_in_N "
                                "and (read back) digital_out_N")
    return problems


class RRBotHardwareInterface(SystemInterface):
    """The RRBot driver: opens the device at configure, runs it between activate and deactivate.

    Attributes:
        device: The device, between configure and cleanup (None otherwise).
    """

    def __init__(self) -> None:
        super().__init__()
        self.device: RRBotDevice | None = None
        self._joints: list[str] = []
        self._sensor: ComponentInfo | None = None
        self._gpio: ComponentInfo | None = None
        self._claimed: set[str] = set()  # joint command interfaces claimed by controllers now
        self._next_mode = ControlMode.POSITION

    # ----------------------------------------------------------------- lifecycle
    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Check that the description is one the device can serve."""
        result = super().on_init(info)
        if result is not CallbackReturn.SUCCESS:
            return result
        problems = description_problems(info)
        if problems:
            self.logger.error("'%s' cannot drive this description: %s", info.name, "; ".join(problems))
            return CallbackReturn.ERROR
        try:
            int(info.hardware_parameters.get("seed", "0"))
        except ValueError:
            self.logger.error("'%s': hardware parameter seed='%s' must be an integer", info.name,
                              info.hardware_parameters["seed"])
            return CallbackReturn.ERROR
        self._joints = [j.name for j in info.joints]
        self._sensor = info.sensors[0] if info.sensors else None
        self._gpio = info.gpios[0] if info.gpios else None
        return CallbackReturn.SUCCESS

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Open the device (joints at 0.1 rad, movement disabled); effort states read NaN (no torque sensing)."""
        self.device = RRBotDevice(len(self._joints), seed=int(self.info.hardware_parameters.get("seed", "0")))
        self._claimed = set()
        self._next_mode = ControlMode.POSITION
        for joint in self._joints:
            if f"{joint}/effort" in self.state_interface_names:
                self.set_state(f"{joint}/effort", math.nan)
        self.read(0.0, 0.0)  # the states show the device as it is, before any controller runs
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Enable movement; commands start where the joints are (no jump when a controller takes over)."""
        assert self.device is not None
        self.device.init()
        positions, velocities, _ = self.device.read_joint_states()
        for joint, position, velocity in zip(self._joints, positions, velocities, strict=True):
            self.set_command(f"{joint}/position", position)
            self.set_command(f"{joint}/velocity", velocity)
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Disable movement."""
        if self.device is not None:
            self.device.stop()
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Close the device."""
        self.device = None
        return CallbackReturn.SUCCESS

    on_shutdown = on_cleanup

    # ----------------------------------------------------------------- cycle
    def read(self, time: float, period: float) -> ReturnType:
        """Joint states, then the sensor, then the GPIOs, from the device."""
        if self.device is None:
            return ReturnType.ERROR
        positions, velocities, accelerations = self.device.read_joint_states()
        for joint, p, v, a in zip(self._joints, positions, velocities, accelerations, strict=True):
            self.set_state(f"{joint}/position", p)
            self.set_state(f"{joint}/velocity", v)
            if f"{joint}/acceleration" in self.state_interface_names:
                self.set_state(f"{joint}/acceleration", a)
        if self._sensor is not None:
            values = self.device.read_sensor_values(len(self._sensor.state_interfaces))
            for itf, value in zip(self._sensor.state_interfaces, values, strict=True):
                self.set_state(f"{self._sensor.name}/{itf.name}", value)
        if self._gpio is not None:
            inputs, outputs = self.device.read_gpio()
            for itf in self._gpio.state_interfaces:
                kind, _, number = itf.name.rpartition("_")
                bits = inputs if kind == "digital_in" else outputs
                index = int(number) - 1 if number.isdigit() else -1
                if 0 <= index < len(bits):
                    self.set_state(f"{self._gpio.name}/{itf.name}", 1.0 if bits[index] else 0.0)
        return ReturnType.OK

    def write(self, time: float, period: float) -> ReturnType:
        """Joint commands (the device uses those of its mode) and the digital outputs."""
        if self.device is None:
            return ReturnType.ERROR
        positions = [self.get_command(f"{j}/position") for j in self._joints]
        velocities = [self.get_command(f"{j}/velocity") for j in self._joints]
        self.device.write_joint_commands(positions, velocities, period)
        if self._gpio is not None and self._gpio.command_interfaces:
            _, outputs = self.device.read_gpio()
            for itf in self._gpio.command_interfaces:
                value = self.get_command(f"{self._gpio.name}/{itf.name}")
                index = int(itf.name.rpartition("_")[2]) - 1
                if 0 <= index < len(outputs) and not math.isnan(value):
                    outputs[index] = value > 0.5
            self.device.write_gpios(outputs)
        return ReturnType.OK

    # ----------------------------------------------------------------- control modes
    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Accept the switch if, afterwards, every commanded joint is in one and the same mode."""
        joints = set(self._joints)
        after = (self._claimed - set(stop_interfaces)) | {
            name for name in start_interfaces if name.rpartition("/")[0] in joints
        }
        modes = {name.rpartition("/")[2] for name in after}
        if len(modes) > 1:
            by_mode = {mode: sorted(n for n in after if n.endswith(f"/{mode}")) for mode in sorted(modes)}
            self.mode_switch_rejection = (
                f"the RRBot device runs all joints in one mode, position or velocity; after this switch "
                f"{by_mode['position']} would be commanded in position and {by_mode['velocity']} in velocity"
            )
            self.logger.error("%s", self.mode_switch_rejection)
            return ReturnType.ERROR
        self._next_mode = _MODES[modes.pop()] if modes else (self.device.get_control_mode() if self.device
                                                              else ControlMode.POSITION)
        return ReturnType.OK

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Put the device in the mode chosen by :meth:`prepare_command_mode_switch`."""
        joints = set(self._joints)
        self._claimed = (self._claimed - set(stop_interfaces)) | {
            name for name in start_interfaces if name.rpartition("/")[0] in joints
        }
        if self.device is not None:
            self.device.set_control_mode(self._next_mode)
        return ReturnType.OK
