"""Trajectory sampling and spline interpolation of the joint trajectory controller.

A :class:`Trajectory` holds one ``JointTrajectory`` message and the state the robot was in when it
started ("the point before the trajectory"). :meth:`Trajectory.sample` answers "where should the
joints be at time t?": before the first waypoint it interpolates from that starting state, inside a
segment between the segment's two waypoints, and after the last waypoint it holds the last one.

The polynomial used for a segment depends on which fields *both* of its waypoints carry, as in
ros2_controllers: positions only -> linear, positions and velocities -> cubic, positions,
velocities and accelerations -> quintic. Efforts, when present, are interpolated linearly. A waypoint
given only as velocities or accelerations gets the missing fields integrated with Heun's rule
(trapezoids) from the previous waypoint (see :func:`deduce_from_derivatives`).
"""

from __future__ import annotations

import copy
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

__all__ = [
    "InterpolationMethod",
    "TrajectorySample",
    "Trajectory",
    "interpolate_between_points",
    "deduce_from_derivatives",
    "wraparound_joint",
    "shortest_angular_distance",
]


class InterpolationMethod(enum.Enum):
    """``interpolation_method`` parameter values."""

    SPLINES = "splines"
    NONE = "none"


def shortest_angular_distance(from_angle: float, to_angle: float) -> float:
    """Signed angle in [rad] from ``from_angle`` to ``to_angle``, within [-pi, pi] (as ``angles`` does)."""
    diff = math.fmod(to_angle - from_angle, 2.0 * math.pi)
    if diff > math.pi:
        diff -= 2.0 * math.pi
    elif diff < -math.pi:
        diff += 2.0 * math.pi
    return diff


def wraparound_joint(current: list[float], target: Sequence[float], wraparound: Sequence[bool]) -> None:
    """Shift each continuous joint of ``current`` by whole turns so it is closest to ``target`` (in place)."""
    for i, wrap in enumerate(wraparound):
        if wrap and i < len(current) and i < len(target):
            dist = shortest_angular_distance(current[i], target[i])
            if abs(abs(dist) - math.pi) < 1e-9:  # exactly half a turn: go the way the numbers go
                dist = abs(dist) if target[i] > current[i] else -abs(dist)
            current[i] = target[i] - dist


def _powers(x: float, n: int) -> list[float]:
    out = [1.0]
    for _ in range(n):
        out.append(out[-1] * x)
    return out


