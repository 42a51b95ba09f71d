"""joint_limits: joint limits from parameters, and the saturation and soft limiters of ros2_control's ``joint_limits``
package (Jazzy semantics).

* :func:`get_joint_limits` and :func:`get_soft_joint_limits` read a node's ``joint_limits.<joint>.*`` parameters
  (nested or dotted) over the limits they are given, usually the URDF's; :func:`load_joint_limits_yaml` reads a
  ``joint_limits.yaml`` written for ROS 1 (``joint_limits:`` at the top) or ROS 2 (in a node's ``ros__parameters``).
  The rules are in :mod:`~rrbot_workshop.joint_limits.rosparam`.
* :class:`JointSaturationLimiter` clamps one joint's commands into its limits; :class:`JointSoftLimiter` also slows
  it down as it nears its soft limits. Both take :class:`JointControlInterfacesData` (optional position, velocity,
  effort, acceleration, jerk): ``enforce(actual, desired, dt)`` changes ``desired`` in place and returns whether it
  limited anything. One limiter per joint, as in Jazzy.
  :class:`JointTrajectoryPointSaturationLimiter` limits a trajectory point of several joints at once.

**Where the parameters come from.** In Jazzy the resource manager limits commands (``enforce_command_limits: true``)
with the limits of the URDF alone; ``joint_limits.*`` parameters are read by whoever builds a limiter from its own
node's parameters (a controller, a hardware component). This library also reads them for the resource manager, from
the **controller manager's** ``ros__parameters`` (and from ``/**``, which reaches it too), over the URDF's: that is
where a ROS 1 user loads a ``joint_limits.yaml`` next to the controllers. A YAML without ``joint_limits`` behaves
exactly as in Jazzy::

    controller_manager:
      ros__parameters:
        update_rate: 100
        enforce_command_limits: true
        joint_limits:
          joint1: {has_velocity_limits: true, max_velocity: 0.5}

or, with the ROS 1 file kept as it is::

    config = yaml.safe_load(Path("config/controllers.yaml").read_text())
    config["controller_manager"]["ros__parameters"].update(rw.joint_limits.load_joint_limits_yaml("config/joint_limits.yaml"))
    system = rw.bringup("my_robot", config, ...)

**A limiter of your own** (in a controller's ``on_configure``; a hardware component has ``self.info.limits`` and
``self.info.soft_limits`` from the URDF, and its parameters from wherever it reads them, a ``joint_limits.yaml`` for
instance)::

    from rrbot_workshop import joint_limits as jl
    info = rw.description.parse_ros2_control(self.get_robot_description())[0]   # the URDF's limits
    self.limiter = jl.JointSoftLimiter()  # Jazzy's: one limiter per joint
    self.limiter.init_from_parameters(["joint1"], self.get_node().parameters, info.limits, info.soft_limits)
    # each update(): ``desired`` is limited in place
    self.limiter.enforce(jl.JointControlInterfacesData("joint1", position=measured), desired, period)

``JointSaturationLimiter(["joint1"], [jl.get_joint_limits("joint1", params, urdf_limits)])`` builds one directly.
"""

from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.joint_limits.data_structures import (
    JointControlInterfacesData,
    JointInterfacesCommandLimiterData,
    LimitRange,
)
from rrbot_workshop.joint_limits.helpers import (
    OUT_OF_BOUNDS_EXCEPTION_TOLERANCE,
    POSITION_BOUNDS_TOLERANCE,
    compute_acceleration_limits,
    compute_effort_limits,
    compute_position_limits,
    compute_velocity_limits,
)
from rrbot_workshop.joint_limits.limiter_interface import JointLimiterInterface
from rrbot_workshop.joint_limits.rosparam import (
    HARD_LIMIT_PARAMETERS,
    SOFT_LIMIT_PARAMETERS,
    declare_parameters,
    get_joint_limits,
    get_soft_joint_limits,
    joint_limits_parameters,
    load_joint_limits_yaml,
)
from rrbot_workshop.joint_limits.saturation_limiter import JointSaturationLimiter
from rrbot_workshop.joint_limits.soft_limiter import (
    SOFT_LIMIT_REACH_VELOCITY,
    JointSoftLimiter,
    has_soft_limits,
    has_soft_position_limits,
)
from rrbot_workshop.joint_limits.trajectory_limiter import JointTrajectoryPointSaturationLimiter

__all__ = [
    "JointLimits",
    "SoftJointLimits",
    "JointControlInterfacesData",
    "JointInterfacesCommandLimiterData",
    "LimitRange",
    "HARD_LIMIT_PARAMETERS",
    "SOFT_LIMIT_PARAMETERS",
    "declare_parameters",
    "joint_limits_parameters",
    "get_joint_limits",
    "get_soft_joint_limits",
    "load_joint_limits_yaml",
    "JointLimiterInterface",
    "JointSaturationLimiter",
    "JointSoftLimiter",
    "JointTrajectoryPointSaturationLimiter",
    "has_soft_limits",
    "has_soft_position_limits",
    "SOFT_LIMIT_REACH_VELOCITY",
    "POSITION_BOUNDS_TOLERANCE",
    "OUT_OF_BOUNDS_EXCEPTION_TOLERANCE",
    "compute_position_limits",
    "compute_velocity_limits",
    "compute_effort_limits",
    "compute_acceleration_limits",
]
