"""Trajectory sampling and spline interpolation of the joint trajectory controller.

A :class:`Trajectory` holds one ``JointTrajectory`` message and the state the robot was in when it
started ("the point before the trajectory"). :meth:`Trajectory.sample` answers "where should the
joints be at time t?": before the first waypoint it interpolates from that starting state, inside a
segment between the segment's two waypoints, and after the last waypoint it holds the last one.

The polynomial used for a segment depends on which fields *both* of its waypoints carry, as in
ros2_controllers: positions only -> linear, positions and velocities -> cubic, positions,
velocities and accelerations -> quintic. Efforts, when present, are interpolated linearly. A waypoint
given only as velocities or accelerations gets the missing fields integrated with Heun's rule
(trapezoids) from the previous waypoint (see :func:`deduce_from_derivatives`). The math of one segment is in
:mod:`rrbot_workshop.controllers.interpolation`.
"""

from __future__ import annotations

import copy
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.controllers.interpolation import (
    LinearSegment,
    deduce_from_derivatives,
    interpolate_between_points,
    is_spline,
    shortest_angular_distance,
    wraparound_joint,
)
from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

__all__ = [
    "InterpolationMethod",
    "TrajectorySample",
    "Trajectory",
    "LinearSegment",
    "interpolate_between_points",
    "deduce_from_derivatives",
    "wraparound_joint",
    "shortest_angular_distance",
]


class InterpolationMethod(enum.Enum):
    """``interpolation_method`` parameter values."""

    SPLINES = "splines"
    NONE = "none"


#: ``InterpolationMethod.NONE``, looked up once (an enum member costs a class attribute lookup every time).
_NO_INTERPOLATION = InterpolationMethod.NONE


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
        #: The segment sampled last: (from, until, t0, p0, t1, p1, start index, end index, time_from_start or None,
        #: its LinearSegment or None for a spline). A sample within [from, until) is that segment's, found without the
        #: search (see :meth:`sample`).
        self._hit: tuple[Any, ...] | None = None
        #: From this time on the trajectory has played out (the search found it so, and no waypoint is later): a sample
        #: holds the last waypoint, found without the search (see :meth:`sample`).
        self._ended_from = math.inf
        #: The last sample: (time, method, sample). The JTC samples one period ahead, so this cycle's desired state is
        #: the last cycle's command: the same time, the same trajectory, the same numbers (see :meth:`sample`).
        self._last: tuple[float, InterpolationMethod, TrajectorySample | None] | None = None
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
        self._hit = None
        self._ended_from = math.inf
        self._last = None

    def set_point_before_trajectory_msg(
        self, current_time: float, current_point: JointTrajectoryPoint, joints_angle_wraparound: Sequence[bool] = ()
    ) -> None:
        """Set the state the trajectory starts from.

        If the first waypoint has velocities (accelerations) and the state has none, the state gets
        zeros, so that the first segment uses the same spline degree as the rest. Continuous joints are
        shifted by whole turns towards the first waypoint.
        """
        self._time_before = current_time
        self._hit = None
        self._ended_from = math.inf
        self._last = None
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
        if is_spline(p0, p1, t - t0, t1 - t0):
            return interpolate_between_points(t0, p0, t1, p1, t)
        segment = self._segment
        if segment is None or not segment.matches(t0, p0, t1, p1):
            segment = self._segment = LinearSegment(t0, p0, t1, p1)
        return segment.at(t)

    def sample(self, sample_time: float, method: InterpolationMethod = InterpolationMethod.SPLINES) -> TrajectorySample | None:
        """The desired state at ``sample_time`` [s].

        The first call fixes the start time when the header stamp is 0. Asked again for the time of the last
        sample (and nothing changed since: no new message, no new state before it), it returns that sample.

        Returns:
            The sample, or None if there is no message, it has no points, or ``sample_time`` is before
            the state the trajectory starts from.
        """
        last = self._last
        if last is not None and last[0] == sample_time and last[1] is method:
            return last[2]  # sampled at this very time since the trajectory last changed: nothing to compute again
        hit = self._hit
        if hit is not None and hit[0] <= sample_time < hit[1] and method is not _NO_INTERPOLATION:
            # the segment of the last sample, whose fields were deduced then: the same numbers, without the search
            _, _, t0, p0, t1, p1, start, end, time_from_start, segment = hit
            spline = (p0.velocities and p1.velocities) or (p0.accelerations and p1.accelerations)  # is_spline inside
            if segment is not None and not spline:
                out = segment.at(sample_time)  # the linear segment found with the hit: its slopes as they were
            else:
                out = self._interpolate(t0, p0, t1, p1, sample_time)
            if time_from_start is not None:
                out.time_from_start = time_from_start
            result: TrajectorySample | None = TrajectorySample(out, start, end)
        elif sample_time >= self._ended_from:
            result = self._hold_last_waypoint()
        else:
            result = self._sample(sample_time, method)
        self._last = (sample_time, method, result)
        return result

    def _linear_segment(self, t0: float, p0: JointTrajectoryPoint, t1: float, p1: JointTrajectoryPoint,
                        ) -> LinearSegment | None:
        """The segment :meth:`_interpolate` just sampled from ``p0`` to ``p1``, if it was linear (else None)."""
        segment = self._segment
        return segment if segment is not None and segment.matches(t0, p0, t1, p1) else None

    def _sample(self, sample_time: float, method: InterpolationMethod) -> TrajectorySample | None:
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
                self._hit = (self._time_before, first_time, self._time_before, self._state_before, first_time, first,
                             0, 0, None, self._linear_segment(self._time_before, self._state_before, first_time, first))
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
                    self._hit = (t0, t1, t0, points[i], t1, points[i + 1], i, i + 1, points[i + 1].time_from_start,
                                 self._linear_segment(t0, points[i], t1, points[i + 1]))
                out.time_from_start = points[i + 1].time_from_start
                return TrajectorySample(out, i, i + 1)
        # the whole trajectory has played out: hold the last waypoint, now and at any time past every waypoint (max
        # skips a NaN time, which no segment contains; a NaN time before the trajectory gives NaN: no shortcut)
        self._ended_from = max(self._time_before, *(self._start_time + p.time_from_start for p in points))
        return self._hold_last_waypoint()

    def _hold_last_waypoint(self) -> TrajectorySample:
        """The sample once the trajectory has played out: the last waypoint, with zeros for its missing fields."""
        points = self._msg.points  # type: ignore[union-attr]  # only called with a message that has points
        out = points[-1].copy()
        n = len(out.positions)
        if not out.velocities:
            out.velocities = [0.0] * n
        if not out.accelerations:
            out.accelerations = [0.0] * n
        if not out.effort:
            out.effort = [0.0] * n
        return TrajectorySample(out, len(points) - 1, len(points))
