"""The saturation limiter of trajectory points (Jazzy's ``JointSaturationLimiter<JointTrajectoryPoint>``).

Unlike the per-joint limiters, it limits several joints at once: a desired
:class:`~rrbot_workshop.msgs.JointTrajectoryPoint` (positions, velocities, accelerations) against the current one.
Per joint, in this order:

1. the position is clamped into ``[min_position, max_position]``;
2. the velocity (the desired one, or the position step over ``dt`` when none is given) is clamped to
   ``±max_velocity``, and the position recomputed from it;
3. the acceleration (given, or the velocity change over ``dt``) is clamped to ``±max_deceleration`` when it slows the
   joint, else ``±max_acceleration``, and velocity and position recomputed from it;
4. a joint commanded by velocity only may not pass a position limit within ``dt``;
5. if a joint could not stop before its position limit at its deceleration (or acceleration) limit, **every** joint
   brakes: its acceleration becomes ``-v / dt`` (at most the limit), and velocity and position follow from that.

The current point needs positions and the desired one positions or velocities; otherwise nothing is limited.
One difference from Jazzy: without desired positions, a zero desired velocity stays zero (Jazzy recomputes it from
missing positions).
"""

from __future__ import annotations

import logging
import math

from rrbot_workshop.joint_limits.limiter_interface import JointLimiterInterface
from rrbot_workshop.msgs import JointTrajectoryPoint

__all__ = ["JointTrajectoryPointSaturationLimiter"]

_log = logging.getLogger(__name__)

VALUE_CONSIDERED_ZERO = 1e-10


class JointTrajectoryPointSaturationLimiter(JointLimiterInterface[JointTrajectoryPoint]):
    """Limits trajectory points of several joints (see the module docstring)."""

    def on_configure(self, current_joint_states: JointTrajectoryPoint) -> bool:
        """Nothing to remember: each point is limited against the current one given to :meth:`enforce`."""
        return True

    def on_enforce(self, actual: JointTrajectoryPoint, desired: JointTrajectoryPoint, dt: float) -> bool:
        """See :meth:`~rrbot_workshop.joint_limits.JointLimiterInterface.enforce`; ``actual`` is the current point."""
        if dt <= 0.0:
            return False
        n = self.number_of_joints
        has_pos, has_vel = len(desired.positions) == n, len(desired.velocities) == n
        has_acc = len(desired.accelerations) == n
        if len(actual.positions) != n or not (has_pos or has_vel):
            return False
        cur_pos = list(actual.positions)
        cur_vel = list(actual.velocities) if len(actual.velocities) == n else [0.0] * n
        pos = list(desired.positions) if has_pos else [0.0] * n
        vel = list(desired.velocities) if has_vel else [0.0] * n
        acc = list(desired.accelerations) if has_acc else [0.0] * n
        limited: dict[str, list[str]] = {"position": [], "velocity": [], "acceleration": [], "deceleration": []}
        braking = False
        for i, lim in enumerate(self.joint_limits):
            name = self.joint_names[i]
            if has_pos:
                if lim.has_position_limits:
                    clamped = min(max(pos[i], lim.min_position), lim.max_position)
                    if clamped != pos[i]:
                        pos[i] = clamped
                        limited["position"].append(name)
                step = pos[i] - cur_pos[i]
                if abs(step) > VALUE_CONSIDERED_ZERO and abs(vel[i]) <= VALUE_CONSIDERED_ZERO:
                    vel[i] = step / dt
            if lim.has_velocity_limits:
                if has_pos and (abs(vel[i]) <= VALUE_CONSIDERED_ZERO or math.isnan(vel[i])):
                    vel[i] = (pos[i] - cur_pos[i]) / dt
                if abs(vel[i]) > lim.max_velocity:
                    vel[i] = math.copysign(lim.max_velocity, vel[i])
                    limited["velocity"].append(name)
                    if has_pos:
                        pos[i] = cur_pos[i] + vel[i] * dt
                    acc[i] = (vel[i] - cur_vel[i]) / dt
            if lim.has_acceleration_limits or lim.has_deceleration_limits:
                if abs(acc[i]) <= VALUE_CONSIDERED_ZERO or math.isnan(acc[i]):
                    acc[i] = (vel[i] - cur_vel[i]) / dt
                slowing = (acc[i] < 0 < cur_vel[i]) or (acc[i] > 0 > cur_vel[i])
                applied = False
                if slowing and lim.has_deceleration_limits:
                    if abs(acc[i]) > lim.max_deceleration:
                        acc[i] = math.copysign(lim.max_deceleration, acc[i])
                        limited["deceleration"].append(name)
                        applied = True
                elif lim.has_acceleration_limits and abs(acc[i]) > lim.max_acceleration:
                    acc[i] = math.copysign(lim.max_acceleration, acc[i])
                    limited["acceleration"].append(name)
                    applied = True
                if applied:
                    vel[i] = cur_vel[i] + acc[i] * dt
                    if has_pos:
                        pos[i] = cur_pos[i] + cur_vel[i] * dt + 0.5 * acc[i] * dt * dt
            if lim.has_position_limits:
                if has_vel and not has_pos:
                    expected = cur_pos[i] + vel[i] * dt
                    clamped = min(max(expected, lim.min_position), lim.max_position)
                    if clamped != expected:
                        vel[i] = (clamped - cur_pos[i]) / dt
                        limited["position"].append(name)
                if self._must_brake(i, vel[i], cur_pos[i], dt):
                    braking = True
                    if name not in limited["position"]:
                        limited["position"].append(name)
        if braking:
            for i, lim in enumerate(self.joint_limits):
                acc[i] = -cur_vel[i] / dt
                bound = (lim.max_deceleration if lim.has_deceleration_limits
                         else lim.max_acceleration if lim.has_acceleration_limits else math.inf)
                acc[i] = math.copysign(min(abs(acc[i]), bound), acc[i])
                if has_vel:
                    vel[i] = cur_vel[i] + acc[i] * dt
                if has_pos:
                    pos[i] = cur_pos[i] + cur_vel[i] * dt + 0.5 * acc[i] * dt * dt
        for kind, names in limited.items():
            if names:
                _log.debug("joint(s) [%s] would exceed %s limits, limiting", " ".join(names), kind)
        if has_pos:
            desired.positions = pos
        if has_vel:
            desired.velocities = vel
        if has_acc:
            desired.accelerations = acc
        return braking or any(limited.values())

    def _must_brake(self, i: int, velocity: float, position: float, dt: float) -> bool:
        """True if joint ``i`` moving at ``velocity`` could not stop before its position limit (at its deceleration
        limit, else its acceleration limit, else within one cycle)."""
        lim = self.joint_limits[i]
        if lim.has_deceleration_limits:
            decel = lim.max_deceleration
        elif lim.has_acceleration_limits:
            decel = lim.max_acceleration
        else:
            decel = abs(velocity / dt)
        if decel <= 0.0 or math.isnan(decel):
            return False
        stopping_distance = velocity * velocity / (2.0 * decel)
        travel = velocity * abs(velocity / decel)
        room_up, room_down = lim.max_position - position, position - lim.min_position
        if (velocity < 0 and room_down < stopping_distance) or (velocity > 0 and room_up < stopping_distance):
            return True
        return (velocity < 0 and room_down < travel) or (velocity > 0 and room_up < travel)
