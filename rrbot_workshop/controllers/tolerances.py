"""Path and goal tolerances of the joint trajectory controller.

Two sets of per-joint tolerances decide the fate of a trajectory: the *path* (``state_tolerance``)
tolerances are checked while it runs, the *goal* tolerances once its last waypoint is due, and
``goal_time_tolerance`` says how long past that the goal may still be reached. A tolerance of 0
means "not checked". Defaults come from the ``constraints`` parameters; a FollowJointTrajectory
goal can override them per joint, where 0 keeps the default and -1 erases it. The errors they are
checked against come from :func:`compute_state_error`.
"""

from __future__ import annotations

import logging
import math
import operator
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from rrbot_workshop.controllers.interpolation import shortest_angular_distance
from rrbot_workshop.msgs import JointTolerance, JointTrajectoryPoint

__all__ = [
    "StateTolerances",
    "SegmentTolerances",
    "ERASE_VALUE",
    "get_segment_tolerances",
    "get_segment_tolerances_from_goal",
    "resolve_tolerance_source",
    "compute_state_error",
    "state_error_function",
    "checked_joints",
    "check_state_tolerance_per_joint",
]

_log = logging.getLogger(__name__)

#: ``control_msgs/JointTolerance`` value that removes a default tolerance.
ERASE_VALUE = -1.0


@dataclass
class StateTolerances:
    """Largest allowed errors of one joint; 0 disables a check.

    Attributes:
        position: Position error in [rad].
        velocity: Velocity error in [rad/s].
        acceleration: Acceleration error in [rad/s^2].
    """

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass
class SegmentTolerances:
    """Tolerances of a whole trajectory.

    Attributes:
        state_tolerance: Per joint, checked while the trajectory runs.
        goal_state_tolerance: Per joint, checked once the last waypoint is due.
        goal_time_tolerance: Time allowed past the end to reach the goal in [s]; 0 waits forever.
    """

    state_tolerance: list[StateTolerances] = field(default_factory=list)
    goal_state_tolerance: list[StateTolerances] = field(default_factory=list)
    goal_time_tolerance: float = 0.0


def get_segment_tolerances(params: Any) -> SegmentTolerances:
    """Default tolerances from the ``constraints`` parameters of a JTC.

    ``constraints.<joint>.trajectory`` is the path position tolerance, ``constraints.<joint>.goal`` the
    goal position tolerance, ``constraints.stopped_velocity_tolerance`` the goal velocity tolerance of
    every joint and ``constraints.goal_time`` the goal time tolerance.
    """
    constraints = params.constraints
    out = SegmentTolerances(goal_time_tolerance=float(constraints.goal_time))
    for joint in params.joints:
        per_joint = constraints.joints_map[joint]
        out.state_tolerance.append(StateTolerances(position=float(per_joint.trajectory)))
        out.goal_state_tolerance.append(
            StateTolerances(position=float(per_joint.goal), velocity=float(constraints.stopped_velocity_tolerance))
        )
    return out


def resolve_tolerance_source(default_value: float, goal_value: float) -> float:
    """The tolerance to use given a default and a value from a goal.

    A positive goal value wins; 0 keeps the default; -1 (:data:`ERASE_VALUE`) gives 0 (unchecked).

    Raises:
        ValueError: For any other negative goal value.
    """
    if goal_value > 0.0:
        return goal_value
    if abs(goal_value - ERASE_VALUE) < 1.2e-7:  # float epsilon, as upstream
        return 0.0
    if goal_value < 0.0:
        raise ValueError(f"illegal tolerance {goal_value}: use > 0, 0 (default) or -1 (erase)")
    return default_value


def get_segment_tolerances_from_goal(
    default: SegmentTolerances,
    joints: Sequence[str],
    path_tolerance: Sequence[JointTolerance] = (),
    goal_tolerance: Sequence[JointTolerance] = (),
    goal_time_tolerance: float = 0.0,
) -> SegmentTolerances:
    """Tolerances of one FollowJointTrajectory goal: the defaults overridden by the goal's values.

    As in ros2_controllers, an unknown joint name or an illegal value makes the whole goal fall back
    to the defaults (with an error logged); the goal itself is not rejected.
    """
    out = SegmentTolerances(
        [StateTolerances(t.position, t.velocity, t.acceleration) for t in default.state_tolerance],
        [StateTolerances(t.position, t.velocity, t.acceleration) for t in default.goal_state_tolerance],
        default.goal_time_tolerance,
    )
    try:
        out.goal_time_tolerance = resolve_tolerance_source(default.goal_time_tolerance, goal_time_tolerance)
        for source, target, default_list in (
            (path_tolerance, out.state_tolerance, default.state_tolerance),
            (goal_tolerance, out.goal_state_tolerance, default.goal_state_tolerance),
        ):
            for tol in source:
                if tol.name not in joints:
                    raise ValueError(f"joint '{tol.name}' of a tolerance is not a controller joint {list(joints)}")
                i = list(joints).index(tol.name)
                target[i] = StateTolerances(
                    resolve_tolerance_source(default_list[i].position, tol.position),
                    resolve_tolerance_source(default_list[i].velocity, tol.velocity),
                    resolve_tolerance_source(default_list[i].acceleration, tol.acceleration),
                )
    except ValueError as exc:
        _log.error("goal tolerances ignored, using the defaults: %s", exc)
        return default
    return out


