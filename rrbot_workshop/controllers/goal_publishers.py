"""Test goal publishers, like the ``ros2_controllers_test_nodes`` the workshop launches in task 2.

Two small nodes publish a list of goals in turn, one every ``wait_sec_between_publish`` seconds of
(simulated) time, starting one period after they start (as a ROS timer does):

* :class:`ForwardCommandGoalPublisher` sends ``Float64MultiArray`` to ``/<controller_name>/commands``;
* :class:`JointTrajectoryGoalPublisher` sends a one-point ``JointTrajectory`` (reached after
  ``goal_time_from_start`` seconds) to ``/<controller_name>/joint_trajectory``.

Their defaults are the numbers of the workshop's ``test_goal_publishers_config.yaml``. Drive one with
:meth:`GoalPublisher.step` or add it as a controller manager cycle hook (it is callable as
``publisher(time, period)``). :func:`load_goal_publishers` builds both from that YAML file.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.topics import Node, TopicBus
from rrbot_workshop.msgs import Float64MultiArray, Header, JointTrajectory, JointTrajectoryPoint

__all__ = [
    "DEFAULT_GOALS",
    "GoalPublisher",
    "ForwardCommandGoalPublisher",
    "JointTrajectoryGoalPublisher",
    "load_goal_publishers",
    "default_config_path",
]

_log = logging.getLogger(__name__)

#: The four goals of the workshop, in [rad].
DEFAULT_GOALS: tuple[tuple[float, ...], ...] = ((0.785, 0.785), (0.0, 0.0), (-0.785, -0.785), (0.0, 0.0))


class GoalPublisher:
    """Publishes ``goals`` in turn every ``wait_sec_between_publish`` seconds.

    Args:
        bus: The running system's topic bus.
        node_name: Name of the publishing node.
        goals: The goals, published in order and then again from the first.
        wait_sec_between_publish: Time between two publications in [s].
        repeat_the_same_goal: How many times each goal is published before the next one.
    """

    msg_type: type = Float64MultiArray
    topic_suffix = "commands"

    def __init__(
        self,
        bus: TopicBus,
        node_name: str,
        controller_name: str,
        goals: Sequence[Sequence[float]],
        wait_sec_between_publish: float,
        repeat_the_same_goal: int = 1,
    ) -> None:
        if not goals:
            raise ParameterError(node_name, "goal_names", "must name at least one goal")
        if wait_sec_between_publish <= 0:
            raise ParameterError(node_name, "wait_sec_between_publish", f"must be > 0 [s], got {wait_sec_between_publish}")
        if repeat_the_same_goal < 1:
            raise ParameterError(node_name, "repeat_the_same_goal", f"must be >= 1, got {repeat_the_same_goal}")
        self.node = Node(node_name, bus)
        self.controller_name = controller_name
        self.goals = [list(map(float, g)) for g in goals]
        self.wait_sec_between_publish = float(wait_sec_between_publish)
        self.repeat_the_same_goal = int(repeat_the_same_goal)
        self.topic = f"/{controller_name}/{self.topic_suffix}"
        self._publisher = self.node.create_publisher(self.msg_type, self.topic)
        self._next_time: float | None = None
        self.published = 0

    def start(self, time: float) -> None:
        """Start the timer at ``time`` [s]; the first goal goes out one period later."""
        self._next_time = time + self.wait_sec_between_publish

    @property
    def current_goal_index(self) -> int:
        """Index of the goal published last (-1 before the first)."""
        return (self.published - 1) // self.repeat_the_same_goal % len(self.goals) if self.published else -1

    def step(self, time: float) -> int:
        """Publish every goal that is due at ``time`` [s]; the first call starts the timer.

        Returns:
            Number of messages published by this call.
        """
        if self._next_time is None:
            self.start(time)
        count = 0
        assert self._next_time is not None
        while time + 1e-9 >= self._next_time:
            goal = self.goals[self.published // self.repeat_the_same_goal % len(self.goals)]
            self._publisher.publish(self.make_message(goal, self._next_time))
            _log.info("%s published goal %s on %s", self.node.get_name(), goal, self.topic)
            self.published += 1
            count += 1
            self._next_time += self.wait_sec_between_publish
        return count

    def __call__(self, time: float, period: float) -> None:
        """Cycle hook form of :meth:`step`."""
        self.step(time)

    def make_message(self, goal: list[float], time: float) -> Any:
        """The message for one goal."""
        return Float64MultiArray(data=list(goal))


class ForwardCommandGoalPublisher(GoalPublisher):
    """``publisher_forward_position_controller``: position goals for a forward command controller."""

    def __init__(
        self,
        bus: TopicBus,
        controller_name: str = "forward_position_controller",
        goals: Sequence[Sequence[float]] = DEFAULT_GOALS,
        wait_sec_between_publish: float = 5.0,
        node_name: str = "publisher_forward_position_controller",
    ) -> None:
        super().__init__(bus, node_name, controller_name, goals, wait_sec_between_publish)


class JointTrajectoryGoalPublisher(GoalPublisher):
    """``publisher_joint_trajectory_controller``: one-point trajectories for a JTC.

    Args:
        bus: The running system's topic bus.
        controller_name: The JTC's name.
        goals: Joint positions in [rad], one list per goal.
        joints: Joint names of the trajectories.
        wait_sec_between_publish: Time between two goals in [s].
        goal_time_from_start: ``time_from_start`` of the single point in [s].
        repeat_the_same_goal: How many times each goal is sent before the next one.
        node_name: Name of the publishing node.
    """

    msg_type = JointTrajectory
    topic_suffix = "joint_trajectory"

    def __init__(
        self,
        bus: TopicBus,
        controller_name: str = "joint_trajectory_controller",
        goals: Sequence[Sequence[float]] = DEFAULT_GOALS,
        joints: Sequence[str] = ("joint1", "joint2"),
        wait_sec_between_publish: float = 6.0,
        goal_time_from_start: float = 3.0,
        repeat_the_same_goal: int = 1,
        node_name: str = "publisher_joint_trajectory_controller",
    ) -> None:
        bad = [g for g in goals if len(g) != len(joints)]
        if bad:
            raise ParameterError(node_name, "goal_names", f"goals {bad} do not have one value per joint {list(joints)}")
        if goal_time_from_start <= 0:
            raise ParameterError(node_name, "goal_time_from_start", f"must be > 0 [s], got {goal_time_from_start}")
        super().__init__(bus, node_name, controller_name, goals, wait_sec_between_publish, repeat_the_same_goal)
        self.joints = list(joints)
        self.goal_time_from_start = float(goal_time_from_start)

    def make_message(self, goal: list[float], time: float) -> JointTrajectory:
        """A trajectory with one point at ``goal_time_from_start``, starting on receipt (stamp 0)."""
        point = JointTrajectoryPoint(positions=list(goal), time_from_start=self.goal_time_from_start)
        return JointTrajectory(Header(stamp=0.0), list(self.joints), [point])


def default_config_path() -> Path:
    """``descriptions/rrbot/config/test_goal_publishers_config.yaml``."""
    from rrbot_workshop.description import descriptions_root

    return descriptions_root() / "rrbot" / "config" / "test_goal_publishers_config.yaml"


def _goals(node: str, params: Mapping[str, Any], jtc: bool) -> list[list[float]]:
    names = params.get("goal_names")
    if not isinstance(names, list) or not names:
        raise ParameterError(node, "goal_names", "must be a non-empty list of parameter names such as ['pos1']")
    goals = []
    for name in names:
        value = params.get(name)
        if jtc and isinstance(value, Mapping):
            value = value.get("positions")
        if not isinstance(value, list) or not all(isinstance(v, int | float) for v in value):
            form = f"'{name}: {{positions: [..]}}'" if jtc else f"'{name}: [..]'"
            raise ParameterError(node, str(name), f"is named in goal_names but is not given as {form}")
        goals.append([float(v) for v in value])
    return goals


def load_goal_publishers(bus: TopicBus, path: str | Path | None = None) -> dict[str, GoalPublisher]:
    """Build the publishers of a ``test_goal_publishers_config.yaml`` (ROS layout).

    Entries whose name contains ``forward`` become :class:`ForwardCommandGoalPublisher`, entries with
    ``joints`` (or ``trajectory`` in the name) :class:`JointTrajectoryGoalPublisher`.

    Raises:
        ParameterError: If the file is missing, not in the ``<node>: ros__parameters:`` layout, or a
            goal named in ``goal_names`` is not given.
    """
    source = Path(path) if path is not None else default_config_path()
    try:
        data = yaml.safe_load(source.read_text()) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise ParameterError("goal publishers", str(source), f"cannot be read: {exc}") from exc
    out: dict[str, GoalPublisher] = {}
    for node, body in data.items():
        if not isinstance(body, Mapping) or not isinstance(body.get("ros__parameters"), Mapping):
            raise ParameterError(str(node), "ros__parameters", f"missing in {source}")
        p = body["ros__parameters"]
        jtc = "joints" in p or "trajectory" in str(node)
        goals = _goals(str(node), p, jtc)
        if jtc:
            out[str(node)] = JointTrajectoryGoalPublisher(
                bus, p.get("controller_name", "joint_trajectory_controller"), goals, p.get("joints", ["joint1", "joint2"]),
                float(p.get("wait_sec_between_publish", 6)), float(p.get("goal_time_from_start", 3.0)),
                int(p.get("repeat_the_same_goal", 1)), node_name=str(node))
        else:
            out[str(node)] = ForwardCommandGoalPublisher(
                bus, p.get("controller_name", "forward_position_controller"), goals,
                float(p.get("wait_sec_between_publish", 5)), node_name=str(node))
    return out
