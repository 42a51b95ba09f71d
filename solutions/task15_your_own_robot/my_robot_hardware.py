"""Task 15: MyRobot's hardware component, ``my_robot/MyRobotHardware``: the ROS 1 ``MyRobot`` node, ported.

In ROS 1 the node was the robot: a ``hardware_interface::RobotHW`` that registered a handle per joint
(``registerInterface``), read the joint limits from the parameter server (``joint_limits.yaml``), enforced them on
every command (``effortJointSaturationInterface.enforceLimits(period)``, the soft-limits interfaces), and ran its own
loop: ``read()``, ``controller_manager.update()``, ``write()``. In ros2_control the controller manager owns the loop and
this class is a plugin it drives:

* ``on_init(info)``: the ``<ros2_control>`` tag replaces the handles registered in C++: check that it declares what the
  motors can do, and build one joint limiter per joint from the ``joint_limits.<joint>.*`` parameters of the file the
  hardware parameter ``joint_limits_file`` names, over the URDF's limits;
* ``on_configure``/``on_activate``/``on_deactivate``: open the device, power the motors, switch them off;
* ``read``: the device's values into the state interfaces; ``write``: the commands, limited, to the device.

The device is :class:`rrbot_workshop.hardware.my_robot.MyRobotDevice`: effort joints and position joints, applying what
it is sent with no limits of its own (``write(commands, dt)``, ``read()``). Work through the TODOs 15.1 to 15.3 in
order (15.4 is the controllers YAML); notebook 15 runs your component, and ``rrbot-workshop grade 15`` compares what the
device receives with what Jazzy's limiters give, cycle by cycle, to 1e-9.
"""

from __future__ import annotations

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.hardware import SystemInterface
from rrbot_workshop.hardware.my_robot import MyRobotDevice
from rrbot_workshop.joint_limits import (
    JointControlInterfacesData,
    JointSaturationLimiter,
    JointSoftLimiter,
    get_joint_limits,
    get_soft_joint_limits,
    load_joint_limits_yaml,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["MyRobotHardware"]

#: The command interfaces a joint of the device may declare: exactly one of these.
MODES = ("effort", "position")


class MyRobotHardware(SystemInterface):
    """MyRobot's arm: effort joints and position joints, their limits enforced in ``write``."""

    def __init__(self) -> None:
        super().__init__()
        self.device: MyRobotDevice | None = None
        self.joints: list[str] = []  # joint names, in the description's order
        self.modes: list[str] = []  # each joint's command interface: "effort" or "position"
        self.limiters: list[JointSaturationLimiter] = []  # one per joint (a JointSoftLimiter is one too)

    # ------------------------------------------------------------------------ 15.1 on_init: the interfaces

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        if super().on_init(info) is not CallbackReturn.SUCCESS:
            return CallbackReturn.ERROR
        for joint in info.joints:
            commands = [interface.name for interface in joint.command_interfaces]
            states = [interface.name for interface in joint.state_interfaces]
            if len(commands) != 1 or commands[0] not in MODES:
                self.logger.error("joint '%s' has command interfaces %s; a motor of MyRobot takes exactly one, effort "
                                  "or position", joint.name, commands)
                return CallbackReturn.ERROR
            if "position" not in states or "velocity" not in states:
                self.logger.error("joint '%s' has state interfaces %s; the device reports position and velocity",
                                  joint.name, states)
                return CallbackReturn.ERROR
        self.joints = [joint.name for joint in info.joints]
        self.modes = [joint.command_interfaces[0].name for joint in info.joints]

        # ------------------------------------------------------------------ 15.2 the limiters
        path = info.hardware_parameters.get("joint_limits_file", "")
        if not path:
            self.logger.error("'%s' needs the hardware parameter joint_limits_file (the joint_limits.yaml)", info.name)
            return CallbackReturn.ERROR
        try:
            params = load_joint_limits_yaml(path)
            self.limiters = []
            for joint in self.joints:
                hard = get_joint_limits(joint, params, info.limits.get(joint))
                soft = get_soft_joint_limits(joint, params, info.soft_limits.get(joint))
                if soft is not None:
                    self.limiters.append(JointSoftLimiter([joint], [hard], [soft]))
                else:
                    self.limiters.append(JointSaturationLimiter([joint], [hard]))
        except RRBotWorkshopError as exc:
            self.logger.error("'%s': the joint limits cannot be used: %s", info.name, exc)
            return CallbackReturn.ERROR
        return CallbackReturn.SUCCESS

    # ------------------------------------------------------------------------ given: lifecycle and read

    def on_configure(self, previous_state: State) -> CallbackReturn:
        self.device = MyRobotDevice(self.modes)
        self.read(0.0, 0.0)
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        self.device.enable()
        for joint, mode in zip(self.joints, self.modes, strict=True):
            # no jump: a position joint is commanded where it is, an effort joint gets no torque
            self.set_command(f"{joint}/{mode}", self.get_state(f"{joint}/position") if mode == "position" else 0.0)
        for limiter in self.limiters:
            limiter.reset_internals()  # the limiters start again from the measured state
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        self.device.disable()
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        self.device = None
        return CallbackReturn.SUCCESS

    def read(self, time: float, period: float) -> ReturnType:
        positions, velocities, efforts = self.device.read()
        for joint, position, velocity, effort in zip(self.joints, positions, velocities, efforts, strict=True):
            self.set_state(f"{joint}/position", position)
            self.set_state(f"{joint}/velocity", velocity)
            if f"{joint}/effort" in self.state_interface_names:
                self.set_state(f"{joint}/effort", effort)
        return ReturnType.OK

    # ------------------------------------------------------------------------ 15.3 write: limits, then the device

    def write(self, time: float, period: float) -> ReturnType:
        commands = []
        for joint, mode, limiter in zip(self.joints, self.modes, self.limiters, strict=True):
            actual = JointControlInterfacesData(joint, position=self.get_state(f"{joint}/position"),
                                                velocity=self.get_state(f"{joint}/velocity"))
            desired = JointControlInterfacesData(joint)
            setattr(desired, mode, self.get_command(f"{joint}/{mode}"))
            limiter.enforce(actual, desired, period)
            commands.append(getattr(desired, mode))
        self.device.write(commands, period)
        return ReturnType.OK
