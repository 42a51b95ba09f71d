"""The soft limiter of one joint (Jazzy's ``JointSoftLimiter``): the saturation limiter, plus soft limits that slow
the joint down before it reaches them.

With soft limits ``[soft_lower_limit, soft_upper_limit]`` and gains ``k_position`` [1/s], ``k_velocity``
[N m s/rad], and ``p`` the previous position command (the measured position before the first one):

* the joint may move at velocities in ``[-k_position * (p - soft_lower_limit), -k_position * (p - soft_upper_limit)]``,
  each bound clamped to ``±max_velocity``: the closer to a soft limit, the slower it may go towards it;
* outside the soft range it may only move back, at 1 degree/s; beyond a hard limit (by more than
  :data:`~rrbot_workshop.joint_limits.helpers.POSITION_BOUNDS_TOLERANCE`) not at all;
* a **position** command stays within the soft range and one cycle's travel at those velocities (and within what
  the saturation limiter allows);
* a **velocity** command stays within those velocities (and within ``max_acceleration * dt`` of the measured one);
* an **effort** command ``e`` stays within ``[-k_velocity * (v - v_min), -k_velocity * (v - v_max)]``, ``v`` the
  measured velocity and ``[v_min, v_max]`` the velocities above, clamped to ``±max_effort``: an effort that would
  drive the joint faster than the soft limits allow is cut back.

Soft limits take effect only with position and velocity limits (and a ``k_position`` that is not zero); the effort
bounds need ``k_velocity`` and an effort limit.
"""

from __future__ import annotations

import math

from rrbot_workshop.description.info import SoftJointLimits
from rrbot_workshop.joint_limits.data_structures import JointControlInterfacesData
from rrbot_workshop.joint_limits.helpers import (
    POSITION_BOUNDS_TOLERANCE,
    compute_acceleration_limits,
    compute_effort_limits,
    compute_position_limits,
    compute_velocity_limits,
    is_limited,
    update_prev_command,
)
from rrbot_workshop.joint_limits.saturation_limiter import JointSaturationLimiter

__all__ = ["JointSoftLimiter", "has_soft_position_limits", "has_soft_limits", "SOFT_LIMIT_REACH_VELOCITY"]

#: Below this a range or a gain counts as zero.
VALUE_CONSIDERED_ZERO = 1e-10
#: Velocity [rad/s] at which a joint outside its soft range is brought back (1 degree/s, Jazzy's value).
SOFT_LIMIT_REACH_VELOCITY = math.radians(1.0)


def has_soft_position_limits(soft: SoftJointLimits) -> bool:
    """True if ``soft`` has finite lower and upper soft limits, the upper above the lower."""
    return (math.isfinite(soft.min_position) and math.isfinite(soft.max_position)
            and soft.max_position - soft.min_position > VALUE_CONSIDERED_ZERO)


def has_soft_limits(soft: SoftJointLimits) -> bool:
    """True if ``soft`` has soft position limits and a finite, non-zero ``k_position``."""
    return (has_soft_position_limits(soft) and math.isfinite(soft.k_position)
            and abs(soft.k_position) > VALUE_CONSIDERED_ZERO)


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


