"""Parameters of the joint trajectory controller and the checks on its input.

The schema is the ros2_controllers Jazzy ``joint_trajectory_controller`` parameter file, written in
generate_parameter_library syntax. :func:`check_interface_combinations` and
:func:`validate_trajectory_msg` hold the rules that decide which interface sets a JTC can work with
and which trajectory messages it accepts; each rule gives a sentence saying what is wrong.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.controllers.follow_joint_trajectory import FollowJointTrajectoryResult as Result
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.params import register_validator
from rrbot_workshop.msgs import JointTrajectory

__all__ = [
    "JTC_PARAMETERS",
    "command_interface_problem",
    "state_interface_problem",
    "check_interface_combinations",
    "validate_trajectory_msg",
]

JTC_PARAMETERS = """
joint_trajectory_controller:
  joints:
    type: string_array
    default_value: []
    read_only: true
    description: "Joints whose state the controller reads and whose trajectories it accepts."
    validation: {unique<>: null, size_gt<>: [0]}
  command_joints:
    type: string_array
    default_value: []
    read_only: true
    description: "Prefixes of the command interfaces; empty means 'joints'. In a chain, the names of the following controller's references (e.g. pid_controller_joint1/joint1)."
    validation: {unique<>: null}
  command_interfaces:
    type: string_array
    default_value: []
    read_only: true
    description: "Command interfaces per joint: effort | velocity | position [velocity [acceleration]] | position, effort."
    validation:
      unique<>: null
      size_gt<>: [0]
      subset_of<>: [[position, velocity, acceleration, effort]]
      "joint_trajectory_controller::command_interface_type_combinations": null
  state_interfaces:
    type: string_array
    default_value: []
    read_only: true
    description: "State interfaces per joint: position [velocity [acceleration]]."
    validation:
      unique<>: null
      size_gt<>: [0]
      subset_of<>: [[position, velocity, acceleration]]
      "joint_trajectory_controller::state_interface_type_combinations": null
  allow_partial_joints_goal: {type: bool, default_value: false, description: "Accept trajectories for a subset of the joints."}
  open_loop_control: {type: bool, default_value: false, read_only: true, description: "Deprecated in Jazzy: use interpolate_from_desired_state and zero gains."}
  interpolate_from_desired_state: {type: bool, default_value: false, read_only: true, description: "Start new trajectories from the last command instead of the measured state."}
  allow_integration_in_goal_trajectories: {type: bool, default_value: false, description: "Accept waypoints given only as velocities or accelerations."}
  set_last_command_interface_value_as_state_on_activation: {type: bool, default_value: true, description: "On activation, use finite command values as the state to hold."}
  action_monitor_rate: {type: double, default_value: 20.0, read_only: true, description: "Rate of action status checks in [Hz].", validation: {gt_eq<>: [0.1]}}
  interpolation_method:
    type: string
    default_value: splines
    read_only: true
    description: "splines (linear, cubic or quintic by the fields given) or none (jump to the next waypoint)."
    validation: {one_of<>: [[splines, none]]}
  allow_nonzero_velocity_at_trajectory_end: {type: bool, default_value: false, description: "Accept trajectories whose last waypoint still moves."}
  cmd_timeout: {type: double, default_value: 0.0, description: "Hold position this long in [s] after the end of a trajectory that did not reach its goal; 0 disables; must exceed constraints.goal_time."}
  gains:
    __map_joints:
      p: {type: double, default_value: 0.0, description: "Proportional gain."}
      i: {type: double, default_value: 0.0, description: "Integral gain."}
      d: {type: double, default_value: 0.0, description: "Derivative gain."}
      ff_velocity_scale: {type: double, default_value: 0.0, description: "Feed-forward scale of the desired velocity."}
      u_clamp_max: {type: double, default_value: .inf, description: "Upper output clamp."}
      u_clamp_min: {type: double, default_value: -.inf, description: "Lower output clamp."}
      i_clamp_max: {type: double, default_value: .inf, description: "Upper integral clamp."}
      i_clamp_min: {type: double, default_value: -.inf, description: "Lower integral clamp."}
      antiwindup: {type: bool, default_value: false, description: "Deprecated in Jazzy (legacy strategy): keep the stored integral within the integral clamps."}
      antiwindup_strategy:
        type: string
        default_value: legacy
        description: "legacy (Jazzy's default) | none | back_calculation | conditional_integration."
        validation: {one_of<>: [[legacy, none, back_calculation, conditional_integration]]}
      tracking_time_constant: {type: double, default_value: 0.0, description: "Back-calculation time constant in [s]; 0 picks one."}
  constraints:
    stopped_velocity_tolerance: {type: double, default_value: 0.01, description: "Largest joint velocity in [rad/s] that counts as stopped at the goal."}
    goal_time: {type: double, default_value: 0.0, description: "Time in [s] allowed past the end to reach the goal; 0 waits forever.", validation: {gt_eq<>: [0.0]}}
    __map_joints:
      trajectory: {type: double, default_value: 0.0, description: "Path position tolerance in [rad]; 0 unchecked."}
      goal: {type: double, default_value: 0.0, description: "Goal position tolerance in [rad]; 0 unchecked."}
