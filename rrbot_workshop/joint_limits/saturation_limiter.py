"""The saturation limiter of one joint (Jazzy's ``JointSaturationLimiter<JointControlInterfacesData>``).

Each cycle it clamps every commanded value into the range the helpers compute:

* **position**: within ``[min_position, max_position]``, and at most ``max_velocity * dt`` from the previous
  position command (the measured position before the first one);
* **velocity**: within ``±max_velocity``, no more than reaches a position limit within ``dt``, and within
  ``max_acceleration * dt`` of the previous velocity command;
* **effort**: within ``±max_effort``, and none that pushes further out at a position limit or beyond the velocity
  limit;
* **acceleration**: within ``±max_deceleration`` when braking (with a deceleration limit), else ``±max_acceleration``;
* **jerk**: within ``±max_jerk``.

A value that is None (not commanded) or NaN (nothing to write) is left alone. Limits the joint does not have are not
applied.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.joint_limits.data_structures import JointControlInterfacesData
from rrbot_workshop.joint_limits.helpers import (
    compute_acceleration_limits,
    compute_effort_limits,
    compute_position_limits,
    compute_velocity_limits,
    is_limited,
    update_prev_command,
)
from rrbot_workshop.joint_limits.limiter_interface import JointLimiterInterface

__all__ = ["JointSaturationLimiter"]

_FIELDS = ("position", "velocity", "effort", "acceleration", "jerk")


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


def _commanded(value: float | None) -> bool:
    return value is not None and not math.isnan(value)


class JointSaturationLimiter(JointLimiterInterface[JointControlInterfacesData]):
    """Clamps one joint's commands into its limits (see the module docstring).

    Build it with ``JointSaturationLimiter([name], [limits])`` or ``JointSaturationLimiter()`` and :meth:`init`.
    """

    def __init__(
        self,
        joint_names: Sequence[str] | None = None,
        limits: Sequence[JointLimits] = (),
        soft_limits: Sequence[SoftJointLimits] = (),
    ) -> None:
        #: The previous limited command (the measured state before the first one).
        self.prev_command = JointControlInterfacesData()
        super().__init__(joint_names, limits, soft_limits)

    def on_init(self) -> None:
        """Refuse any number of joints but one; forget the previous command.

        Raises:
            ParameterError: If the limiter was given more or fewer than one joint.
        """
        if self.number_of_joints != 1:
            raise ParameterError(type(self).__name__, "joint_names",
                                 f"limits exactly one joint (make one limiter per joint), got {self.joint_names}")
        self.prev_command = JointControlInterfacesData(self.joint_names[0])

    def on_configure(self, current_joint_states: JointControlInterfacesData) -> bool:
        """The joint's current state becomes the previous command."""
        self.prev_command = current_joint_states.copy()
        return True

    def reset_internals(self) -> None:
        """Forget the previous command."""
        self.prev_command = JointControlInterfacesData()

    def _fill_prev_command(self, actual: JointControlInterfacesData, desired: JointControlInterfacesData) -> None:
        """Before the first command: the previous command is the measured value, or else the desired one."""
        if self.prev_command.has_data():
            return
        for name in _FIELDS:
            if getattr(desired, name) is None:
                continue
            measured = getattr(actual, name)
            if measured is not None:
                setattr(self.prev_command, name, measured)
            elif _commanded(getattr(desired, name)):
                setattr(self.prev_command, name, getattr(desired, name))
        self.prev_command.joint_name = actual.joint_name if actual.has_data() else desired.joint_name

    def on_enforce(self, actual: JointControlInterfacesData, desired: JointControlInterfacesData, dt: float) -> bool:
        """See :meth:`~rrbot_workshop.joint_limits.JointLimiterInterface.enforce`."""
        if dt <= 0.0:
            return False
        limits, name = self.joint_limits[0], self.joint_names[0]
        self._fill_prev_command(actual, desired)
        limited = False
        pos, vel, eff, acc, jerk = desired.position, desired.velocity, desired.effort, desired.acceleration, desired.jerk
        if pos is not None and not math.isnan(pos):
            rng = compute_position_limits(name, limits, actual.velocity, actual.position, self.prev_command.position,
                                          dt)
            limited = is_limited(pos, rng.lower_limit, rng.upper_limit)
            desired.position = _clamp(pos, rng.lower_limit, rng.upper_limit)
        if vel is not None and not math.isnan(vel):
            rng = compute_velocity_limits(name, limits, vel, actual.position, self.prev_command.velocity, dt)
            limited = is_limited(vel, rng.lower_limit, rng.upper_limit) or limited
            desired.velocity = _clamp(vel, rng.lower_limit, rng.upper_limit)
        if eff is not None and not math.isnan(eff):
            rng = compute_effort_limits(limits, actual.position, actual.velocity, dt)
            limited = is_limited(eff, rng.lower_limit, rng.upper_limit) or limited
            desired.effort = _clamp(eff, rng.lower_limit, rng.upper_limit)
        if acc is not None and not math.isnan(acc):
            rng = compute_acceleration_limits(limits, acc, actual.velocity)
            limited = is_limited(acc, rng.lower_limit, rng.upper_limit) or limited
            desired.acceleration = _clamp(acc, rng.lower_limit, rng.upper_limit)
        if jerk is not None and not math.isnan(jerk) and limits.has_jerk_limits:
            limited = is_limited(jerk, -limits.max_jerk, limits.max_jerk) or limited
            desired.jerk = _clamp(jerk, -limits.max_jerk, limits.max_jerk)
        update_prev_command(desired, self.prev_command)
        return limited
