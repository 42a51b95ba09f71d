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
        # TODO(task 15.1): what ROS 1's registerInterface did, the description does now: check it. Every joint must
        #   declare exactly one command interface, effort or position (the device has one motor per joint, of one
        #   kind), and the state interfaces position and velocity (the device reports both; effort is optional).
        #   Refuse anything else: log why with self.logger.error, naming the joint, and return CallbackReturn.ERROR.
        #   Then remember, in the description's order, the joints' names (self.joints) and modes (self.modes).
        #   Take every name from info: a robot with other joint names (a prefix) must work too.
        raise NotImplementedError("TODO(task 15.1): check the joints' interfaces in on_init")

        # TODO(task 15.2): one limiter per joint, in self.limiters, as ROS 1's joint_limits_interface built one handle
        #   per joint from joint_limits.yaml. The file is the hardware parameter 'joint_limits_file'
        #   (info.hardware_parameters); load_joint_limits_yaml(path) reads it. For each joint:
        #     hard = get_joint_limits(joint, params, <the URDF's limits of that joint: info.limits>)
        #     soft = get_soft_joint_limits(joint, params, <the URDF's soft limits: info.soft_limits>)
        #   A joint with soft limits gets a JointSoftLimiter([joint], [hard], [soft]), any other a
        #   JointSaturationLimiter([joint], [hard]). No parameter, or a file that cannot be read (the library raises
        #   an RRBotWorkshopError): log why and return CallbackReturn.ERROR.
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
        # TODO(task 15.3): ROS 1 called enforceLimits(period) between the controllers and write(); here it is yours.
        #   For each joint, with its limiter:
        #     actual  = JointControlInterfacesData(joint, position=<its position state>, velocity=<its velocity state>)
        #     desired = JointControlInterfacesData(joint, <mode>=<its command>)   (effort=... or position=...)
        #     limiter.enforce(actual, desired, period)   # changes desired in place
        #   then send the limited commands, one per joint in the description's order, with
        #   self.device.write(commands, period). Never send a command past a limiter.
        raise NotImplementedError("TODO(task 15.3): enforce the limits and write to the device")
