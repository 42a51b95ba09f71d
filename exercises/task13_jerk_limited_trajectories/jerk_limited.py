"""Task 13: time-optimal, jerk-limited moves with ruckig, sent to the joint trajectory controller.

ruckig plans from the current state to a goal within velocity, acceleration and jerk limits; the joint trajectory
controller executes a ``JointTrajectory``. Join the two here, with ruckig itself (``from ruckig import ...``; the
notebook shows its API). Never give ruckig intermediate waypoints: in its community version they are computed by a
cloud service.
"""

from __future__ import annotations

from collections.abc import Sequence

from rrbot_workshop.msgs import JointTrajectory

__all__ = ["joint_limits", "plan"]


def joint_limits(urdf: str, joint_names: Sequence[str]) -> dict[str, tuple[float, float, float]]:
    """``{joint: (min_position [rad], max_position [rad], max_velocity [rad/s])}`` from the description.

    For any description and any of its joints, in the order asked; the values are those of the joints' URDF
    ``<limit>`` as parsed for ``<ros2_control>`` (the self-check compares them to 1e-9).

    Raises:
        ValueError: If a joint is in no ``<ros2_control>`` tag, or has no position or velocity limit.
    """
    # TODO(task 13.1): the <ros2_control> parser already merges each joint's URDF <limit> into its limits
    #   (notebook 13 shows where to find them). Name the joint in every error.
    raise NotImplementedError("TODO(task 13.1): read the joints' limits from the description")


def plan(
    urdf: str,
    joint_names: Sequence[str],
    start: Sequence[float],
    goal: Sequence[float],
    max_acceleration: float,
    max_jerk: float,
    sample_period: float = 0.01,
) -> JointTrajectory:
    """A jerk-limited move from rest at ``start`` to rest at ``goal``, all joints arriving together.

    The move is ruckig's time-optimal one within the description's velocity limits and the given acceleration and jerk
    limits: it lasts ruckig's duration (the self-check compares it to 1e-6 s). Every joint that moves arrives at its
    goal at that duration, not before (ruckig synchronizes the joints by default). No point exceeds a limit by more
    than 1e-6 (in rad/s, rad/s²; the change of acceleration between two points is at most ``max_jerk * dt + 1e-6``).
    Points come at most ``sample_period`` apart, ``ceil(duration / sample_period)`` of them after t = 0 (a point at
    t = 0 may be added), each with ruckig's positions, velocities and accelerations at its time, for ``joint_names``
    in that order; the last is the goal at rest (to 1e-6) at the duration.

    Args:
        urdf: The robot's URDF (its ``<limit>`` tags bound positions and velocities).
        joint_names: Joints to move.
        start: Start positions in [rad].
        goal: Goal positions in [rad].
        max_acceleration: Acceleration limit of every joint in [rad/s^2].
        max_jerk: Jerk limit of every joint in [rad/s^3].
        sample_period: Time between trajectory points in [s].

    Raises:
        ValueError: If the lists' lengths differ, a goal is outside its joint's position limits (below the lower or
            above the upper; a goal at a limit is within them), naming the joint, or ruckig finds no trajectory.
    """
    # TODO(task 13.2): 1. refuse what cannot be planned (lengths, goals outside the limits);
    #   2. let ruckig compute the time-optimal motion within the velocity limits of the description and the
    #      given acceleration and jerk limits;
    #   3. sample it every sample_period (whatever its value) into points the JTC can follow exactly: what must
    #      each point carry besides positions? The last point is the goal, at rest, at the motion's duration.
    #   The docstring says to what tolerance the self-check compares each number.
    raise NotImplementedError("TODO(task 13.2): plan with ruckig and sample the result")
