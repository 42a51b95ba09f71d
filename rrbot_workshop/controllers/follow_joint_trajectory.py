"""A FollowJointTrajectory action, in process: goal, feedback, result and a goal handle.

ros2_control's joint trajectory controller offers ``control_msgs/action/FollowJointTrajectory``: a
client sends a trajectory with optional tolerances, gets feedback every cycle and, at the end, a
result with an error code. Here :meth:`JointTrajectoryController.send_goal` returns a
:class:`GoalHandle` whose ``status``, ``feedback`` and ``result`` the controller updates as it runs.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, field

from rrbot_workshop.msgs import Header, JointTolerance, JointTrajectory, JointTrajectoryPoint

__all__ = [
    "GoalStatus",
    "FollowJointTrajectoryGoal",
    "FollowJointTrajectoryFeedback",
    "FollowJointTrajectoryResult",
    "GoalHandle",
]


class GoalStatus(enum.IntEnum):
    """``action_msgs/msg/GoalStatus`` values."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6


@dataclass
class FollowJointTrajectoryGoal:
    """Goal of ``control_msgs/action/FollowJointTrajectory``; ``goal_time_tolerance`` in [s]."""

    trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    path_tolerance: list[JointTolerance] = field(default_factory=list)
    goal_tolerance: list[JointTolerance] = field(default_factory=list)
    goal_time_tolerance: float = 0.0


@dataclass
class FollowJointTrajectoryFeedback:
    """Feedback: where the joints should be (``desired``), are (``actual``) and the difference."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    desired: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    actual: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)


@dataclass
class FollowJointTrajectoryResult:
    """Result with the ``control_msgs`` error codes."""

    SUCCESSFUL = 0
    INVALID_GOAL = -1
    INVALID_JOINTS = -2
    OLD_HEADER_TIMESTAMP = -3
    PATH_TOLERANCE_VIOLATED = -4
    GOAL_TOLERANCE_VIOLATED = -5

    error_code: int = 0
    error_string: str = ""


class GoalHandle:
    """The client's view of one goal.

    Attributes:
        goal: The goal as sent.
        accepted: False if the controller rejected it (then ``result`` says why).
        status: Current :class:`GoalStatus`.
        feedback: Latest feedback, or None before the first cycle.
        result: The result once the goal is done (or rejected), else None.
    """

    def __init__(self, goal: FollowJointTrajectoryGoal, cancel_callback: Callable[[GoalHandle], bool] | None = None) -> None:
        self.goal = goal
        self.accepted = False
        self.status = GoalStatus.UNKNOWN
        self.feedback: FollowJointTrajectoryFeedback | None = None
        self.result: FollowJointTrajectoryResult | None = None
        self._cancel_callback = cancel_callback

    @property
    def done(self) -> bool:
        """True once the goal succeeded, was aborted or canceled, or was rejected."""
        return self.result is not None

    def cancel(self) -> bool:
        """Ask the controller to cancel; True if the goal was still running and is now canceled."""
        if self.done or self._cancel_callback is None:
            return False
        return self._cancel_callback(self)

    # ----------------------------------------------------------------- set by the controller
    def _finish(self, status: GoalStatus, error_code: int, error_string: str) -> None:
        self.status = status
        self.result = FollowJointTrajectoryResult(error_code, error_string)

    def __repr__(self) -> str:
        res = f", error_code={self.result.error_code}" if self.result else ""
        return f"GoalHandle(status={self.status.name}{res})"
