"""The spline math of the joint trajectory controller: one segment between two waypoints.

The polynomial of a segment depends on which fields *both* of its waypoints carry, as in ros2_controllers: positions
only -> linear, positions and velocities -> cubic, positions, velocities and accelerations -> quintic. Efforts, when
present, are interpolated linearly. A waypoint given only as velocities or accelerations gets the missing fields
integrated with Heun's rule (trapezoids) from the previous waypoint (:func:`deduce_from_derivatives`). A linear
segment sampled on many cycles keeps its slopes (:class:`LinearSegment`). Continuous joints take the shortest way
round (:func:`shortest_angular_distance`, :func:`wraparound_joint`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.exceptions import ArgumentError
from rrbot_workshop.middleware.arguments import number
from rrbot_workshop.msgs import JointTrajectoryPoint

__all__ = [
    "LinearSegment",
    "is_spline",
    "interpolate_between_points",
    "deduce_from_derivatives",
    "wraparound_joint",
    "shortest_angular_distance",
]


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


def is_spline(p0: JointTrajectoryPoint, p1: JointTrajectoryPoint, tau: float, big_t: float) -> bool:
    """Whether the segment from ``p0`` to ``p1`` (``big_t`` [s] long) is a spline at ``tau`` [s] into it: both
    waypoints carry velocities or both carry accelerations, and ``tau`` lies within the segment (outside it, and
    otherwise, the state is a linear blend)."""
    has_vel = bool(p0.velocities) and bool(p1.velocities)
    has_acc = bool(p0.accelerations) and bool(p1.accelerations)
    return (has_vel or has_acc) and 0.0 <= tau <= big_t


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

    Raises:
        ArgumentError: If a time is not a finite number, a waypoint is not a JointTrajectoryPoint, or the two
            waypoints' positions differ in length.
    """
    _check_points(t0, p0, t1, p1, t)
    # the linear blend gives the efforts on every segment, and the whole state outside [t0, t1] or without
    # velocities and accelerations on both waypoints
    out = LinearSegment(t0, p0, t1, p1).at(t)
    big_t, tau = t1 - t0, t - t0
    if not is_spline(p0, p1, tau, big_t):
        return out
    has_vel = bool(p0.velocities) and bool(p1.velocities)
    has_acc = bool(p0.accelerations) and bool(p1.accelerations)
    dim = len(p0.positions)
    tt = _powers(tau, 5)
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
    """A linear segment between two waypoints, its slopes worked out once (the linear blend of
    :func:`interpolate_between_points`).

    A trajectory samples the same segment on many cycles (twice per cycle: the state and, one period ahead, the
    command). The slopes depend on the segment only; each sample then costs one multiply-add per joint, done by
    numpy from :data:`_NUMPY_FROM` joints on, with the same operations on the same doubles in the same order as the
    list path: the samples are bit-identical either way.

    Args:
        t0: Time of the first waypoint in [s].
        p0: First waypoint.
        t1: Time of the second waypoint in [s].
        p1: Second waypoint.
    """

    __slots__ = ("t0", "t1", "p0", "p1", "_dim", "_joints", "_big_t", "_x0", "_slopes", "_e0", "_effort_slopes", "_np")

    def __init__(self, t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint) -> None:
        self.t0, self.t1, self.p0, self.p1 = t0, t1, p0, p1
        dim = self._dim = len(p0.positions)
        self._joints = range(dim)
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
        """The state at time ``t`` (clamped to the segment): positions and efforts blended, velocities the slopes,
        accelerations 0."""
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
        else:  # indexing over a prepared range: for a few joints the cheapest loop (zip with strict= is not)
            x0, slopes, joints = self._x0, self._slopes, self._joints
            positions = [x0[i] + slopes[i] * tau for i in joints]
            e0l, esl = self._e0, self._effort_slopes
            if e0l is None:
                effort = [0.0] * dim
            elif esl is not None:
                effort = [e0l[i] + esl[i] * tau for i in joints]
            else:
                effort = [e + 0.0 for e in e0l]
        return JointTrajectoryPoint(positions, list(self._slopes), [0.0] * dim, effort, t - self.t0)


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


def _check_points(t0: Any, p0: Any, t1: Any, p1: Any, t: Any) -> None:
    """Refuse what :func:`interpolate_between_points` cannot interpolate, naming the argument."""
    function = "interpolate_between_points"
    for argument, value in (("t0", t0), ("t1", t1), ("t", t)):
        number(function, argument, value)
    for argument, point in (("p0", p0), ("p1", p1)):
        if not isinstance(point, JointTrajectoryPoint):
            raise ArgumentError(function, argument, point, "a JointTrajectoryPoint")
    if len(p0.positions) != len(p1.positions):
        raise ArgumentError(function, "p1.positions", p1.positions,
                            f"as many positions as p0.positions ({len(p0.positions)})")
