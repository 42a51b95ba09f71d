"""Command limits: what Jazzy's resource manager does to commands when ``enforce_command_limits`` is true.

With the controller manager parameter ``enforce_command_limits: true`` (Jazzy's default is false), every command a
controller wrote is limited before the hardware's ``write``, joint by joint, from the limits the description gives
(URDF ``<limit>``, ``<safety_controller>``, and the ``min``/``max`` of a ``<command_interface>``):

* **position** command: within ``[lower, upper]``, and at most ``velocity * period`` away from the previous
  (limited) position command, or from the joint's position at the first command;
* **velocity** command: within ``±velocity``; with position limits, no velocity that would leave
  ``[lower, upper]`` within one period; with an acceleration limit, at most ``acceleration * period`` away from the
  previous velocity command;
* **effort** command: within ``±effort``; no effort that pushes further out once the joint is at a position limit or
  at its velocity limit;
* **soft limits** (``<safety_controller soft_lower_limit soft_upper_limit k_position>``): the velocity a position or
  velocity command may ask for is bounded by ``-k_position * (position - soft_limit)`` at each side, so the joint
  slows down into the soft range instead of hitting the hard one.

A NaN command (nothing to write) stays NaN. This is the saturation and soft limiters of Jazzy's ``joint_limits``
package in their essentials, without their jerk limits. Limits a joint does not have are not applied.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from rrbot_workshop.description.info import JointLimits, SoftJointLimits

__all__ = ["JointCommandLimiter", "limit_position", "limit_velocity", "limit_effort"]


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


def _soft_velocity_bounds(limits: JointLimits, soft: SoftJointLimits | None, position: float) -> tuple[float, float]:
    vmax = limits.max_velocity if limits.has_velocity_limits else math.inf
    low, high = -vmax, vmax
    if soft is not None and math.isfinite(position) and math.isfinite(soft.k_position):
        if math.isfinite(soft.min_position):
            low = max(low, -soft.k_position * (position - soft.min_position))
        if math.isfinite(soft.max_position):
            high = min(high, -soft.k_position * (position - soft.max_position))
        if low > high:  # outside the soft range on both counts: move back in, no faster than allowed
            low = high = _clamp(0.0, low, high)
    return low, high


def limit_position(
    command: float, previous: float, limits: JointLimits, period: float, soft: SoftJointLimits | None = None
) -> float:
    """A position command [rad] within the position limits and reachable from ``previous`` within one period."""
    if math.isnan(command):
        return command
    low, high = -math.inf, math.inf
    if limits.has_position_limits:
        low, high = limits.min_position, limits.max_position
    if math.isfinite(previous):
        vlow, vhigh = _soft_velocity_bounds(limits, soft, previous)
        low, high = max(low, previous + vlow * period), min(high, previous + vhigh * period)
    return _clamp(command, low, high) if low <= high else _clamp(command, high, low)


def limit_velocity(
    command: float, position: float, previous: float, limits: JointLimits, period: float,
    soft: SoftJointLimits | None = None,
) -> float:
    """A velocity command [rad/s] within ``±max_velocity``, the position range and the acceleration limit."""
    if math.isnan(command):
        return command
    low, high = _soft_velocity_bounds(limits, soft, position)
    if limits.has_position_limits and math.isfinite(position) and period > 0.0:
        low = max(low, min(0.0, (limits.min_position - position) / period))
        high = min(high, max(0.0, (limits.max_position - position) / period))
    if limits.has_acceleration_limits and math.isfinite(previous):
        step = limits.max_acceleration * period
        low, high = max(low, previous - step), min(high, previous + step)
    return _clamp(command, low, high) if low <= high else _clamp(command, high, low)


def limit_effort(command: float, position: float, velocity: float, limits: JointLimits) -> float:
    """An effort command [N m] within ``±max_effort``, never pushing further out at a position or velocity limit."""
    if math.isnan(command):
        return command
    emax = limits.max_effort if limits.has_effort_limits else math.inf
    low, high = -emax, emax
    if limits.has_position_limits and math.isfinite(position):
        if position <= limits.min_position:
            low = max(low, 0.0)
        if position >= limits.max_position:
            high = min(high, 0.0)
    if limits.has_velocity_limits and math.isfinite(velocity):
        if velocity <= -limits.max_velocity:
            low = max(low, 0.0)
        if velocity >= limits.max_velocity:
            high = min(high, 0.0)
    return _clamp(command, low, high)


@dataclass
class JointCommandLimiter:
    """Limits the command interfaces of one joint, remembering its previous limited commands.

    Attributes:
        joint: Joint name (the prefix of its interfaces).
        limits: Hard limits of the joint.
        soft: Soft limits, if the description has a ``<safety_controller>``.
    """

    joint: str
    limits: JointLimits
    soft: SoftJointLimits | None = None
    _previous: dict[str, float] = field(default_factory=dict)

    def reset(self) -> None:
        """Forget the previous commands (the next position command starts from the joint's position)."""
        self._previous.clear()

    def enforce(self, commands: Mapping[str, float], states: Mapping[str, float], period: float) -> dict[str, float]:
        """Limited values for the joint's ``commands`` (interface -> value), given its ``states``.

        Args:
            commands: ``"position"``, ``"velocity"``, ``"effort"`` -> commanded value (others pass through).
            states: The joint's state values by interface (``"position"``, ``"velocity"``), NaN if unknown.
            period: Controller manager period in [s].
        """
        position = states.get("position", math.nan)
        velocity = states.get("velocity", math.nan)
        out = dict(commands)
        if "position" in commands:
            previous = self._previous.get("position", position)
            out["position"] = limit_position(commands["position"], previous, self.limits, period, self.soft)
        if "velocity" in commands:
            previous = self._previous.get("velocity", math.nan)
            out["velocity"] = limit_velocity(commands["velocity"], position, previous, self.limits, period, self.soft)
        if "effort" in commands:
            out["effort"] = limit_effort(commands["effort"], position, velocity, self.limits)
        for name in ("position", "velocity"):
            if name in out and not math.isnan(out[name]):
                self._previous[name] = out[name]
        return out
