"""The ranges a joint's commands may take this cycle (Jazzy's ``joint_limits_helpers``).

Each function returns a :class:`~rrbot_workshop.joint_limits.data_structures.LimitRange` for one quantity, from the
joint's limits, what was measured and what was commanded before; the limiters clamp the desired value into it.
"""

from __future__ import annotations

import math

from rrbot_workshop.description.info import JointLimits
from rrbot_workshop.exceptions import JointLimitsError
from rrbot_workshop.joint_limits.data_structures import JointControlInterfacesData, LimitRange

__all__ = [
    "POSITION_BOUNDS_TOLERANCE",
    "OUT_OF_BOUNDS_EXCEPTION_TOLERANCE",
    "is_limited",
    "update_prev_command",
    "compute_position_limits",
    "compute_velocity_limits",
    "compute_effort_limits",
    "compute_acceleration_limits",
]

#: How far [rad] or [m] a joint may be beyond a position limit and still be moved back in (Jazzy's value).
POSITION_BOUNDS_TOLERANCE = 0.002
#: How far [rad] or [m] beyond a position limit a joint may be while a position is commanded before that is an
#: error (:class:`~rrbot_workshop.exceptions.JointLimitsError`; Jazzy's value, about half a degree).
OUT_OF_BOUNDS_EXCEPTION_TOLERANCE = 0.0087


def _swapped(lower: float, upper: float) -> LimitRange:
    return LimitRange(upper, lower) if lower > upper else LimitRange(lower, upper)


def is_limited(value: float, lower: float, upper: float) -> bool:
    """True if ``value`` is outside ``[lower, upper]``."""
    return value < lower or value > upper


def update_prev_command(desired: JointControlInterfacesData, prev_command: JointControlInterfacesData) -> None:
    """Copy the values of ``desired`` that are set and not NaN into ``prev_command``."""
    for name in ("position", "velocity", "effort", "acceleration", "jerk"):
        value = getattr(desired, name)
        if value is not None and not math.isnan(value):
            setattr(prev_command, name, value)
    prev_command.joint_name = desired.joint_name


def _verify_position(joint_name: str, position: float | None, limits: JointLimits) -> None:
    if position is not None and limits.has_position_limits and (
        position > limits.max_position + OUT_OF_BOUNDS_EXCEPTION_TOLERANCE
        or position < limits.min_position - OUT_OF_BOUNDS_EXCEPTION_TOLERANCE
    ):
        raise JointLimitsError(joint_name, position, (limits.min_position, limits.max_position))


def compute_position_limits(
    joint_name: str,
    limits: JointLimits,
    actual_velocity: float | None,
    actual_position: float | None,
    prev_command_position: float | None,
    dt: float,
) -> LimitRange:
    """The range of a position command: the position limits, narrowed to one cycle's travel at the velocity limit
    (at most ``|v| + max_acceleration * dt`` with an acceleration limit) around the previous command (or, without
    one, the measured position).

    Args:
        joint_name: Name of the joint, for the error.
        limits: The joint's limits.
        actual_velocity: Measured velocity in [rad/s], or None.
        actual_position: Measured position in [rad], or None.
        prev_command_position: Previous position command in [rad], or None.
        dt: Period in [s].

    Raises:
        JointLimitsError: If the measured position is beyond a position limit by more than
            :data:`OUT_OF_BOUNDS_EXCEPTION_TOLERANCE`.
    """
    low, high = (limits.min_position, limits.max_position) if limits.has_position_limits else (-math.inf, math.inf)
    _verify_position(joint_name, actual_position, limits)
    if limits.has_velocity_limits:
        speed = abs(actual_velocity) if actual_velocity is not None else 0.0
        reachable = speed + limits.max_acceleration * dt if limits.has_acceleration_limits else limits.max_velocity
        step = min(limits.max_velocity, reachable) * dt
        ref = prev_command_position if prev_command_position is not None else actual_position
        if ref is not None:
            low = max(min(ref - step, high), low)
            high = min(max(ref + step, low), high)
    return _swapped(low, high)