def interpolate_between_points(
    t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint, t: float
) -> JointTrajectoryPoint:
    """The state at time ``t`` on the spline from waypoint ``p0`` (at ``t0``) to ``p1`` (at ``t1``).

    Linear, cubic or quintic depending on whether both waypoints carry velocities and accelerations.
    Outside ``[t0, t1]`` the time is clamped to the nearer end and a linear blend is used.

    Args:
        t0: Time of the first waypoint in [s].
        p0: First waypoint (positions required).
        t1: Time of the second waypoint in [s].
        p1: Second waypoint (positions required).
        t: Sample time in [s].

    Returns:
        A point with positions [rad], velocities [rad/s], accelerations [rad/s^2] and efforts, all of
        the joint count; ``time_from_start`` is ``t - t0``.
    """
    dim = len(p0.positions)
    big_t = t1 - t0
    tau = t - t0
    has_vel = bool(p0.velocities) and bool(p1.velocities)
    has_acc = bool(p0.accelerations) and bool(p1.accelerations)
    if tau < 0.0:
        tau = 0.0
        has_vel = has_acc = False
    if tau > big_t:
        tau = big_t
        has_vel = has_acc = False
    zeros = [0.0] * dim
    effort = zeros
    if p0.effort and p1.effort:
        e0, e1 = p0.effort, p1.effort
        if big_t != 0.0:
            effort = [e0[i] + (e1[i] - e0[i]) / big_t * tau for i in range(dim)]
        else:  # a zero slope: e0 + 0.0 (which also turns -0.0 into 0.0, as the general formula does)
            effort = [e0[i] + 0.0 for i in range(dim)]
    if not has_vel and not has_acc:  # linear: the common case of a goal given by positions only
        pos0, pos1 = p0.positions, p1.positions
        slopes = [(pos1[i] - pos0[i]) / big_t for i in range(dim)] if big_t != 0.0 else list(zeros)
        return JointTrajectoryPoint(positions=[pos0[i] + slopes[i] * tau for i in range(dim)], velocities=slopes,
                                    accelerations=list(zeros), effort=effort if effort is not zeros else list(zeros),
                                    time_from_start=t - t0)
    tt = _powers(tau, 5)
    out = JointTrajectoryPoint(positions=list(zeros), velocities=list(zeros), accelerations=list(zeros),
                               effort=effort if effort is not zeros else list(zeros), time_from_start=t - t0)
    if has_vel and not has_acc:
        T = _powers(big_t, 3)
        for i in range(dim):
            x0, v0, x1, v1 = p0.positions[i], p0.velocities[i], p1.positions[i], p1.velocities[i]
            c2 = c3 = 0.0
            if big_t != 0.0:
                c2 = (-3.0 * x0 + 3.0 * x1 - 2.0 * v0 * T[1] - v1 * T[1]) / T[2]
                c3 = (2.0 * x0 - 2.0 * x1 + v0 * T[1] + v1 * T[1]) / T[3]
            out.positions[i] = x0 + v0 * tt[1] + c2 * tt[2] + c3 * tt[3]
            out.velocities[i] = v0 + 2.0 * c2 * tt[1] + 3.0 * c3 * tt[2]
            out.accelerations[i] = 2.0 * c2 + 6.0 * c3 * tt[1]
    else:
        # Quintic. ros2_controllers has no branch for "accelerations but no velocities" and returns
        # zeros for such a segment (a jump to 0 rad); here missing velocities count as 0 rad/s instead.
        T = _powers(big_t, 5)
        for i in range(dim):
            x0, v0, a0 = p0.positions[i], p0.velocities[i] if p0.velocities else 0.0, p0.accelerations[i]
            x1, v1, a1 = p1.positions[i], p1.velocities[i] if p1.velocities else 0.0, p1.accelerations[i]
            c = [x0, v0, 0.5 * a0, 0.0, 0.0, 0.0]
            if big_t != 0.0:
                c[3] = (-20.0 * x0 + 20.0 * x1 - 3.0 * a0 * T[2] + a1 * T[2] - 12.0 * v0 * T[1] - 8.0 * v1 * T[1]) / (
                    2.0 * T[3]
                )
                c[4] = (30.0 * x0 - 30.0 * x1 + 3.0 * a0 * T[2] - 2.0 * a1 * T[2] + 16.0 * v0 * T[1] + 14.0 * v1 * T[1]) / (
                    2.0 * T[4]
                )
                c[5] = (-12.0 * x0 + 12.0 * x1 - a0 * T[2] + a1 * T[2] - 6.0 * v0 * T[1] - 6.0 * v1 * T[1]) / (
                    2.0 * T[5]
                )
            out.positions[i] = sum(c[k] * tt[k] for k in range(6))
            out.velocities[i] = sum(k * c[k] * tt[k - 1] for k in range(1, 6))
            out.accelerations[i] = sum(k * (k - 1) * c[k] * tt[k - 2] for k in range(2, 6))
    return out


#: From this many joints on, a linear segment is evaluated with numpy (the same IEEE operations, element by element).
_NUMPY_FROM = 16


