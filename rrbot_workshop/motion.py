"""Jerk-limited point-to-point motion with ruckig, as a ``JointTrajectory`` for the JTC.

The JTC's splines only join the waypoints they are given: a single far waypoint gives a linear or
cubic move whose acceleration jumps at the start and the end. :func:`jerk_limited_trajectory`
instead asks ruckig (offline, on this machine) for the time-optimal motion within velocity,
acceleration and jerk limits, and samples it densely with positions, velocities and accelerations,
so the JTC's quintic interpolation between samples reproduces it.

ruckig's intermediate waypoints are never used: in the community version they call a cloud service.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.msgs import Header, JointTrajectory, JointTrajectoryPoint

__all__ = ["jerk_limited_trajectory"]

_OWNER = "jerk_limited_trajectory"


def _per_joint(name: str, value: float | Sequence[float], n: int, positive: bool) -> list[float]:
    values = [float(value)] * n if isinstance(value, int | float) else [float(v) for v in value]
    if len(values) != n:
        raise ParameterError(_OWNER, name, f"has {len(values)} entries for {n} joints")
    bad = [v for v in values if not math.isfinite(v) or (positive and v <= 0.0)]
    if bad:
        raise ParameterError(_OWNER, name, f"must be finite{' and > 0' if positive else ''}, got {bad}")
    return values


def jerk_limited_trajectory(
    joint_names: Sequence[str],
    start_positions: Sequence[float],
    goal_positions: Sequence[float],
    max_velocity: float | Sequence[float],
    max_acceleration: float | Sequence[float],
    max_jerk: float | Sequence[float],
    sample_period: float = 0.01,
    start_velocities: Sequence[float] | None = None,
) -> JointTrajectory:
    """A time-optimal, jerk-limited move from rest (or ``start_velocities``) to rest at the goal.

    All joints are synchronised to arrive together.

    Args:
        joint_names: Joint names of the trajectory.
        start_positions: Start positions in [rad].
        goal_positions: Goal positions in [rad].
        max_velocity: Limit in [rad/s], one for all joints or one per joint.
        max_acceleration: Limit in [rad/s^2].
        max_jerk: Limit in [rad/s^3].
        sample_period: Time between points in [s].
        start_velocities: Start velocities in [rad/s]; zeros by default.

    Returns:
        A trajectory (header stamp 0: "start now") whose points carry positions, velocities and
        accelerations, from ``time_from_start`` 0 to the motion's duration; the last point is the
        goal with zero velocity and acceleration.

    Raises:
        ParameterError: If a list has the wrong length, a limit is not finite and positive, the sample
            period is not positive, or ruckig finds no trajectory.
    """
    from ruckig import InputParameter, Result, Ruckig, Trajectory  # imported lazily: a compiled extension

    n = len(joint_names)
    if n == 0:
        raise ParameterError(_OWNER, "joint_names", "must not be empty")
    start = _per_joint("start_positions", start_positions, n, positive=False)
    goal = _per_joint("goal_positions", goal_positions, n, positive=False)
    v0 = _per_joint("start_velocities", start_velocities if start_velocities is not None else 0.0, n, False)
    if not (math.isfinite(sample_period) and sample_period > 0.0):
        raise ParameterError(_OWNER, "sample_period", f"must be > 0 [s], got {sample_period}")
    inp = InputParameter(n)
    inp.current_position, inp.current_velocity, inp.current_acceleration = start, v0, [0.0] * n
    inp.target_position, inp.target_velocity, inp.target_acceleration = goal, [0.0] * n, [0.0] * n
    inp.max_velocity = _per_joint("max_velocity", max_velocity, n, positive=True)
    inp.max_acceleration = _per_joint("max_acceleration", max_acceleration, n, positive=True)
    inp.max_jerk = _per_joint("max_jerk", max_jerk, n, positive=True)
    traj = Trajectory(n)
    result = Ruckig(n).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise ParameterError(_OWNER, "limits", f"ruckig found no trajectory ({result.name})")
    duration = float(traj.duration)
    count = max(1, math.ceil(duration / sample_period - 1e-9))
    times = [k * sample_period for k in range(count)] + [duration]
    points = []
    for t in times:
        pos, vel, acc = traj.at_time(t)
        points.append(JointTrajectoryPoint(positions=list(pos), velocities=list(vel), accelerations=list(acc),
                                           time_from_start=t))
    points[-1] = JointTrajectoryPoint(positions=list(goal), velocities=[0.0] * n, accelerations=[0.0] * n,
                                      time_from_start=duration)
    if duration == 0.0:  # already there: one point
        points = points[-1:]
    return JointTrajectory(Header(stamp=0.0), list(joint_names), points)
