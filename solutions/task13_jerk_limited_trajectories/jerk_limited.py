"""Task 13: time-optimal, jerk-limited moves with ruckig, sent to the joint trajectory controller.

ruckig plans from the current state to a goal within velocity, acceleration and jerk limits; the joint trajectory
controller executes a ``JointTrajectory``. This module joins the two: it takes the velocity and position limits from
the robot's description (the ``<limit>`` of each joint, as parsed for ``<ros2_control>``), refuses goals outside
them, and samples ruckig's trajectory into points that carry positions, velocities and accelerations, so the JTC's
quintic interpolation between points follows ruckig's motion.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory

from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

__all__ = ["joint_limits", "plan"]


def joint_limits(urdf: str, joint_names: Sequence[str]) -> dict[str, tuple[float, float, float]]:
    """``{joint: (min_position [rad], max_position [rad], max_velocity [rad/s])}`` from the description.

    For any description and any of its joints, in the order asked; the values are those of the joints' URDF
    ``<limit>`` as parsed for ``<ros2_control>`` (the self-check compares them to 1e-9).

    Raises:
        ValueError: If a joint is in no ``<ros2_control>`` tag, or has no position or velocity limit.
    """
    limits = {name: lim for info in parse_ros2_control(urdf) for name, lim in info.limits.items()}
    out = {}
    for name in joint_names:
        if name not in limits:
            raise ValueError(f"joint '{name}' is not in the description's <ros2_control> tags (joints: {sorted(limits)})")
        lim = limits[name]
        if not (lim.has_position_limits and lim.has_velocity_limits):
            raise ValueError(f"joint '{name}' has no position or velocity limit in the URDF")
        out[name] = (lim.min_position, lim.max_position, lim.max_velocity)
    return out


def plan(
    urdf: str,
    joint_names: Sequence[str],
    start: Sequence[float],
    goal: Sequence[float],
    max_acceleration: float,
    max_jerk: float,
    sample_period: float = 0.01,
) -> JointTrajectory:
    """A jerk-limited move from rest at ``start`` to rest at ``goal``, all joints arriving together.

    The move is ruckig's time-optimal one within the description's velocity limits and the given acceleration and jerk
    limits: it lasts ruckig's duration (the self-check compares it to 1e-6 s). Every joint that moves arrives at its
    goal at that duration, not before (ruckig synchronizes the joints by default). No point exceeds a limit by more
    than 1e-6 (in rad/s, rad/s²; the change of acceleration between two points is at most ``max_jerk * dt + 1e-6``).
    Points come at most ``sample_period`` apart, ``ceil(duration / sample_period)`` of them after t = 0 (a point at
    t = 0 may be added), each with ruckig's positions, velocities and accelerations at its time, for ``joint_names``
    in that order; the last is the goal at rest (to 1e-6) at the duration.

    Args:
        urdf: The robot's URDF (its ``<limit>`` tags bound positions and velocities).
        joint_names: Joints to move.
        start: Start positions in [rad].
        goal: Goal positions in [rad].
        max_acceleration: Acceleration limit of every joint in [rad/s^2].
        max_jerk: Jerk limit of every joint in [rad/s^3].
        sample_period: Time between trajectory points in [s].

    Raises:
        ValueError: If the lists' lengths differ, a goal is outside its joint's position limits (below the lower or
            above the upper; a goal at a limit is within them), naming the joint, or ruckig finds no trajectory.
    """
    n = len(joint_names)
    if not (len(start) == len(goal) == n):
        raise ValueError(f"{n} joints but {len(start)} start and {len(goal)} goal positions")
    limits = joint_limits(urdf, joint_names)
    for name, g in zip(joint_names, goal, strict=True):
        low, high, _ = limits[name]
        if not low <= g <= high:
            raise ValueError(f"goal {g} rad of joint '{name}' is outside its limits [{low}, {high}] rad")
    inp = InputParameter(n)
    inp.current_position, inp.current_velocity, inp.current_acceleration = list(start), [0.0] * n, [0.0] * n
    inp.target_position, inp.target_velocity, inp.target_acceleration = list(goal), [0.0] * n, [0.0] * n
    inp.max_velocity = [limits[name][2] for name in joint_names]
    inp.max_acceleration = [max_acceleration] * n
    inp.max_jerk = [max_jerk] * n
    trajectory = Trajectory(n)
    try:
        result = Ruckig(n).calculate(inp, trajectory)
    except RuckigError as exc:  # e.g. a zero limit: ruckig refuses the input itself
        why = next((line for line in str(exc).splitlines() if line.strip()), "its input is invalid")
        raise ValueError(f"ruckig found no trajectory for max_acceleration={max_acceleration}, "
                         f"max_jerk={max_jerk}: {why}") from exc
    if result not in (Result.Working, Result.Finished):
        raise ValueError(f"ruckig found no trajectory: {result.name}")
    duration = trajectory.duration
    times = [k * sample_period for k in range(math.ceil(duration / sample_period - 1e-9))] + [duration]
    points = []
    for t in times[1:]:
        position, velocity, acceleration = trajectory.at_time(t)
        points.append(JointTrajectoryPoint(positions=list(position), velocities=list(velocity),
                                           accelerations=list(acceleration), time_from_start=t))
    points[-1] = JointTrajectoryPoint(positions=list(goal), velocities=[0.0] * n, accelerations=[0.0] * n,
                                      time_from_start=duration)
    return JointTrajectory(joint_names=list(joint_names), points=points)