def compute_velocity_limits(
    joint_name: str,
    limits: JointLimits,
    desired_velocity: float,
    actual_position: float | None,
    prev_command_velocity: float | None,
    dt: float,
) -> LimitRange:
    """The range of a velocity command: ``±max_velocity``; no more than reaches a position limit within ``dt``
    (zero, once beyond a limit, in the direction that leaves further); within ``max_acceleration * dt`` of the
    previous velocity command.

    Args:
        joint_name: Name of the joint (unused; kept for Jazzy's signature).
        limits: The joint's limits.
        desired_velocity: The commanded velocity in [rad/s].
        actual_position: Measured position in [rad], or None.
        prev_command_velocity: Previous velocity command in [rad/s], or None.
        dt: Period in [s].
    """
    del joint_name
    if not limits.has_velocity_limits:
        return LimitRange(-math.inf, math.inf)
    low, high = -limits.max_velocity, limits.max_velocity
    if limits.has_position_limits and actual_position is not None:
        pos = actual_position
        low = max((limits.min_position - pos) / dt, low)
        high = min((limits.max_position - pos) / dt, high)
        if pos > limits.max_position or pos < limits.min_position:
            inside_tolerance = (
                (pos < limits.max_position + POSITION_BOUNDS_TOLERANCE and pos > limits.min_position
                 and desired_velocity >= 0.0)
                or (pos > limits.min_position - POSITION_BOUNDS_TOLERANCE and pos < limits.max_position
                    and desired_velocity <= 0.0)
            )
            far_out = (pos > limits.max_position + POSITION_BOUNDS_TOLERANCE
                       or pos < limits.min_position - POSITION_BOUNDS_TOLERANCE)
            if inside_tolerance or far_out:
                low = high = 0.0
    if limits.has_acceleration_limits and prev_command_velocity is not None:
        step = limits.max_acceleration * dt
        low = max(prev_command_velocity - step, low)
        high = min(prev_command_velocity + step, high)
    return _swapped(low, high)


def compute_effort_limits(
    limits: JointLimits, actual_position: float | None, actual_velocity: float | None, dt: float
) -> LimitRange:
    """The range of an effort command: ``±max_effort``; none that pushes further out at a position limit (when the
    joint is not already moving back) or beyond the velocity limit.

    Args:
        limits: The joint's limits.
        actual_position: Measured position in [rad], or None.
        actual_velocity: Measured velocity in [rad/s], or None.
        dt: Period in [s] (unused).
    """
    del dt
    if not limits.has_effort_limits:
        return LimitRange(-math.inf, math.inf)
    low, high = -limits.max_effort, limits.max_effort
    if limits.has_position_limits and actual_position is not None and actual_velocity is not None:
        if actual_position <= limits.min_position and actual_velocity <= 0.0:
            low = 0.0
        elif actual_position >= limits.max_position and actual_velocity >= 0.0:
            high = 0.0
    if limits.has_velocity_limits and actual_velocity is not None:
        if actual_velocity < -limits.max_velocity:
            low = 0.0
        elif actual_velocity > limits.max_velocity:
            high = 0.0
    return _swapped(low, high)


def compute_acceleration_limits(
    limits: JointLimits, desired_acceleration: float, actual_velocity: float | None
) -> LimitRange:
    """The range of an acceleration command: ``±max_deceleration`` when it slows the joint down (and there is a
    deceleration limit), else ``±max_acceleration``.

    Args:
        limits: The joint's limits.
        desired_acceleration: The commanded acceleration in [rad/s^2].
        actual_velocity: Measured velocity in [rad/s], or None.
    """
    braking = actual_velocity is not None and (
        (desired_acceleration < 0 and actual_velocity > 0) or (desired_acceleration > 0 and actual_velocity < 0))
    if limits.has_deceleration_limits and braking:
        return _swapped(-limits.max_deceleration, limits.max_deceleration)
    if limits.has_acceleration_limits:
        return _swapped(-limits.max_acceleration, limits.max_acceleration)
    return LimitRange(-math.inf, math.inf)
