"""Command limits: what Jazzy's resource manager does to commands when ``enforce_command_limits`` is true.

With the controller manager parameter ``enforce_command_limits: true`` (Jazzy's default is false), every joint that
has limits gets a limiter of :mod:`rrbot_workshop.joint_limits`: a
:class:`~rrbot_workshop.joint_limits.JointSoftLimiter` if it has soft limits, else a
:class:`~rrbot_workshop.joint_limits.JointSaturationLimiter`. Before the hardware's ``write``, each limiter gets the
joint's state interfaces as ``actual`` and its *claimed* command interfaces as ``desired``, and the limited values
are written back. Joints with ``<limits enable="false"/>`` are left alone.

The limits are the description's (URDF ``<limit>``, ``<safety_controller>``, the ``min``/``max`` of a
``<command_interface>``), overridden by the controller manager's ``joint_limits.<joint>.*`` parameters (see
:mod:`rrbot_workshop.joint_limits`; Jazzy itself takes the description's only). In short:

* **position** command: within ``[min_position, max_position]``, and at most ``max_velocity * period`` away from the
  previous (limited) position command, or from the joint's position at the first command;
* **velocity** command: within ``±max_velocity``, no more than reaches a position limit within one period, and within
  ``max_acceleration * period`` of the previous velocity command;
* **effort** command: within ``±max_effort``; no effort that pushes further out once the joint is at a position limit
  or beyond its velocity limit;
* **soft limits**: the velocity a command may ask for is bounded by ``-k_position * (position - soft_limit)`` at each
  side, so the joint slows down into the soft range instead of hitting the hard one.

A NaN command (nothing to write) stays NaN. :class:`JointCommandLimiter` and the ``limit_*`` functions are a
dictionary-shaped front to those limiters, kept for the lessons that use them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.joint_limits import JointControlInterfacesData, JointSaturationLimiter, JointSoftLimiter

__all__ = ["JointCommandLimiter", "make_limiter", "limit_position", "limit_velocity", "limit_effort"]

_KINDS = ("position", "velocity", "effort", "acceleration")


def make_limiter(joint: str, limits: JointLimits, soft: SoftJointLimits | None = None) -> JointSaturationLimiter:
    """The limiter the resource manager uses for a joint: soft if it has soft limits, else saturation."""
    if soft is None:
        return JointSaturationLimiter([joint], [limits])
    return JointSoftLimiter([joint], [limits], [soft])


def _value(value: float | None) -> float | None:
    """None for a value that is missing or NaN (an unknown state)."""
    return None if value is None or math.isnan(value) else value


def limit_position(
    command: float, previous: float, limits: JointLimits, period: float, soft: SoftJointLimits | None = None
) -> float:
    """A position command [rad] within the position limits and reachable from ``previous`` within one period.

    Args:
        command: Position command in [rad].
        previous: Previous position command in [rad] (NaN: none, then no rate limit).
        limits: The joint's limits.
        period: Period in [s].
        soft: Soft limits, if any.
    """
    limiter = make_limiter("joint", limits, soft)
    if _value(previous) is not None:
        limiter.configure(JointControlInterfacesData("joint", position=previous))
    desired = JointControlInterfacesData("joint", position=command)
    limiter.enforce(JointControlInterfacesData("joint"), desired, period)
    return desired.position if desired.position is not None else command


def limit_velocity(
    command: float, position: float, previous: float, limits: JointLimits, period: float,
    soft: SoftJointLimits | None = None,
) -> float:
    """A velocity command [rad/s] within ``±max_velocity``, the position range and the acceleration limit.

    Args:
        command: Velocity command in [rad/s].
        position: Measured position in [rad] (NaN: unknown).
        previous: Previous velocity command in [rad/s] (NaN: none).
        limits: The joint's limits.
        period: Period in [s].
        soft: Soft limits, if any.
    """
    limiter = make_limiter("joint", limits, soft)
    if _value(previous) is not None:
        limiter.configure(JointControlInterfacesData("joint", velocity=previous))
    desired = JointControlInterfacesData("joint", velocity=command)
    limiter.enforce(JointControlInterfacesData("joint", position=_value(position)), desired, period)
    return desired.velocity if desired.velocity is not None else command


def limit_effort(command: float, position: float, velocity: float, limits: JointLimits) -> float:
    """An effort command [N m] within ``±max_effort``, never pushing further out at a position limit or beyond the
    velocity limit.

    Args:
        command: Effort command in [N m].
        position: Measured position in [rad] (NaN: unknown).
        velocity: Measured velocity in [rad/s] (NaN: unknown).
        limits: The joint's limits.
    """
    limiter = make_limiter("joint", limits)
    desired = JointControlInterfacesData("joint", effort=command)
    actual = JointControlInterfacesData("joint", position=_value(position), velocity=_value(velocity))
    limiter.enforce(actual, desired, 1.0)
    return desired.effort if desired.effort is not None else command


@dataclass
class JointCommandLimiter:
    """Limits the command interfaces of one joint, remembering its previous limited commands.

    Attributes:
        joint: Joint name (the prefix of its interfaces).
        limits: Hard limits of the joint.
        soft: Soft limits, if the description (or a parameter) gives them.
    """

    joint: str
    limits: JointLimits
    soft: SoftJointLimits | None = None
    _limiter: JointSaturationLimiter | None = field(default=None, repr=False)

    @property
    def limiter(self) -> JointSaturationLimiter:
        """The :mod:`rrbot_workshop.joint_limits` limiter doing the work."""
        if self._limiter is None:
            self._limiter = make_limiter(self.joint, self.limits, self.soft)
        return self._limiter

    def reset(self) -> None:
        """Forget the previous commands (the next position command starts from the joint's position)."""
        self.limiter.reset_internals()

    def enforce(self, commands: Mapping[str, float], states: Mapping[str, float], period: float) -> dict[str, float]:
        """Limited values for the joint's ``commands`` (interface -> value), given its ``states``.

        Args:
            commands: ``"position"``, ``"velocity"``, ``"effort"``, ``"acceleration"`` -> commanded value (others
                pass through).
            states: The joint's state values by interface, NaN if unknown.
            period: Controller manager period in [s].

        Raises:
            JointLimitsError: If a position is commanded while the joint is beyond a position limit.
        """
        actual = JointControlInterfacesData(self.joint, **{k: _value(states.get(k)) for k in _KINDS})
        desired = JointControlInterfacesData(self.joint, **{k: commands[k] for k in _KINDS if k in commands})
        self.limiter.enforce(actual, desired, period)
        out = dict(commands)
        for kind in _KINDS:
            value = getattr(desired, kind)
            if kind in commands and value is not None:
                out[kind] = value
        return out