def compute_state_error(
    current: JointTrajectoryPoint,
    desired: JointTrajectoryPoint,
    wraparound: Sequence[bool],
    has_state: Mapping[str, bool],
    has_command: Mapping[str, bool],
) -> JointTrajectoryPoint:
    """``desired - current`` per joint, the fields the tolerances of a JTC are checked against.

    Continuous joints (``wraparound``) take the shortest angular distance. Velocity and acceleration
    errors exist when the state interfaces have those fields, and are 0 unless the controller commands
    velocity or effort (velocity error), or acceleration (acceleration error).

    Args:
        current: The measured state.
        desired: The sampled reference.
        wraparound: Per joint, True for continuous joints.
        has_state: State interface kind -> whether the controller reads it.
        has_command: Command interface kind -> whether the controller commands it.
    """
    return state_error_function(wraparound, has_state, has_command)(current, desired)


def state_error_function(
    wraparound: Sequence[bool], has_state: Mapping[str, bool], has_command: Mapping[str, bool]
) -> Callable[[JointTrajectoryPoint, JointTrajectoryPoint], JointTrajectoryPoint]:
    """:func:`compute_state_error` with its joints and interfaces fixed: a function of ``(current, desired)``.

    A JTC prepares it when it is configured; every decision that depends on the interfaces is taken here once,
    not in every cycle. The numbers are the same as :func:`compute_state_error`'s.
    """
    n = len(wraparound)
    joints = range(n)
    wrap = list(wraparound) if any(wraparound) else None
    # Per field: whether the state interfaces have it, and whether its error is computed (else it is zeros). As
    # upstream, the velocity error is only computed with a velocity or effort command, so `stopped_velocity_tolerance`
    # is not checked when the JTC commands positions.
    has_v, has_a = has_state["velocity"], has_state["acceleration"]
    v_error = has_v and (has_command["velocity"] or has_command["effort"])
    a_error = has_a and has_command["acceleration"]

    def differences(des: list[float], cur: list[float]) -> list[float]:
        if len(des) == n and len(cur) == n:  # every joint, nothing more: the common case, in every cycle
            return list(map(operator.sub, des, cur))
        return [des[i] - cur[i] for i in joints]  # the first n values (fewer: an IndexError)

    def state_error(current: JointTrajectoryPoint, desired: JointTrajectoryPoint) -> JointTrajectoryPoint:
        cur, des = current.positions, desired.positions
        if wrap is None:  # no continuous joint
            positions = list(map(operator.sub, des, cur)) if len(des) == n and len(cur) == n else differences(des, cur)
        else:
            positions = [shortest_angular_distance(cur[i], des[i]) if wrap[i] else des[i] - cur[i] for i in joints]
        velocities = (differences(desired.velocities, current.velocities) if v_error
                      else [0.0] * n if has_v else [])
        accelerations = (differences(desired.accelerations, current.accelerations) if a_error
                         else [0.0] * n if has_a else [])
        return JointTrajectoryPoint(positions, velocities, accelerations, [], 0.0)

    return state_error


def checked_joints(tolerances: Sequence[StateTolerances], dof: int) -> list[int]:
    """The joints (of the first ``dof``) whose tolerance checks anything: one of its values is above 0."""
    return [i for i, t in enumerate(tolerances[:dof]) if t.position > 0.0 or t.velocity > 0.0 or t.acceleration > 0.0]


def check_state_tolerance_per_joint(
    state_error: JointTrajectoryPoint, index: int, tolerance: StateTolerances, show_errors: bool = False
) -> bool:
    """True if joint ``index`` is within every tolerance that is > 0 (missing error fields count as 0)."""
    position, velocity, acceleration = tolerance.position, tolerance.velocity, tolerance.acceleration
    ok = True  # each check that fails logs (with show_errors), in the order position, velocity, acceleration
    if position > 0.0 and not _within("position", position, state_error.positions, index, show_errors):
        ok = False
    if velocity > 0.0 and not _within("velocity", velocity, state_error.velocities, index, show_errors):
        ok = False
    if acceleration > 0.0 and not _within("acceleration", acceleration, state_error.accelerations, index, show_errors):
        ok = False
    return ok


def _within(name: str, tolerance: float, errors: list[float], index: int, show_errors: bool) -> bool:
    """One check of :func:`check_state_tolerance_per_joint` (``tolerance`` > 0)."""
    error = errors[index] if len(errors) > index else 0.0
    # a NaN error fails the check: not knowing where the joint is is not "within tolerance"
    if abs(error) > tolerance or math.isnan(error):
        if show_errors:
            _log.error("joint %d: %s error %.6g exceeds the tolerance %.6g", index, name, error, tolerance)
        return False
    return True