"""


def command_interface_problem(interfaces: Sequence[str]) -> str | None:
    """Why a ``command_interfaces`` list is not a combination a JTC can drive, or None if it is."""
    names = set(interfaces)
    if "velocity" in names and len(names) > 1 and "position" not in names:
        return "'velocity' must be used alone or together with 'position' (valid: [effort], [velocity], " \
               "[position], [position, velocity], [position, velocity, acceleration], [position, effort])"
    # ros2_controllers Jazzy lets [position, acceleration] through (its check joins the two
    # conditions with 'and'); an acceleration command needs both lower derivatives, so reject it.
    if "acceleration" in names and not {"position", "velocity"} <= names:
        return "'acceleration' needs both 'position' and 'velocity' (valid: [position, velocity, acceleration])"
    if "effort" in names and not (len(names) == 1 or (len(names) == 2 and "position" in names)):
        return "'effort' must be used alone or together with 'position' only (valid: [effort], [position, effort])"
    return None


def state_interface_problem(interfaces: Sequence[str]) -> str | None:
    """Why a ``state_interfaces`` list is not usable by a JTC, or None if it is."""
    names = set(interfaces)
    if "velocity" in names and "position" not in names:
        return "'velocity' needs 'position' too (valid: [position], [position, velocity], " \
               "[position, velocity, acceleration])"
    if "acceleration" in names and not {"position", "velocity"} <= names:
        return "'acceleration' needs 'position' and 'velocity' (valid: [position, velocity, acceleration])"
    return None


register_validator("joint_trajectory_controller::command_interface_type_combinations", command_interface_problem)
register_validator("joint_trajectory_controller::state_interface_type_combinations", state_interface_problem)


def check_interface_combinations(params: Any, owner: str) -> None:
    """Checks that need several parameters at once (generate_parameter_library sees one at a time).

    Raises:
        ParameterError: If velocity-only or effort commands lack position and velocity states, or
            ``command_joints`` is longer than ``joints``.
    """
    cmd, state = list(params.command_interfaces), set(params.state_interfaces)
    has_pos_vel_state = {"position", "velocity"} <= state
    if cmd == ["velocity"] and not has_pos_vel_state:
        raise ParameterError(
            owner, "state_interfaces",
            f"is {sorted(state)}, but the command interface 'velocity' alone runs a PID that needs the "
            "'position' and 'velocity' state interfaces",
        )
    if "effort" in cmd and (len(cmd) == 1 or (len(cmd) == 2 and "position" in cmd)) and not has_pos_vel_state:
        raise ParameterError(
            owner, "state_interfaces",
            f"is {sorted(state)}, but an 'effort' command interface needs the 'position' and 'velocity' "
            "state interfaces",
        )
    if len(params.command_joints) > len(params.joints):
        raise ParameterError(
            owner, "command_joints",
            f"has {len(params.command_joints)} entries, more than 'joints' ({len(params.joints)})",
        )
    if 0 < len(params.command_joints) < len(params.joints):
        missing = [j for j in params.command_joints if j not in params.joints]
        if missing:
            raise ParameterError(
                owner, "command_joints",
                f"is shorter than 'joints', so it must be a subset of {list(params.joints)}; {missing} are not",
            )


def _size_problem(values: list[float], joint_count: int, field: str, index: int) -> str | None:
    if len(values) != joint_count:
        return f"point {index} has {len(values)} {field} for {joint_count} joints"
    return None


def validate_trajectory_msg(  # noqa: C901 - one rule after the other, as upstream
    trajectory: JointTrajectory, params: Any, has_effort_command_interface: bool, now: float
) -> tuple[int, str] | None:
    """Check a trajectory against the rules of ros2_controllers' ``validate_trajectory_msg``.

    Args:
        trajectory: The incoming message.
        params: The controller's parameters.
        has_effort_command_interface: Whether 'effort' is among the command interfaces.
        now: Current time in [s] (for trajectories with a start stamp).

    Returns:
        None if the message is accepted, else ``(error_code, reason)`` with a
        ``FollowJointTrajectory`` result code.
    """
    joints = list(params.joints)
    names = list(trajectory.joint_names)
    if not params.allow_partial_joints_goal and len(names) != len(joints):
        return Result.INVALID_JOINTS, (
            f"the trajectory names {len(names)} joints {names} but the controller has {len(joints)} {joints}; "
            "send all of them or set allow_partial_joints_goal"
        )
    if not names:
        return Result.INVALID_JOINTS, "the trajectory has no joint_names"
    if not trajectory.points:
        return Result.INVALID_GOAL, "the trajectory has no points"
    for name in names:
        if name not in joints:
            return Result.INVALID_JOINTS, f"joint '{name}' is not a controller joint (valid: {joints})"
    # Not checked by ros2_controllers Jazzy: repeated names (the re-sorting would lose a joint) and, below,
    # non-finite values (they would reach the hardware as commands).
    if len(set(names)) != len(names):
        return Result.INVALID_JOINTS, f"joint_names {names} repeat a joint"
    if not params.allow_nonzero_velocity_at_trajectory_end:
        for i, v in enumerate(trajectory.points[-1].velocities):
            if abs(v) > 1.2e-7 and i < len(names):
                return Result.INVALID_GOAL, (
                    f"the last point's velocity of '{names[i]}' is {v}, not 0; "
                    "set allow_nonzero_velocity_at_trajectory_end to allow it"
                )
    stamp = float(trajectory.header.stamp)
    if stamp != 0.0:
        end = stamp + trajectory.points[-1].time_from_start
        if end < now:
            return Result.OLD_HEADER_TIMESTAMP, (
                f"the trajectory starts at {stamp:.3f} s and ends at {end:.3f} s, before now ({now:.3f} s)"
            )
    previous = 0.0
    count = len(names)
    for i, point in enumerate(trajectory.points):
        # Not checked by ros2_controllers Jazzy either (a Duration cannot hold NaN): a time that is not a finite
        # number >= 0 would make the sampling never reach or always pass the point.
        if not (math.isfinite(point.time_from_start) and point.time_from_start >= 0.0):
            return Result.INVALID_GOAL, (
                f"point {i} has time_from_start {point.time_from_start}; it must be a finite number of seconds >= 0"
            )
        if i > 0 and not point.time_from_start > previous:
            return Result.INVALID_GOAL, (
                f"time_from_start must strictly increase, but point {i - 1} is at {previous} s and point {i} "
                f"at {point.time_from_start} s"
            )
        previous = point.time_from_start
        if params.allow_integration_in_goal_trajectories:
            if not point.positions and not point.velocities and not point.accelerations:
                return Result.INVALID_GOAL, f"point {i} has no positions, velocities or accelerations"
            fields = [("positions", point.positions), ("velocities", point.velocities),
                      ("accelerations", point.accelerations)]
            for fname, values in fields:
                if values and (problem := _size_problem(values, count, fname, i)):
                    return Result.INVALID_GOAL, problem
        else:
            if problem := _size_problem(point.positions, count, "positions", i):
                return Result.INVALID_GOAL, problem + (
                    " (positions are required unless allow_integration_in_goal_trajectories is set)"
                    if not point.positions else ""
                )
            for fname, values in (("velocities", point.velocities), ("accelerations", point.accelerations)):
                if values and (problem := _size_problem(values, count, fname, i)):
                    return Result.INVALID_GOAL, problem
        if point.effort and not has_effort_command_interface:
            return Result.INVALID_GOAL, f"point {i} has efforts but 'effort' is not a command interface"
        for fname, values in (("positions", point.positions), ("velocities", point.velocities),
                              ("accelerations", point.accelerations), ("effort", point.effort)):
            if any(not math.isfinite(v) for v in values):
                return Result.INVALID_GOAL, f"point {i} has a non-finite value in {fname}"
    return None
