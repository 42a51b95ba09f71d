"""Trajectory messages as the joint trajectory controller reshapes and builds them.

Every trajectory the JTC runs, received or its own, goes through these functions: an incoming message
is padded with the joints it leaves out (:func:`fill_partial_goal`) and put in the controller's joint
order (:func:`sort_to_joint_order`); holding a position is itself a one-point trajectory
(:func:`hold_position_trajectory`, :func:`last_waypoint_trajectory`); and each cycle's
``~/controller_state`` message is assembled by :func:`controller_state_message`.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence

from rrbot_workshop.msgs import Header, JointTrajectory, JointTrajectoryControllerState, JointTrajectoryPoint

__all__ = [
    "fill_partial_goal",
    "sort_to_joint_order",
    "hold_position_trajectory",
    "last_waypoint_trajectory",
    "controller_state_message",
    "controller_state_from_commands",
]

_FIELDS = ("positions", "velocities", "accelerations", "effort")


def fill_partial_goal(msg: JointTrajectory, joints: Sequence[str], hold: Sequence[float]) -> None:
    """Append the controller joints ``msg`` leaves out, holding still (in place).

    ros2_controllers Jazzy pads with ``has_value()`` of the position command (i.e. 1.0) instead of its
    value; here the missing joints keep ``hold``.

    Args:
        msg: A validated trajectory whose joint names are controller joints.
        joints: The controller's joints.
        hold: Per controller joint, the position in [rad] or [m] a missing joint keeps; its velocity,
            acceleration and effort are 0 wherever the waypoints carry those fields.
    """
    for idx, joint in enumerate(joints):
        if joint in msg.joint_names:
            continue
        msg.joint_names.append(joint)
        for point in msg.points:
            if point.positions:
                point.positions.append(hold[idx])
            for attr in _FIELDS[1:]:
                if getattr(point, attr):
                    getattr(point, attr).append(0.0)


def sort_to_joint_order(msg: JointTrajectory, joints: Sequence[str]) -> None:
    """Reorder the joint names and every waypoint field of ``msg`` to ``joints`` (in place)."""
    order = [msg.joint_names.index(j) for j in joints]
    for point in msg.points:
        for attr in _FIELDS:
            values = getattr(point, attr)
            if len(values) == len(order):
                setattr(point, attr, [values[k] for k in order])
    msg.joint_names = list(joints)


def hold_position_trajectory(
    joints: Sequence[str], positions: Sequence[float], has_command: Mapping[str, bool]
) -> JointTrajectory:
    """A one-point trajectory at ``positions``, starting now.

    The waypoint has zero velocities with a velocity or acceleration command, zero accelerations with
    an acceleration command and zero efforts with an effort command.

    Args:
        joints: The controller's joints.
        positions: Per joint, the position to hold in [rad] or [m].
        has_command: Command interface kind -> whether the controller commands it.
    """
    n = len(joints)
    point = JointTrajectoryPoint(positions=list(positions), time_from_start=0.0)
    if has_command["velocity"] or has_command["acceleration"]:
        point.velocities = [0.0] * n
    if has_command["acceleration"]:
        point.accelerations = [0.0] * n
    if has_command["effort"]:
        point.effort = [0.0] * n
    return JointTrajectory(Header(stamp=0.0), list(joints), [point])


def last_waypoint_trajectory(msg: JointTrajectory, joints: Sequence[str]) -> JointTrajectory:
    """A one-point trajectory, starting now, at the last waypoint of ``msg`` (whatever its velocity)."""
    last = copy.deepcopy(msg.points[-1])
    last.time_from_start = 0.0
    return JointTrajectory(Header(stamp=0.0), list(joints), [last])


def controller_state_message(
    time: float,
    joints: Sequence[str],
    desired: JointTrajectoryPoint,
    current: JointTrajectoryPoint,
    error: JointTrajectoryPoint,
    output: JointTrajectoryPoint,
) -> JointTrajectoryControllerState:
    """The ``~/controller_state`` message of one cycle.

    ``reference``, ``feedback`` and ``error`` carry positions, velocities and accelerations (copies);
    the deprecated ``desired`` and ``actual`` fields repeat ``reference`` and ``feedback``.

    Args:
        time: Stamp in [s].
        joints: The controller's joints.
        desired: The sampled reference.
        current: The measured state.
        error: ``desired - current``.
        output: The commands written.
    """
    msg = JointTrajectoryControllerState(header=Header(stamp=time), joint_names=list(joints))
    msg.reference = JointTrajectoryPoint(list(desired.positions), list(desired.velocities), list(desired.accelerations))
    msg.feedback = JointTrajectoryPoint(list(current.positions), list(current.velocities), list(current.accelerations))
    msg.error = JointTrajectoryPoint(list(error.positions), list(error.velocities), list(error.accelerations))
    msg.output = output
    msg.desired, msg.actual = msg.reference, msg.feedback
    return msg


def controller_state_from_commands(
    time: float,
    joints: Sequence[str],
    desired: JointTrajectoryPoint,
    current: JointTrajectoryPoint,
    error: JointTrajectoryPoint,
    commands: tuple[list[float] | None, list[float] | None, list[float] | None, list[float] | None],
) -> JointTrajectoryControllerState:
    """:func:`controller_state_message` from the command values a cycle read, per field of a point, None for a kind
    the controller does not command (the output point is made here: a cycle publishes the message lazily, and it is
    built when someone reads it)."""
    p, v, a, e = commands
    output = JointTrajectoryPoint([] if p is None else p, [] if v is None else v, [] if a is None else a,
                                  [] if e is None else e)
    return controller_state_message(time, joints, desired, current, error, output)