class LinearSegment:
    """One linear segment of :func:`interpolate_between_points`, its slopes worked out once.

    A trajectory samples the same segment on many cycles (twice per cycle: the state and, one period ahead, the
    command). The slopes depend on the segment only; each sample then costs one multiply-add per joint, done by
    numpy from :data:`_NUMPY_FROM` joints on. The results are those of :func:`interpolate_between_points` bit for bit:
    the same operations on the same doubles, in the same order.

    Args:
        t0: Time of the first waypoint in [s].
        p0: First waypoint.
        t1: Time of the second waypoint in [s].
        p1: Second waypoint.
    """

    __slots__ = ("t0", "t1", "p0", "p1", "_dim", "_big_t", "_x0", "_slopes", "_e0", "_effort_slopes", "_np")

    def __init__(self, t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint) -> None:
        self.t0, self.t1, self.p0, self.p1 = t0, t1, p0, p1
        dim = self._dim = len(p0.positions)
        big_t = self._big_t = t1 - t0
        x0, x1 = p0.positions, p1.positions
        self._x0 = list(x0[:dim])
        self._slopes = [(x1[i] - x0[i]) / big_t for i in range(dim)] if big_t != 0.0 else [0.0] * dim
        self._e0: list[float] | None = None
        self._effort_slopes: list[float] | None = None
        if p0.effort and p1.effort:
            e0, e1 = p0.effort, p1.effort
            self._e0 = [e0[i] for i in range(dim)]
            self._effort_slopes = [(e1[i] - e0[i]) / big_t for i in range(dim)] if big_t != 0.0 else None
        self._np: tuple[Any, ...] | None = None
        if dim >= _NUMPY_FROM:
            import numpy as np

            def arr(values: list[float] | None) -> Any:
                return None if values is None else np.array(values, dtype=float)

            self._np = (arr(self._x0), arr(self._slopes), arr(self._e0), arr(self._effort_slopes))

    def matches(self, t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint) -> bool:
        """Whether this is the segment from ``p0`` at ``t0`` to ``p1`` at ``t1`` (the same point objects)."""
        return self.p0 is p0 and self.p1 is p1 and self.t0 == t0 and self.t1 == t1

    def at(self, t: float) -> JointTrajectoryPoint:
        """The state at time ``t``, clamped to the segment, as :func:`interpolate_between_points` gives it."""
        dim, tau = self._dim, t - self.t0
        if tau < 0.0:
            tau = 0.0
        if tau > self._big_t:
            tau = self._big_t
        if self._np is not None:
            x0, slopes, e0, es = self._np
            positions = (x0 + slopes * tau).tolist()
            if e0 is None:
                effort = [0.0] * dim
            else:
                effort = (e0 + es * tau).tolist() if es is not None else (e0 + 0.0).tolist()
        else:
            x0l, sl = self._x0, self._slopes
            positions = [x0l[i] + sl[i] * tau for i in range(dim)]
            e0l, esl = self._e0, self._effort_slopes
            if e0l is None:
                effort = [0.0] * dim
            elif esl is not None:
                effort = [e0l[i] + esl[i] * tau for i in range(dim)]
            else:
                effort = [e0l[i] + 0.0 for i in range(dim)]
        return JointTrajectoryPoint(positions=positions, velocities=list(self._slopes), accelerations=[0.0] * dim,
                                    effort=effort, time_from_start=t - self.t0)


def deduce_from_derivatives(
    first: JointTrajectoryPoint, second: JointTrajectoryPoint, dim: int, delta_t: float
) -> None:
    """Fill a waypoint given without positions by integrating from the previous one (in place).

    Velocities missing on ``second`` come from the trapezoid of the two accelerations; its positions
    from the trapezoid of the two velocities. Missing fields of ``first`` count as zero. Efforts
    missing on either point become zeros. Nothing changes when ``second`` has positions.

    Args:
        first: The earlier waypoint (or the state before the trajectory).
        second: The later waypoint.
        dim: Number of joints.
        delta_t: Time between the two in [s].
    """
    if not first.effort:
        first.effort = [0.0] * dim
    if not second.effort:
        second.effort = [0.0] * dim
    if second.positions:
        return
    if not first.velocities:
        first.velocities = [0.0] * dim
    if not second.velocities:
        if not first.accelerations:
            first.accelerations = [0.0] * dim
        acc2 = second.accelerations or [0.0] * dim
        second.velocities = [first.velocities[i] + (first.accelerations[i] + acc2[i]) * 0.5 * delta_t for i in range(dim)]
    second.positions = [first.positions[i] + (first.velocities[i] + second.velocities[i]) * 0.5 * delta_t for i in range(dim)]


@dataclass
class TrajectorySample:
    """Result of :meth:`Trajectory.sample`.

    Attributes:
        point: The sampled state.
        start_index: Index of the waypoint that begins the current segment.
        end_index: Index of the waypoint that ends it; ``len(points)`` once the trajectory has ended.
            Before the first waypoint both indices are 0.
    """

    point: JointTrajectoryPoint
    start_index: int
    end_index: int


