"""The FollowJointTrajectory action side of the joint trajectory controller.

:class:`FollowJointTrajectoryServer` is mixed into
:class:`~rrbot_workshop.controllers.joint_trajectory.JointTrajectoryController`: it accepts or rejects
goals, preempts and cancels them, fills their feedback every cycle and ends them with the result codes of
``control_msgs`` (as ros2_controllers' ``goal_received_callback``, ``goal_accepted_callback``,
``goal_cancelled_callback`` and the goal part of ``update``).
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any

from rrbot_workshop.controllers.follow_joint_trajectory import (
    FollowJointTrajectoryFeedback,
    FollowJointTrajectoryGoal,
    GoalHandle,
    GoalStatus,
)
from rrbot_workshop.controllers.follow_joint_trajectory import FollowJointTrajectoryResult as Result
from rrbot_workshop.controllers.joint_trajectory_parameters import validate_trajectory_msg
from rrbot_workshop.controllers.tolerances import get_segment_tolerances_from_goal
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import Header, JointTolerance, JointTrajectory

__all__ = ["FollowJointTrajectoryServer"]


class FollowJointTrajectoryServer:
    """Goal handling of a JTC (a mixin: it uses the controller's trajectory state)."""

    _active_goal: GoalHandle | None
    _p: Any
    _has_cmd: dict[str, bool]
    _pending: JointTrajectory | None
    _is_holding: bool
    _default_tol: Any
    _active_tol: Any
    logger: Any
    state_desired: Any
    state_current: Any
    state_error: Any

    if TYPE_CHECKING:  # provided by the controller

        def get_name(self) -> str: ...
        def get_node(self) -> Any: ...
        def get_lifecycle_state(self) -> Any: ...
        def _hold_position(self) -> JointTrajectory: ...
        def _success_point(self) -> JointTrajectory: ...
        def _reject(self, reason: str) -> None: ...

    def send_goal(
        self,
        trajectory: JointTrajectory,
        path_tolerance: list[JointTolerance] | None = None,
        goal_tolerance: list[JointTolerance] | None = None,
        goal_time_tolerance: float = 0.0,
    ) -> GoalHandle:
        """Send a FollowJointTrajectory goal (the action interface, in process).

        A rejected goal comes back with ``accepted`` False and a result whose ``error_code`` says why
        (``INVALID_JOINTS``, ``OLD_HEADER_TIMESTAMP`` or ``INVALID_GOAL``). An accepted goal preempts
        the running one (which ends ABORTED with ``INVALID_GOAL``, as in Jazzy) and ends SUCCEEDED, ABORTED (path or goal tolerance) or
        CANCELED.

        Args:
            trajectory: The trajectory to follow.
            path_tolerance: Per-joint tolerances while moving (0 keeps the default, -1 erases it).
            goal_tolerance: Per-joint tolerances at the end.
            goal_time_tolerance: Time allowed past the end in [s] (0 keeps ``constraints.goal_time``).
        """
        goal = FollowJointTrajectoryGoal(trajectory, list(path_tolerance or []), list(goal_tolerance or []),
                                         goal_time_tolerance)
        handle = GoalHandle(goal, self._cancel_goal)
        if self.get_lifecycle_state() is not State.ACTIVE:
            self._reject("the controller is not active")
            handle._finish(GoalStatus.UNKNOWN, Result.INVALID_GOAL, "Can't accept new action goals. Controller is not running.")
            return handle
        problem = validate_trajectory_msg(trajectory, self._p, self._has_cmd["effort"], self.get_node().now())
        if problem is not None:
            self._reject(problem[1])
            handle._finish(GoalStatus.UNKNOWN, problem[0], problem[1])
            return handle
        if self._active_goal is not None:
            self._active_goal._finish(GoalStatus.ABORTED, Result.INVALID_GOAL,
                                      "Current goal preempted by new incoming action.")
        self._pending = copy.deepcopy(trajectory)
        self._is_holding = False
        handle.accepted = True
        handle.status = GoalStatus.EXECUTING
        self._active_goal = handle
        self._active_tol = get_segment_tolerances_from_goal(
            self._default_tol, list(self._p.joints), goal.path_tolerance, goal.goal_tolerance, goal_time_tolerance)
        return handle

    def _cancel_goal(self, handle: GoalHandle) -> bool:
        if handle is not self._active_goal:
            return False
        handle._finish(GoalStatus.CANCELED, Result.SUCCESSFUL, "")
        self._active_goal = None
        self._pending = self._hold_position()
        return True

    def _handle_outcome(self, time: float, violated: bool, before_last_point: bool, outside_goal: bool,
                        within_goal_time: bool, time_difference: float) -> None:
        goal = self._active_goal
        if goal is not None:
            goal.feedback = FollowJointTrajectoryFeedback(
                Header(stamp=time), list(self._p.joints), self.state_desired.copy(), self.state_current.copy(),
                self.state_error.copy())  # the points' own copies: lists of floats, no deep copy per cycle
            if violated:
                goal._finish(GoalStatus.ABORTED, Result.PATH_TOLERANCE_VIOLATED, "Aborted due to path tolerance violation")
                self._active_goal = None
                self.logger.warning("'%s': goal aborted, path tolerance violated", self.get_name())
                self._pending = self._hold_position()
            elif not before_last_point:
                if not outside_goal:
                    goal._finish(GoalStatus.SUCCEEDED, Result.SUCCESSFUL, "Goal successfully reached!")
                    self._active_goal = None
                    self._pending = self._success_point()
                elif not within_goal_time:
                    text = f"Aborted due to goal_time_tolerance exceeding by {time_difference:.6f} seconds"
                    goal._finish(GoalStatus.ABORTED, Result.GOAL_TOLERANCE_VIOLATED, text)
                    self._active_goal = None
                    self.logger.warning("'%s': %s", self.get_name(), text)
                    self._pending = self._hold_position()
        elif violated:
            self.logger.error("'%s': holding position due to a path tolerance violation", self.get_name())
            self._pending = self._hold_position()
        elif not before_last_point and not within_goal_time:
            self.logger.error("'%s': goal_time tolerance exceeded, holding position", self.get_name())
            self._pending = self._hold_position()

    @property
    def active_goal(self) -> GoalHandle | None:
        """The goal being executed, or None."""
        return self._active_goal

