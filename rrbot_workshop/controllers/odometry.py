"""Odometry and speed limiting of a differential-drive base (diff_drive_controller's helpers).

:class:`Odometry` integrates the pose of the base from wheel positions (or wheel travel, or the
commanded twist in open loop). A step with an angular change below 1e-6 rad is integrated as a
straight line (second-order Runge-Kutta), any other as the exact arc. Velocities are rolling means
over the last ``velocity_rolling_window_size`` steps. :class:`SpeedLimiter` clamps a velocity
command, its rate of change and its jerk.
"""

from __future__ import annotations

import collections
import math

__all__ = ["Odometry", "SpeedLimiter"]


class Odometry:
    """Pose and twist of a differential-drive base.

    Args:
        velocity_rolling_window_size: Number of steps averaged for the reported velocities.
    """

    def __init__(self, velocity_rolling_window_size: int = 10) -> None:
        self.wheel_separation = 0.0
        self.left_wheel_radius = 0.0
        self.right_wheel_radius = 0.0
        self._window = max(1, velocity_rolling_window_size)
        self.reset_odometry()
        self._timestamp = 0.0

    def init(self, time: float) -> None:
        """Start counting time at ``time`` [s] (clears the velocity means)."""
        self._reset_accumulators()
        self._timestamp = time

    def set_wheel_params(self, wheel_separation: float, left_wheel_radius: float, right_wheel_radius: float) -> None:
        """Wheel separation and radii in [m] (multipliers already applied)."""
        self.wheel_separation = wheel_separation
        self.left_wheel_radius = left_wheel_radius
        self.right_wheel_radius = right_wheel_radius

    def set_velocity_rolling_window_size(self, size: int) -> None:
        """Number of steps averaged for :attr:`linear` and :attr:`angular`."""
        self._window = max(1, size)
        self._reset_accumulators()

    def reset_odometry(self) -> None:
        """Pose back to the origin; velocities and wheel baselines cleared."""
        self.x = 0.0
        self.y = 0.0
        self.heading = 0.0
        self.linear = 0.0
        self.angular = 0.0
        self._left_old: float | None = None
        self._right_old: float | None = None
        self._reset_accumulators()

    def _reset_accumulators(self) -> None:
        self._lin_acc: collections.deque[float] = collections.deque(maxlen=self._window)
        self._ang_acc: collections.deque[float] = collections.deque(maxlen=self._window)

    def update(self, left_pos: float, right_pos: float, time: float) -> bool:
        """Integrate from wheel positions in [rad] at ``time`` [s].

        Returns:
            False if less than 0.1 ms passed since the last update (nothing is integrated), or if this
            is the first sample, which only sets the wheel baselines.
        """
        dt = time - self._timestamp
        if dt < 0.0001:
            return False
        left = left_pos * self.left_wheel_radius
        right = right_pos * self.right_wheel_radius
        if self._left_old is None or self._right_old is None:
            # ros2_controllers Jazzy measures the first step from 0 rad, so a robot whose wheels do not
            # start at 0 "jumps"; here the first sample is the baseline (as upstream fixed later).
            self._left_old, self._right_old = left, right
            self._timestamp = time
            return False
        d_left, d_right = left - self._left_old, right - self._right_old
        self._left_old, self._right_old = left, right
        return self.update_from_velocity(d_left, d_right, time)

    def update_from_velocity(self, left_distance: float, right_distance: float, time: float) -> bool:
        """Integrate the distances in [m] each wheel travelled since the last update, at ``time`` [s]."""
        dt = time - self._timestamp
        if dt < 0.0001:
            return False
        linear = (left_distance + right_distance) * 0.5
        angular = (right_distance - left_distance) / self.wheel_separation
        self._integrate_exact(linear, angular)
        self._timestamp = time
        self._lin_acc.append(linear / dt)
        self._ang_acc.append(angular / dt)
        self.linear = sum(self._lin_acc) / len(self._lin_acc)
        self.angular = sum(self._ang_acc) / len(self._ang_acc)
        return True

    def update_open_loop(self, linear: float, angular: float, time: float) -> None:
        """Integrate the commanded twist: ``linear`` in [m/s], ``angular`` in [rad/s]."""
        self.linear = linear
        self.angular = angular
        dt = time - self._timestamp
        self._timestamp = time
        self._integrate_exact(linear * dt, angular * dt)

    def _integrate_runge_kutta2(self, linear: float, angular: float) -> None:
        direction = self.heading + angular * 0.5
        self.x += linear * math.cos(direction)
        self.y += linear * math.sin(direction)
        self.heading += angular

    def _integrate_exact(self, linear: float, angular: float) -> None:
        if abs(angular) < 1e-6:
            self._integrate_runge_kutta2(linear, angular)
            return
        heading_old = self.heading
        radius = linear / angular
        self.heading += angular
        self.x += radius * (math.sin(self.heading) - math.sin(heading_old))
        self.y += -radius * (math.cos(self.heading) - math.cos(heading_old))