class Trajectory:
    """One trajectory message being executed, with the state it starts from.

    Args:
        trajectory_msg: The message to execute; it is copied (sampling fills in deduced fields).
        current_time: Time of the state before the trajectory in [s].
        current_point: State of the joints before the trajectory.
        joints_angle_wraparound: Per joint, True for continuous joints.
    """

    def __init__(
        self,
        trajectory_msg: JointTrajectory | None = None,
        current_time: float | None = None,
        current_point: JointTrajectoryPoint | None = None,
        joints_angle_wraparound: Sequence[bool] = (),
    ) -> None:
        self._msg: JointTrajectory | None = None
        self._start_time = 0.0
        self._sampled_already = False
        self._time_before = 0.0
        self._state_before = JointTrajectoryPoint()
        self._segment: LinearSegment | None = None
        if trajectory_msg is not None:
            self.update(trajectory_msg)
        if current_time is not None and current_point is not None:
            self.set_point_before_trajectory_msg(current_time, current_point, joints_angle_wraparound)

    # ----------------------------------------------------------------- state
    def update(self, trajectory_msg: JointTrajectory) -> None:
        """Replace the message; the next sample restarts it."""
        self._msg = copy.deepcopy(trajectory_msg)
        self._start_time = float(trajectory_msg.header.stamp)
        self._sampled_already = False

    def set_point_before_trajectory_msg(
        self, current_time: float, current_point: JointTrajectoryPoint, joints_angle_wraparound: Sequence[bool] = ()
    ) -> None:
        """Set the state the trajectory starts from.

        If the first waypoint has velocities (accelerations) and the state has none, the state gets
        zeros, so that the first segment uses the same spline degree as the rest. Continuous joints are
        shifted by whole turns towards the first waypoint.
        """
        self._time_before = current_time
        state = current_point.copy()
        first = self._msg.points[0] if self._msg is not None and self._msg.points else None
        if first is not None:
            if not state.velocities and first.velocities:
                state.velocities = [0.0] * len(first.velocities)
            if not state.accelerations and first.accelerations:
                state.accelerations = [0.0] * len(first.accelerations)
            wraparound_joint(state.positions, first.positions, joints_angle_wraparound)
        self._state_before = state

    @property
    def trajectory_msg(self) -> JointTrajectory | None:
        """The message being executed (with deduced fields filled in), or None."""
        return self._msg

    @property
    def time_from_start(self) -> float:
        """Start time of the trajectory in [s] (the header stamp, or the first sample time if it was 0)."""
        return self._start_time

    def has_trajectory_msg(self) -> bool:
        """True once a message was set."""
        return self._msg is not None

    def is_sampled_already(self) -> bool:
        """True after the first :meth:`sample` of the current message."""
        return self._sampled_already

    @property
    def state_before_trajectory(self) -> JointTrajectoryPoint:
        """The state the trajectory starts from."""
        return self._state_before

    # ----------------------------------------------------------------- sampling
    def _interpolate(self, t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint,
                     t: float) -> JointTrajectoryPoint:
        """:func:`interpolate_between_points`, with a linear segment's slopes kept while it is sampled."""
        tau = t - t0
        spline = (bool(p0.velocities) and bool(p1.velocities)) or (bool(p0.accelerations) and bool(p1.accelerations))
        if spline and 0.0 <= tau <= t1 - t0:
            return interpolate_between_points(t0, p0, t1, p1, t)
        segment = self._segment
        if segment is None or not segment.matches(t0, p0, t1, p1):
            segment = self._segment = LinearSegment(t0, p0, t1, p1)
        return segment.at(t)

    def sample(self, sample_time: float, method: InterpolationMethod = InterpolationMethod.SPLINES) -> TrajectorySample | None:
        """The desired state at ``sample_time`` [s].

        The first call fixes the start time when the header stamp is 0.

        Returns:
            The sample, or None if there is no message, it has no points, or ``sample_time`` is before
            the state the trajectory starts from.
        """
        msg = self._msg
        if msg is None or not msg.points:
            return None
        if not self._sampled_already:
            if self._start_time == 0.0:
                self._start_time = sample_time
            self._sampled_already = True
        if sample_time < self._time_before:
            return None
        points = msg.points
        dim = len(self._state_before.positions)
        first = points[0]
        first_time = self._start_time + first.time_from_start
        if sample_time < first_time:
            if method is InterpolationMethod.NONE:
                out = self._state_before.copy()
            else:
                deduce_from_derivatives(self._state_before, first, dim, first_time - self._time_before)
                out = self._interpolate(self._time_before, self._state_before, first_time, first, sample_time)
            return TrajectorySample(out, 0, 0)
        for i in range(len(points) - 1):
            t0 = self._start_time + points[i].time_from_start
            t1 = self._start_time + points[i + 1].time_from_start
            if t0 <= sample_time < t1:
                if method is InterpolationMethod.NONE:
                    out = points[i + 1].copy()
                else:
                    deduce_from_derivatives(points[i], points[i + 1], dim, t1 - t0)
                    out = self._interpolate(t0, points[i], t1, points[i + 1], sample_time)
                out.time_from_start = points[i + 1].time_from_start
                return TrajectorySample(out, i, i + 1)
        # the whole trajectory has played out: hold the last waypoint
        out = points[-1].copy()
        n = len(out.positions)
        if not out.velocities:
            out.velocities = [0.0] * n
        if not out.accelerations:
            out.accelerations = [0.0] * n
        if not out.effort:
            out.effort = [0.0] * n
        return TrajectorySample(out, len(points) - 1, len(points))
