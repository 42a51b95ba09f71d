"""Test goal publishers, like the ``ros2_controllers_test_nodes`` that the workshop and ros2_control_demos launch.

Two small nodes publish a list of goals in turn, one every ``wait_sec_between_publish`` seconds of
(simulated) time, starting one period after they start (as a ROS timer does):

* :class:`ForwardCommandGoalPublisher` (Jazzy's ``publisher_forward_position_controller``) sends
  ``Float64MultiArray`` on ``publish_topic``;
* :class:`JointTrajectoryGoalPublisher` (Jazzy's ``publisher_joint_trajectory_controller``) sends a one-point
  ``JointTrajectory`` to ``/<controller_name>/joint_trajectory``, optionally only once a first ``/joint_states``
  showed the robot within ``starting_point_limits``.

The constructors' defaults are the numbers of the workshop's ``test_goal_publishers_config.yaml``.
:func:`load_goal_publishers` reads a parameter file in ROS layout and takes Jazzy's parameters and defaults:

``publisher_forward_position_controller``:

* ``publish_topic``: topic of the goals (default ``/position_commands``; relative names resolve in the node's
  namespace);
* ``wait_sec_between_publish``: period in [s] (default 5);
* ``goal_names``: names of the goals (default ``[pos1, pos2]``), each given as ``<name>: [..]``.

``publisher_joint_trajectory_controller``:

* ``controller_name``: the JTC (default ``position_trajectory_controller``); goals go to
  ``/<controller_name>/joint_trajectory``;
* ``wait_sec_between_publish``: period in [s] (default 6);
* ``goal_names``: each goal ``<name>: {positions: [..]}`` (or ``velocities``, ``accelerations``, ``effort``); a field
  is used if it has one value per joint, and a goal with none is skipped with a warning, as Jazzy does;
* ``joints``: joint names of the trajectories;
* ``check_starting_point``: publish only if the first ``joint_states`` is within the limits (default false);
* ``starting_point_limits.<joint>``: ``[lower, upper]`` in [rad] (default about [-2 pi, 2 pi]).

Jazzy's trajectory point is reached 4 s after it is sent. Two more keys of the workshop's file are read as the course
defines them: ``goal_time_from_start`` [s] (default 4, Jazzy's number) and ``repeat_the_same_goal`` (default 1).
Humble's ``controller_name`` of the forward publisher is accepted with a warning: Jazzy ignores it and publishes on
``publish_topic``. Any other key is refused, naming it and what is valid. Drive a publisher with
:meth:`GoalPublisher.step` or add it as a controller manager cycle hook (it is callable as ``publisher(time, period)``).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.topics import Node, TopicBus
from rrbot_workshop.msgs import Float64MultiArray, Header, JointState, JointTrajectory, JointTrajectoryPoint

__all__ = [
    "DEFAULT_GOALS",
    "FORWARD_EXECUTABLE",
    "TRAJECTORY_EXECUTABLE",
    "GoalPublisher",
    "ForwardCommandGoalPublisher",
    "JointTrajectoryGoalPublisher",
    "goal_publisher_from_parameters",
    "load_goal_publishers",
    "default_config_path",
]

_log = logging.getLogger(__name__)

#: The four goals of the workshop, in [rad].
DEFAULT_GOALS: tuple[tuple[float, ...], ...] = ((0.785, 0.785), (0.0, 0.0), (-0.785, -0.785), (0.0, 0.0))
#: Executable names of ``ros2_controllers_test_nodes``.
FORWARD_EXECUTABLE = "publisher_forward_position_controller"
TRAJECTORY_EXECUTABLE = "publisher_joint_trajectory_controller"
#: Jazzy's fixed ``time_from_start`` of a trajectory goal in [s].
JAZZY_GOAL_TIME_FROM_START = 4.0
_POINT_FIELDS = ("positions", "velocities", "accelerations", "effort")
_TWO_PI = 2 * 3.14159  # Jazzy's default starting point limits use this rounded pi


class GoalPublisher:
    """Publishes ``goals`` in turn every ``wait_sec_between_publish`` seconds.

    Args:
        bus: The running system's topic bus.
        node_name: Name of the publishing node.
        controller_name: The controller the goals are for (names the default topic).
        goals: The goals, published in order and then again from the first.
        wait_sec_between_publish: Time between two publications in [s].
        repeat_the_same_goal: How many times each goal is published before the next one.
        topic: Topic of the goals; default ``/<controller_name>/<topic_suffix>``. Relative names resolve in
            ``namespace``.
        namespace: Namespace of the node.
    """

    msg_type: type = Float64MultiArray
    topic_suffix = "commands"

    def __init__(
        self,
        bus: TopicBus,
        node_name: str,
        controller_name: str,
        goals: Sequence[Any],
        wait_sec_between_publish: float,
        repeat_the_same_goal: int = 1,
        topic: str | None = None,
        namespace: str = "/",
    ) -> None:
        if not goals:
            raise ParameterError(node_name, "goal_names", "must name at least one goal")
        if not isinstance(wait_sec_between_publish, int | float) or not wait_sec_between_publish > 0:
            raise ParameterError(node_name, "wait_sec_between_publish", f"must be > 0 [s], got {wait_sec_between_publish}")
        if repeat_the_same_goal < 1:
            raise ParameterError(node_name, "repeat_the_same_goal", f"must be >= 1, got {repeat_the_same_goal}")
        self.node = Node(node_name, bus, namespace)
        self.controller_name = controller_name
        self.goals = [self._goal(g) for g in goals]
        self.wait_sec_between_publish = float(wait_sec_between_publish)
        self.repeat_the_same_goal = int(repeat_the_same_goal)
        self.topic = self.node.resolve_topic_name(topic if topic else f"/{controller_name}/{self.topic_suffix}")
        self._publisher = self.node.create_publisher(self.msg_type, self.topic)
        self._next_time: float | None = None
        self.published = 0

    @staticmethod
    def _goal(goal: Any) -> Any:
        return [float(v) for v in goal]

    def start(self, time: float) -> None:
        """Start the timer at ``time`` [s]; the first goal goes out one period later."""
        self._next_time = time + self.wait_sec_between_publish

    @property
    def current_goal_index(self) -> int:
        """Index of the goal published last (-1 before the first)."""
        return (self.published - 1) // self.repeat_the_same_goal % len(self.goals) if self.published else -1

    def ready(self) -> bool:
        """Whether a due goal may go out (always, unless a starting point check holds it back)."""
        return True

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
            if self.ready():
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

    def make_message(self, goal: Any, time: float) -> Any:
        """The message for one goal."""
        return Float64MultiArray(data=list(goal))


class ForwardCommandGoalPublisher(GoalPublisher):
    """``publisher_forward_position_controller``: position goals for a forward command controller.

    Args:
        bus: The running system's topic bus.
        controller_name: Names the default topic ``/<controller_name>/commands`` (the workshop's habit).
        goals: One list of values per goal.
        wait_sec_between_publish: Time between two goals in [s].
        node_name: Name of the publishing node.
        publish_topic: Topic of the goals (Jazzy's parameter); overrides ``controller_name``.
        namespace: Namespace of the node (relative topics resolve in it).
    """

    def __init__(
        self,
        bus: TopicBus,
        controller_name: str = "forward_position_controller",
        goals: Sequence[Sequence[float]] = DEFAULT_GOALS,
        wait_sec_between_publish: float = 5.0,
        node_name: str = FORWARD_EXECUTABLE,
        publish_topic: str | None = None,
        namespace: str = "/",
    ) -> None:
        super().__init__(bus, node_name, controller_name, goals, wait_sec_between_publish, topic=publish_topic,
                         namespace=namespace)


class JointTrajectoryGoalPublisher(GoalPublisher):
    """``publisher_joint_trajectory_controller``: one-point trajectories for a JTC.

    Args:
        bus: The running system's topic bus.
        controller_name: The JTC's name: goals go to ``/<controller_name>/joint_trajectory``.
        goals: One goal each: a list of joint positions in [rad], or a mapping of point fields
            (``positions``, ``velocities``, ``accelerations``, ``effort``) to one value per joint.
        joints: Joint names of the trajectories.
        wait_sec_between_publish: Time between two goals in [s].
        goal_time_from_start: ``time_from_start`` of the single point in [s].
        repeat_the_same_goal: How many times each goal is sent before the next one.
        node_name: Name of the publishing node.
        check_starting_point: Publish only once the first ``joint_states`` message showed every listed joint within
            ``starting_point_limits`` (as Jazzy, only the first message is checked).
        starting_point_limits: Joint -> ``[lower, upper]`` in [rad]; missing joints get [-2 pi, 2 pi].
        namespace: Namespace of the node (``joint_states`` resolves in it).
    """

    msg_type = JointTrajectory
    topic_suffix = "joint_trajectory"

    def __init__(
        self,
        bus: TopicBus,
        controller_name: str = "joint_trajectory_controller",
        goals: Sequence[Sequence[float] | Mapping[str, Sequence[float]]] = DEFAULT_GOALS,
        joints: Sequence[str] = ("joint1", "joint2"),
        wait_sec_between_publish: float = 6.0,
        goal_time_from_start: float = 3.0,
        repeat_the_same_goal: int = 1,
        node_name: str = TRAJECTORY_EXECUTABLE,
        check_starting_point: bool = False,
        starting_point_limits: Mapping[str, Sequence[float]] | None = None,
        namespace: str = "/",
    ) -> None:
        bad = [g for g in goals if not _fits(g, len(joints))]
        if bad:
            raise ParameterError(node_name, "goal_names", f"goals {bad} do not have one value per joint {list(joints)}")
        if not isinstance(goal_time_from_start, int | float) or not goal_time_from_start > 0:
            raise ParameterError(node_name, "goal_time_from_start", f"must be > 0 [s], got {goal_time_from_start}")
        self.joints = list(joints)
        super().__init__(bus, node_name, controller_name, goals, wait_sec_between_publish, repeat_the_same_goal,
                         namespace=namespace)
        self.goal_time_from_start = float(goal_time_from_start)
        self.check_starting_point = bool(check_starting_point)
        limits = dict(starting_point_limits or {})
        self.starting_point_limits: dict[str, list[float]] = {}
        for joint in self.joints:
            pair = limits.get(joint, [-_TWO_PI, _TWO_PI])
            if not isinstance(pair, Sequence) or len(pair) != 2:
                raise ParameterError(node_name, f"starting_point_limits.{joint}",
                                     f"must be [lower, upper] in [rad], got {pair!r}")
            self.starting_point_limits[joint] = [float(pair[0]), float(pair[1])]
        #: Whether a due goal may go out: True without the check, else set by the first joint_states message.
        self.starting_point_ok = not self.check_starting_point
        self.joint_state_msg_received = False
        if self.check_starting_point:
            self.node.create_subscription(JointState, "joint_states", self._on_joint_states)

    @staticmethod
    def _goal(goal: Any) -> Any:
        if isinstance(goal, Mapping):
            return {k: [float(v) for v in goal[k]] for k in _POINT_FIELDS if k in goal}
        return [float(v) for v in goal]

    def _on_joint_states(self, msg: JointState) -> None:
        if self.joint_state_msg_received:
            return
        self.joint_state_msg_received = True
        outside = [n for n, p in zip(msg.name, msg.position)  # noqa: B905 - a short message checks what it has
                   if n in self.starting_point_limits
                   and not self.starting_point_limits[n][0] <= p <= self.starting_point_limits[n][1]]
        for name in outside:
            _log.warning("%s: starting point limits exceeded for joint %s", self.node.get_name(), name)
        self.starting_point_ok = not outside

    def ready(self) -> bool:
        """True once the starting point is known to be within limits (always without the check)."""
        if self.starting_point_ok:
            return True
        if not self.joint_state_msg_received:
            _log.warning("%s: start configuration could not be checked: no message on %s yet", self.node.get_name(),
                         self.node.resolve_topic_name("joint_states"))
        else:
            _log.warning("%s: start configuration is not within starting_point_limits; not publishing",
                         self.node.get_name())
        return False

    def make_message(self, goal: Any, time: float) -> JointTrajectory:
        """A trajectory with one point at ``goal_time_from_start``, starting on receipt (stamp 0)."""
        fields = goal if isinstance(goal, Mapping) else {"positions": goal}
        point = JointTrajectoryPoint(**{k: list(v) for k, v in fields.items()}, time_from_start=self.goal_time_from_start)
        return JointTrajectory(Header(stamp=0.0), list(self.joints), [point])


def _fits(goal: Any, n: int) -> bool:
    if isinstance(goal, Mapping):
        return any(k in goal for k in _POINT_FIELDS) and all(len(goal[k]) == n for k in _POINT_FIELDS if k in goal)
    return len(goal) == n


def default_config_path() -> Path:
    """``descriptions/rrbot/config/test_goal_publishers_config.yaml``."""
    from rrbot_workshop.description import descriptions_root

    return descriptions_root() / "rrbot" / "config" / "test_goal_publishers_config.yaml"


# ----------------------------------------------------------------------------- parameters as Jazzy reads them


def _number_list(node: str, name: str, value: Any) -> list[float]:
    if not isinstance(value, list) or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise ParameterError(node, name, f"must be a list of numbers, got {value!r}")
    return [float(v) for v in value]


def _number(node: str, name: str, value: Any) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value) or value <= 0:
        raise ParameterError(node, name, f"must be a number > 0, got {value!r}")
    return float(value)


def _string_list(node: str, name: str, value: Any) -> list[str]:
    if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
        raise ParameterError(node, name, f"must be a non-empty list of names, got {value!r}")
    return list(value)


def _refuse_unknown(node: str, params: Mapping[str, Any], known: Sequence[str], executable: str) -> None:
    for key in params:
        if key not in known and key != "use_sim_time":
            raise ParameterError(
                node, str(key), f"is not a parameter of {executable} (valid: {', '.join(known)}, use_sim_time; "
                "a goal must be listed in goal_names)")


def _forward(bus: TopicBus, node: str, p: Mapping[str, Any], namespace: str) -> ForwardCommandGoalPublisher:
    names = _string_list(node, "goal_names", p.get("goal_names", ["pos1", "pos2"]))
    _refuse_unknown(node, p, ["publish_topic", "wait_sec_between_publish", "goal_names", "controller_name", *names],
                    FORWARD_EXECUTABLE)
    topic = p.get("publish_topic", "/position_commands")
    if not isinstance(topic, str) or not topic:
        raise ParameterError(node, "publish_topic", f"must be a topic name such as '/forward_position_controller/"
                                                    f"commands', got {topic!r}")
    if "controller_name" in p:
        _log.warning(
            "%s: parameter 'controller_name' is Humble's; Jazzy's %s ignores it and publishes on publish_topic "
            "('%s')%s", node, FORWARD_EXECUTABLE, topic,
            "" if "publish_topic" in p else
            f"; to reach the controller set publish_topic: '/{p['controller_name']}/commands'")
    goals = []
    for name in names:
        if name not in p or p[name] in (None, []):
            raise ParameterError(node, name, f"is named in goal_names but is not given as '{name}: [..]'")
        goals.append(_number_list(node, name, p[name]))
    return ForwardCommandGoalPublisher(
        bus, "", goals, _number(node, "wait_sec_between_publish", p.get("wait_sec_between_publish", 5)),
        node_name=node, publish_topic=topic, namespace=namespace)


def _trajectory(bus: TopicBus, node: str, p: Mapping[str, Any], namespace: str) -> JointTrajectoryGoalPublisher:
    names = _string_list(node, "goal_names", p.get("goal_names", ["pos1", "pos2"]))
    known = ["controller_name", "wait_sec_between_publish", "goal_names", "joints", "check_starting_point",
             "starting_point_limits", "goal_time_from_start", "repeat_the_same_goal", *names]
    _refuse_unknown(node, p, known, TRAJECTORY_EXECUTABLE)
    if "joints" not in p:
        raise ParameterError(node, "joints", "is not set: list the joints of the trajectories")
    joints = _string_list(node, "joints", p["joints"])
    controller = p.get("controller_name", "position_trajectory_controller")
    if not isinstance(controller, str) or not controller:
        raise ParameterError(node, "controller_name", f"must be the trajectory controller's name, got {controller!r}")
    check = p.get("check_starting_point", False)
    if not isinstance(check, bool):
        raise ParameterError(node, "check_starting_point", f"must be true or false, got {check!r}")
    limits_given = p.get("starting_point_limits", {}) or {}
    if not isinstance(limits_given, Mapping):
        raise ParameterError(node, "starting_point_limits", "must map each joint to [lower, upper]")
    # Jazzy declares starting_point_limits.<joint> only with check_starting_point, and only for the listed joints:
    # other entries are never read (the demos' files carry some), so they are ignored here too.
    limits: dict[str, list[float]] = {}
    if check:
        ignored = [j for j in limits_given if j not in joints]
        if ignored:
            _log.info("%s: starting_point_limits of %s ignored: not in 'joints' %s", node, ignored, joints)
        limits = {j: _number_list(node, f"starting_point_limits.{j}", v) for j, v in limits_given.items() if j in joints}
    goals: list[Any] = []
    for name in names:
        spec = p.get(name)
        if spec is None or isinstance(spec, list):
            spec = {}
        if not isinstance(spec, Mapping):
            raise ParameterError(node, name, f"must be a mapping such as '{name}: {{positions: [..]}}', got {spec!r}")
        for key in spec:
            if key not in _POINT_FIELDS:
                raise ParameterError(node, f"{name}.{key}", f"is not a point field (valid: {', '.join(_POINT_FIELDS)})")
        fields = {k: _number_list(node, f"{name}.{k}", spec[k]) for k in _POINT_FIELDS if k in spec}
        fields = {k: v for k, v in fields.items() if len(v) == len(joints)}  # Jazzy uses a field only if it fits
        if fields:
            goals.append(fields["positions"] if list(fields) == ["positions"] else fields)
        else:
            _log.warning("%s: goal '%s' is not used: give '%s: {positions: [..]}' (or velocities, accelerations, "
                         "effort) with one value per joint of %s", node, name, name, joints)
    if not goals:
        raise ParameterError(node, "goal_names", f"no valid goal among {names}: each needs '<name>: {{positions: "
                                                 f"[..]}}' with one value per joint of {joints}")
    repeat = p.get("repeat_the_same_goal", 1)
    if not isinstance(repeat, int) or isinstance(repeat, bool):
        raise ParameterError(node, "repeat_the_same_goal", f"must be an integer >= 1, got {repeat!r}")
    return JointTrajectoryGoalPublisher(
        bus, controller, goals, joints, _number(node, "wait_sec_between_publish", p.get("wait_sec_between_publish", 6)),
        _number(node, "goal_time_from_start", p.get("goal_time_from_start", JAZZY_GOAL_TIME_FROM_START)), repeat,
        node_name=node, check_starting_point=check, starting_point_limits=limits, namespace=namespace)


def _kind(node: str, params: Mapping[str, Any]) -> str:
    if node == FORWARD_EXECUTABLE or "publish_topic" in params:
        return FORWARD_EXECUTABLE
    if node in (TRAJECTORY_EXECUTABLE, "publisher_position_trajectory_controller") or "joints" in params \
            or "trajectory" in node:
        return TRAJECTORY_EXECUTABLE
    return FORWARD_EXECUTABLE


def goal_publisher_from_parameters(
    bus: TopicBus, node_name: str, params: Mapping[str, Any], executable: str | None = None, namespace: str = "/",
) -> GoalPublisher:
    """One goal publisher from its ``ros__parameters``, read as Jazzy's node reads them.

    Args:
        bus: The running system's topic bus.
        node_name: Name of the node (the key of its section in the parameter file).
        params: Its parameters (the content of ``ros__parameters``).
        executable: ``publisher_forward_position_controller`` or ``publisher_joint_trajectory_controller``;
            None guesses from the node name and parameters (``publish_topic`` -> forward, ``joints`` -> trajectory).
        namespace: Namespace of the node.

    Raises:
        ParameterError: Naming the parameter that is unknown, missing or malformed.
    """
    kind = executable or _kind(node_name, params)
    if kind == FORWARD_EXECUTABLE:
        return _forward(bus, node_name, params, namespace)
    if kind == TRAJECTORY_EXECUTABLE:
        return _trajectory(bus, node_name, params, namespace)
    raise ParameterError(node_name, "executable", f"'{kind}' is not a goal publisher (valid: {FORWARD_EXECUTABLE}, "
                                                  f"{TRAJECTORY_EXECUTABLE})")


def load_goal_publishers(
    bus: TopicBus, path: str | Path | None = None, executables: Mapping[str, str] | None = None, namespace: str = "/",
) -> dict[str, GoalPublisher]:
    """Build the publishers of a goal publisher parameter file (ROS layout, one section per node).

    A section key may carry the node's namespace (``/rrbot_1/publisher_forward_position_controller``); the
    publisher is then returned under that full key and its relative topics resolve in ``/rrbot_1``. ``/**``
    parameters apply to every node (a node's own section wins).

    Args:
        bus: The running system's topic bus.
        path: The YAML file; default :func:`default_config_path`.
        executables: Section key -> executable, for nodes renamed in a launch file; otherwise guessed (see
            :func:`goal_publisher_from_parameters`).
        namespace: Namespace of the nodes whose key has none (a launch file's ``namespace=``).

    Raises:
        ParameterError: If the file is missing, not in the ``<node>: ros__parameters:`` layout, or a parameter is
            unknown, missing or malformed (the message names it).
    """
    source = Path(path) if path is not None else default_config_path()
    try:
        data = yaml.safe_load(source.read_text()) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise ParameterError("goal publishers", str(source), f"cannot be read: {exc}") from exc
    if not isinstance(data, Mapping):
        raise ParameterError("goal publishers", str(source), "must map node names to 'ros__parameters:'")
    common: Mapping[str, Any] = {}
    for key in ("/**", "**"):
        body = data.get(key)
        if isinstance(body, Mapping) and isinstance(body.get("ros__parameters"), Mapping):
            common = body["ros__parameters"]
    out: dict[str, GoalPublisher] = {}
    for key, body in data.items():
        if str(key) in ("/**", "**"):
            continue
        if not isinstance(body, Mapping) or not isinstance(body.get("ros__parameters"), Mapping):
            raise ParameterError(str(key), "ros__parameters", f"missing in {source}")
        key_namespace, _, node = str(key).rpartition("/")
        params = {**common, **body["ros__parameters"]}
        kind = (executables or {}).get(str(key))
        out[str(key)] = goal_publisher_from_parameters(bus, node, params, kind, key_namespace or namespace)
    return out