def _finite(value: float) -> bool:
    return value is not None and math.isfinite(value)


class SpeedLimiter:
    """Limits on one velocity command; a NaN limit is off. All limits are magnitudes except ``min_*``.

    Args:
        min_velocity: Lowest velocity; NaN with a finite ``max_velocity`` means ``-max_velocity``.
        max_velocity: Highest velocity.
        max_acceleration_reverse: Largest speed-up while moving backwards (magnitude).
        max_acceleration: Largest speed-up while moving forwards.
        max_deceleration: Largest slow-down while moving forwards (magnitude).
        max_deceleration_reverse: Largest slow-down while moving backwards (magnitude).
        min_jerk: Lowest jerk; NaN with a finite ``max_jerk`` means ``-max_jerk``.
        max_jerk: Highest jerk.
    """

    def __init__(
        self,
        min_velocity: float = math.nan,
        max_velocity: float = math.nan,
        max_acceleration_reverse: float = math.nan,
        max_acceleration: float = math.nan,
        max_deceleration: float = math.nan,
        max_deceleration_reverse: float = math.nan,
        min_jerk: float = math.nan,
        max_jerk: float = math.nan,
    ) -> None:
        self.max_velocity = max_velocity
        self.min_velocity = min_velocity if _finite(min_velocity) or not _finite(max_velocity) else -max_velocity
        acc = abs(max_acceleration) if _finite(max_acceleration) else math.nan
        dec = abs(max_deceleration) if _finite(max_deceleration) else acc
        self.forward = (dec, acc)  # (slow down, speed up) while moving forwards
        acc_r = abs(max_acceleration_reverse) if _finite(max_acceleration_reverse) else acc
        dec_r = abs(max_deceleration_reverse) if _finite(max_deceleration_reverse) else dec
        self.reverse = (dec_r, acc_r)
        self.max_jerk = max_jerk
        self.min_jerk = min_jerk if _finite(min_jerk) or not _finite(max_jerk) else -max_jerk

    def limit(self, v: float, v0: float, v1: float, dt: float) -> float:
        """The limited command, given the last two commands ``v0`` (newest) and ``v1``, and ``dt`` [s]."""
        v = self.limit_jerk(v, v0, v1, dt)
        v = self.limit_acceleration(v, v0, dt)
        return self.limit_velocity(v)

    def limit_velocity(self, v: float) -> float:
        """Clamp to ``[min_velocity, max_velocity]``."""
        if _finite(self.max_velocity):
            v = min(v, self.max_velocity)
        if _finite(self.min_velocity):
            v = max(v, self.min_velocity)
        return v

    def limit_acceleration(self, v: float, v0: float, dt: float) -> float:
        """Bound the change from ``v0`` by the acceleration limits of the current direction."""
        if dt <= 0.0:
            return v
        slow, speed = self.forward if v0 >= 0.0 else self.reverse
        dv = v - v0
        if v0 >= 0.0:
            lo, hi = -slow * dt, speed * dt
        else:
            lo, hi = -speed * dt, slow * dt
        if _finite(hi):
            dv = min(dv, hi)
        if _finite(lo):
            dv = max(dv, lo)
        return v0 + dv

    def limit_jerk(self, v: float, v0: float, v1: float, dt: float) -> float:
        """Bound the change of acceleration over the last two steps."""
        if dt <= 0.0 or not _finite(self.max_jerk):
            return v
        dv, dv0 = v - v0, v0 - v1
        dt2 = 2.0 * dt * dt
        da = min(max(dv - dv0, self.min_jerk * dt2), self.max_jerk * dt2)
        return v0 + dv0 + da
