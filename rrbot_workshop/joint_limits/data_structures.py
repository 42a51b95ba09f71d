"""What a joint limiter reads and writes: one joint's values, each of them optional (Jazzy's ``data_structures.hpp``).

A limiter's ``enforce(actual, desired, dt)`` takes the joint's measured values in ``actual`` and the commanded ones in
``desired``; a field that is None is not there (no such interface, or nothing commanded) and is left alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["JointControlInterfacesData", "JointInterfacesCommandLimiterData", "LimitRange"]

_FIELDS = ("position", "velocity", "effort", "acceleration", "jerk")


@dataclass
class JointControlInterfacesData:
    """One joint's values by interface; None where the joint has no such value.

    Attributes:
        joint_name: Name of the joint.
        position: Position in [rad] or [m].
        velocity: Velocity in [rad/s] or [m/s].
        effort: Effort in [N m] or [N].
        acceleration: Acceleration in [rad/s^2] or [m/s^2].
        jerk: Jerk in [rad/s^3] or [m/s^3].
    """

    joint_name: str = ""
    position: float | None = None
    velocity: float | None = None
    effort: float | None = None
    acceleration: float | None = None
    jerk: float | None = None

    def has_data(self) -> bool:
        """True if at least one value is set."""
        return any(getattr(self, name) is not None for name in _FIELDS)

    def has_position(self) -> bool:
        """True if ``position`` is set."""
        return self.position is not None

    def has_velocity(self) -> bool:
        """True if ``velocity`` is set."""
        return self.velocity is not None

    def has_effort(self) -> bool:
        """True if ``effort`` is set."""
        return self.effort is not None

    def has_acceleration(self) -> bool:
        """True if ``acceleration`` is set."""
        return self.acceleration is not None

    def has_jerk(self) -> bool:
        """True if ``jerk`` is set."""
        return self.jerk is not None

    def copy(self) -> JointControlInterfacesData:
        """An independent copy."""
        return JointControlInterfacesData(self.joint_name, self.position, self.velocity, self.effort,
                                          self.acceleration, self.jerk)

    def __str__(self) -> str:
        values = ", ".join(f"{name}: {getattr(self, name):.6g}" for name in _FIELDS if getattr(self, name) is not None)
        return f"Joint: '{self.joint_name}'" + (f", {values}" if values else "")


@dataclass
class JointInterfacesCommandLimiterData:
    """What the resource manager keeps per limited joint: measured, commanded, previous and limited values.

    Attributes:
        joint_name: Name of the joint.
        actual: Values of the joint's state interfaces.
        command: Values of its claimed command interfaces.
        prev_command: The previous limited command.
        limited: ``command`` after the limiter.
    """

    joint_name: str = ""
    actual: JointControlInterfacesData = field(default_factory=JointControlInterfacesData)
    command: JointControlInterfacesData = field(default_factory=JointControlInterfacesData)
    prev_command: JointControlInterfacesData = field(default_factory=JointControlInterfacesData)
    limited: JointControlInterfacesData = field(default_factory=JointControlInterfacesData)

    def set_joint_name(self, name: str) -> None:
        """Name this data and the four values it holds ``name``."""
        self.joint_name = name
        for data in (self.actual, self.command, self.prev_command, self.limited):
            data.joint_name = name


@dataclass
class LimitRange:
    """A closed range ``[lower_limit, upper_limit]`` (Jazzy's PositionLimits, VelocityLimits, ...)."""

    lower_limit: float = -math.inf
    upper_limit: float = math.inf