class JointSoftLimiter(JointSaturationLimiter):
    """Limits one joint's commands with its hard limits and its soft limits (see the module docstring).

    Build it with ``JointSoftLimiter([name], [limits], [soft])`` or ``JointSoftLimiter()`` and :meth:`init`; without
    soft limits it limits as :class:`~rrbot_workshop.joint_limits.JointSaturationLimiter` does.
    """

    def _velocity_bounds(self, actual: JointControlInterfacesData, soft: SoftJointLimits) -> tuple[float, float, float]:
        """``(v_min, v_max, p)``: velocities the soft limits allow and the position they are computed from."""
        hard = self.joint_limits[0]
        prev = self.prev_command.position
        act_position = (actual.position if actual.position is not None
                        else prev if prev is not None and math.isfinite(prev) else math.inf)
        prev_position = (prev if prev is not None and math.isfinite(prev)
                         else actual.position if actual.position is not None else math.inf)
        low, high = -math.inf, math.inf
        if hard.has_velocity_limits:
            vmax = hard.max_velocity
            low, high = -vmax, vmax
            if hard.has_position_limits and has_soft_limits(soft) and math.isfinite(prev_position):
                low = _clamp(-soft.k_position * (prev_position - soft.min_position), -vmax, vmax)
                high = _clamp(-soft.k_position * (prev_position - soft.max_position), -vmax, vmax)
                if math.isfinite(act_position) and (act_position < hard.min_position - POSITION_BOUNDS_TOLERANCE
                                                    or act_position > hard.max_position + POSITION_BOUNDS_TOLERANCE):
                    low = high = 0.0
                elif act_position < soft.min_position or act_position > soft.max_position:
                    low = math.copysign(SOFT_LIMIT_REACH_VELOCITY, low)
                    high = math.copysign(SOFT_LIMIT_REACH_VELOCITY, high)
        return low, high, prev_position

    def on_enforce(self, actual: JointControlInterfacesData, desired: JointControlInterfacesData, dt: float) -> bool:
        """See :meth:`~rrbot_workshop.joint_limits.JointLimiterInterface.enforce`."""
        if dt <= 0.0:
            return False
        hard, name = self.joint_limits[0], self.joint_names[0]
        soft = self.soft_joint_limits[0] if self.soft_joint_limits else SoftJointLimits()
        self._fill_prev_command(actual, desired)
        soft_min_vel, soft_max_vel, prev_position = self._velocity_bounds(actual, soft)
        limited = False
        pos, vel, eff, acc, jerk = desired.position, desired.velocity, desired.effort, desired.acceleration, desired.jerk
        if pos is not None and not math.isnan(pos):
            rng = compute_position_limits(name, hard, actual.velocity, actual.position, self.prev_command.position, dt)
            low, high = ((soft.min_position, soft.max_position) if has_soft_position_limits(soft)
                         else (-math.inf, math.inf))
            if hard.has_velocity_limits and math.isfinite(prev_position):
                low = _clamp(prev_position + soft_min_vel * dt, low, high)
                high = _clamp(prev_position + soft_max_vel * dt, low, high)
            travel_low, travel_high = low, high
            low, high = max(low, rng.lower_limit), min(high, rng.upper_limit)
            if low > high:  # the soft and the hard ranges do not meet: the soft one wins
                low, high = travel_low, travel_high
            limited = is_limited(pos, low, high)
            desired.position = _clamp(pos, low, high)
        if vel is not None and not math.isnan(vel):
            rng = compute_velocity_limits(name, hard, vel, actual.position, self.prev_command.velocity, dt)
            if hard.has_velocity_limits and hard.has_acceleration_limits and actual.velocity is not None:
                soft_min_vel = max(actual.velocity - hard.max_acceleration * dt, soft_min_vel)
                soft_max_vel = min(actual.velocity + hard.max_acceleration * dt, soft_max_vel)
            soft_min_vel, soft_max_vel = max(soft_min_vel, rng.lower_limit), min(soft_max_vel, rng.upper_limit)
            limited = is_limited(vel, soft_min_vel, soft_max_vel) or limited
            desired.velocity = _clamp(vel, soft_min_vel, soft_max_vel)
        if eff is not None and not math.isnan(eff):
            rng = compute_effort_limits(hard, actual.position, actual.velocity, dt)
            low, high = rng.lower_limit, rng.upper_limit
            if hard.has_effort_limits and math.isfinite(soft.k_velocity) and actual.velocity is not None:
                emax = hard.max_effort
                low = max(_clamp(-soft.k_velocity * (actual.velocity - soft_min_vel), -emax, emax), rng.lower_limit)
                high = min(_clamp(-soft.k_velocity * (actual.velocity - soft_max_vel), -emax, emax), rng.upper_limit)
            limited = is_limited(eff, low, high) or limited
            desired.effort = _clamp(eff, low, high)
        if acc is not None and not math.isnan(acc):
            rng = compute_acceleration_limits(hard, acc, actual.velocity)
            limited = is_limited(acc, rng.lower_limit, rng.upper_limit) or limited
            desired.acceleration = _clamp(acc, rng.lower_limit, rng.upper_limit)
        if jerk is not None and not math.isnan(jerk) and hard.has_jerk_limits:
            limited = is_limited(jerk, -hard.max_jerk, hard.max_jerk) or limited
            desired.jerk = _clamp(jerk, -hard.max_jerk, hard.max_jerk)
        update_prev_command(desired, self.prev_command)
        return limited
