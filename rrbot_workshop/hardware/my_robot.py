"""MyRobot's simulated devices: the arm's motor controller and the tool's force-torque sensor (notebook 15).

MyRobot is the three-joint robot of a ROS 1 ros_control tutorial, brought to ROS 2 in notebook 15: ``joint1`` and
``joint2`` take effort commands, ``joint3`` takes position commands. Its package is ``descriptions/my_robot``.

* :class:`MyRobotDevice` is the arm behind the hardware component a learner writes in task 15
  (``my_robot/MyRobotHardware``). It applies what it is sent, exactly, with no limits of its own: keeping the joints
  inside their limits is the component's job (ROS 1's ``joint_limits_interface``, Jazzy's ``joint_limits``). An
  effort joint is a rotor of inertia ``inertia`` [kg m^2] with viscous damping ``damping`` [N m s/rad], integrated
  with semi-implicit Euler over the period it is given; a position joint is an ideal servo that reaches the
  commanded position within the period. Commands act only while the device is enabled; a NaN command means "no
  command" (zero torque, or the position held).
* :class:`ToolForceTorqueSensor` (plugin ``my_robot/ToolForceTorqueSensor``) is the driver of an external
  force-torque sensor at the tool, a ``<ros2_control type="sensor">`` component of its own, as external sensors are
  in ros2_control's examples. It reads the weight of the tool (hardware parameter ``tool_weight`` [N], default 4.9)
  with a small seeded noise (``noise`` [N], default 0.05; ``seed``, default 0): the same numbers on every run.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware_interface.component_interface import SensorInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["JOINT_MODES", "MyRobotDevice", "ToolForceTorqueSensor", "FORCE_TORQUE_INTERFACES"]

#: The command modes a joint of the device takes.
JOINT_MODES = ("effort", "position")
#: The sensor's state interfaces, in the order it reports them.
FORCE_TORQUE_INTERFACES = ("fx", "fy", "fz", "tx", "ty", "tz")


def _per_joint(value: float | Sequence[float], count: int, name: str) -> list[float]:
    values = [float(value)] * count if isinstance(value, int | float) else [float(v) for v in value]
    if len(values) != count:
        raise ValueError(f"MyRobotDevice: {len(values)} values of '{name}' for {count} joints")
    return values


class MyRobotDevice:
    """The simulated arm: one motor per joint, effort or position, applied exactly as commanded.

    Args:
        modes: Each joint's command mode, ``"effort"`` or ``"position"``, in the order of the commands.
        inertia: Rotor inertia of the effort joints in [kg m^2] (one value, or one per joint).
        damping: Viscous damping of the effort joints in [N m s/rad] (one value, or one per joint).
        initial_positions: Where the joints start, in [rad]; default 0 for each.

    Raises:
        ValueError: For an unknown mode, a non-positive inertia or a list of the wrong length.
    """

    def __init__(self, modes: Sequence[str], inertia: float | Sequence[float] = 0.5,
                 damping: float | Sequence[float] = 0.5, initial_positions: Sequence[float] | None = None) -> None:
        self.modes = list(modes)
        bad = [m for m in self.modes if m not in JOINT_MODES]
        if bad:
            raise ValueError(f"MyRobotDevice: unknown joint mode(s) {bad} (valid: {', '.join(JOINT_MODES)})")
        n = len(self.modes)
        self.inertia = _per_joint(inertia, n, "inertia")
        if any(not i > 0.0 for i in self.inertia):
            raise ValueError(f"MyRobotDevice: inertia must be > 0 [kg m^2], got {self.inertia}")
        self.damping = _per_joint(damping, n, "damping")
        self.positions = _per_joint(initial_positions if initial_positions is not None else 0.0, n, "initial_positions")
        self.velocities = [0.0] * n
        self.efforts = [0.0] * n
        #: The commands of the last :meth:`write`, as the device received them (NaN: none).
        self.last_commands: list[float] = [math.nan] * n
        self._enabled = False

    @property
    def number_of_joints(self) -> int:
        """How many joints the device has."""
        return len(self.modes)

    @property
    def enabled(self) -> bool:
        """Whether the motors act on commands."""
        return self._enabled

    def enable(self) -> None:
        """Power the motors: commands act from now on."""
        self._enabled = True

    def disable(self) -> None:
        """Switch the motors off: effort joints coast, position joints stay where they are."""
        self._enabled = False
        self.efforts = [0.0] * self.number_of_joints

    def read(self) -> tuple[list[float], list[float], list[float]]:
        """Positions [rad], velocities [rad/s] and efforts [N m] (the torque each motor applies) of every joint."""
        return list(self.positions), list(self.velocities), list(self.efforts)

    def write(self, commands: Sequence[float], dt: float) -> None:
        """Apply one command per joint (effort [N m] or position [rad], as its mode says) for ``dt`` seconds.

        Raises:
            ValueError: If the number of commands is not the number of joints.
        """
        if len(commands) != self.number_of_joints:
            raise ValueError(f"MyRobotDevice.write: {len(commands)} commands for {self.number_of_joints} joints")
        self.last_commands = [float(c) for c in commands]
        if dt <= 0.0:
            return
        for i, (mode, command) in enumerate(zip(self.modes, self.last_commands, strict=True)):
            given = self._enabled and not math.isnan(command)
            if mode == "effort":
                torque = command if given else 0.0
                self.efforts[i] = torque
                self.velocities[i] += dt * (torque - self.damping[i] * self.velocities[i]) / self.inertia[i]
                self.positions[i] += dt * self.velocities[i]
            else:
                target = command if given else self.positions[i]
                self.velocities[i] = (target - self.positions[i]) / dt
                self.positions[i] = target


class ToolForceTorqueSensor(SensorInterface):
    """Driver of MyRobot's external force-torque sensor at the tool. Plugin ``my_robot/ToolForceTorqueSensor``."""

    def __init__(self) -> None:
        super().__init__()
        self._rng = random.Random(0)
        self._names: list[str] = []
        self._weight = 4.9
        self._noise = 0.05

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Accept one ``<sensor>`` whose state interfaces are among fx, fy, fz, tx, ty, tz, and no joint."""
        if super().on_init(info) is not CallbackReturn.SUCCESS:
            return CallbackReturn.ERROR
        if len(info.sensors) != 1 or info.joints or info.gpios:
            self.logger.error("'%s': the tool sensor is one <sensor> and nothing else (found %d sensors, %d joints, "
                              "%d GPIOs)", info.name, len(info.sensors), len(info.joints), len(info.gpios))
            return CallbackReturn.ERROR
        sensor = info.sensors[0]
        unknown = [i.name for i in sensor.state_interfaces if i.name not in FORCE_TORQUE_INTERFACES]
        if unknown:
            self.logger.error("sensor '%s': unknown state interface(s) %s (valid: %s)", sensor.name, unknown,
                              ", ".join(FORCE_TORQUE_INTERFACES))
            return CallbackReturn.ERROR
        try:
            self._weight = float(info.hardware_parameters.get("tool_weight", "4.9"))
            self._noise = float(info.hardware_parameters.get("noise", "0.05"))
            int(info.hardware_parameters.get("seed", "0"))
        except ValueError as exc:
            self.logger.error("'%s': a hardware parameter is not a number: %s", info.name, exc)
            return CallbackReturn.ERROR
        self._names = [f"{sensor.name}/{i.name}" for i in sensor.state_interfaces]
        return CallbackReturn.SUCCESS

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Restart the noise from the seed and take a first reading."""
        self._rng = random.Random(int(self.info.hardware_parameters.get("seed", "0")))
        self.read(0.0, 0.0)
        return CallbackReturn.SUCCESS

    def read(self, time: float, period: float) -> ReturnType:
        """The tool's weight along -z, with noise on every axis."""
        for name in self._names:
            nominal = -self._weight if name.endswith("/fz") else 0.0
            self.set_state(name, nominal + self._rng.gauss(0.0, self._noise))
        return ReturnType.OK
