"""An in-process topic bus standing in for ROS 2 topics and services.

Publishing never runs a subscriber's callback on the spot: messages are queued and delivered by
:meth:`TopicBus.deliver`, which the controller manager calls between control cycles. That is the
separation ros2_control keeps between the real-time loop and the executor that runs subscriptions.
Every topic keeps its latest message and a bounded history, so a notebook can echo or plot it.
"""

from __future__ import annotations

import collections
import difflib
import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.exceptions import MessageError
from rrbot_workshop.middleware.names import topic_name_problem
from rrbot_workshop.msgs import message_problem, ros_type_name

__all__ = ["TopicBus", "Node", "Publisher", "Subscription", "Service", "resolve_name", "node_owner"]

_log = logging.getLogger(__name__)


def resolve_name(name: str, node_name: str = "", namespace: str = "/") -> str:
    """Expand a topic name as ROS 2 does.

    ``"~/commands"`` on node ``fwd`` becomes ``"/fwd/commands"``; a relative ``"cmd"`` becomes
    ``"/<namespace>/cmd"``; an absolute ``"/x"`` stays.

    Raises:
        MessageError: If the name is empty or uses ``~`` without a node name.
    """
    if not name:
        raise MessageError("topic name is empty")
    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    if name.startswith("~"):
        if not node_name:
            raise MessageError(f"topic '{name}' uses '~' but there is no node name to expand it")
        rest = name[1:].lstrip("/")
        return f"{ns}/{node_name}" + (f"/{rest}" if rest else "")
    if name.startswith("/"):
        return name
    return f"{ns}/{name}"


def node_owner(name: str, namespace: str = "/") -> str:
    """How the bus names a node's endpoints: ``name`` in the root namespace, ``/<namespace>/<name>`` in another."""
    ns = namespace.strip("/")
    return f"/{ns}/{name}" if ns else name


@dataclass
class _Sub:
    topic: str
    msg_type: type | None
    callback: Callable[[Any], None]
    owner: str


class Subscription:
    """Handle to a subscription; :meth:`destroy` stops delivery."""

    def __init__(self, bus: TopicBus, sub: _Sub) -> None:
        self._bus = bus
        self._sub = sub

    @property
    def topic_name(self) -> str:
        """Fully resolved topic name."""
        return self._sub.topic

    def destroy(self) -> None:
        """Stop receiving messages."""
        self._bus._remove_subscription(self._sub)


class _Lazy(list):  # type: ignore[type-arg]
    """A message built on first read: the cycle stores the numbers, whoever reads the topic builds the message.

    It is ``[build, *args]`` until read and ``[None, message]`` after. A list of its own rather than an object holding
    a tuple: one object per kept message instead of two, made without running any Python code. Python's collector
    walks every object the histories keep (in a 1 kHz simulation, a tenth of the time went there), so each object a
    cycle leaves behind counts.
    """

    __slots__ = ()

    def get(self) -> Any:
        build = self[0]
        if build is None:
            return self[1]
        msg = build(*self[1:])
        self[:] = (None, msg)
        return msg


def _resolved(item: Any) -> Any:
    return item.get() if type(item) is _Lazy else item


class Publisher:
    """Publishes messages of one type on one topic."""

    def __init__(self, bus: TopicBus, topic: str, msg_type: type | None, owner: str) -> None:
        self._bus = bus
        self.topic_name = topic
        self.msg_type = msg_type
        self.owner = owner

    def publish(self, msg: Any) -> None:
        """Queue ``msg`` for delivery (it becomes the topic's latest message at once).

        Raises:
            MessageError: If ``msg`` is not of the publisher's type.
        """
        if self.msg_type is not None and not isinstance(msg, self.msg_type):
            raise MessageError(
                f"publisher on '{self.topic_name}' sends {self.msg_type.__name__}, got {type(msg).__name__}"
            )
        self._bus._publish(self.topic_name, msg)

    def publish_lazy(self, build: Callable[..., Any], *args: Any) -> None:
        """Publish the message ``build(*args)`` returns, building it only when someone reads it.

        Subscribers get the built message at once (they read every message); ``latest``, ``history`` and the
        recorders build it when they are asked. The message is the same as with :meth:`publish`; ``build`` and
        ``args`` must only hold values of this moment (the cycle's numbers, lists nobody changes afterwards), never
        live handles. Passing the values as ``args`` spares the cycle a closure.
        """
        bus, topic = self._bus, self.topic_name
        if bus._subs.get(topic):  # subscribers read every message: build it now
            bus._publish(topic, build(*args))
            return
        bus._keep(topic, _Lazy((build, *args)))

    def get_subscription_count(self) -> int:
        """Number of subscriptions on this topic."""
        return self._bus.subscription_count(self.topic_name)


class Service:
    """A service server: ``callback(request) -> response``."""

    def __init__(self, name: str, callback: Callable[[Any], Any], request_type: type | None) -> None:
        self.name = name
        self.callback = callback
        self.request_type = request_type


class TopicBus:
    """Topics, latest messages, histories and services of one running system.

    Args:
        history_depth: Messages kept per topic for :meth:`history`.
    """

    def __init__(self, history_depth: int = 1000) -> None:
        self._subs: dict[str, list[_Sub]] = collections.defaultdict(list)
        self._types: dict[str, type] = {}
        self._queue: collections.deque[tuple[str, Any]] = collections.deque()
        self._latest: dict[str, Any] = {}
        self._history: dict[str, collections.deque[Any]] = {}
        self._history_depth = history_depth
        self._services: dict[str, Service] = {}
        self._publishers: dict[str, list[str]] = collections.defaultdict(list)
        self._warned_no_subscriber: set[str] = set()
        self._remaps: dict[str, list[tuple[str, str]]] = {}

    # ----------------------------------------------------------------- remapping
    def set_remaps(self, owner: str, rules: list[tuple[str, str]]) -> None:
        """Remap rules (``from``, ``to``) for the node ``owner`` (``-r from:=to`` of its ``--ros-args``), applied
        to the names it resolves from now on; an empty list removes them."""
        if rules:
            self._remaps[owner] = list(rules)
        else:
            self._remaps.pop(owner, None)

    def remaps(self, owner: str) -> list[tuple[str, str]]:
        """The remap rules of node ``owner``."""
        return list(self._remaps.get(owner, ()))

    # ----------------------------------------------------------------- registration
    def _check_type(self, topic: str, msg_type: type | None) -> None:
        if msg_type is None:
            return
        known = self._types.get(topic)
        if known is not None and known is not msg_type:
            raise MessageError(
                f"topic '{topic}' carries {known.__name__}; cannot use it with {msg_type.__name__}"
            )
        self._types[topic] = msg_type

    def create_publisher(self, msg_type: type | None, topic: str, owner: str = "") -> Publisher:
        """Create a publisher on an absolute topic name."""
        self._check_type(topic, msg_type)
        self._publishers[topic].append(owner)
        return Publisher(self, topic, msg_type, owner)

    def create_subscription(
        self, msg_type: type | None, topic: str, callback: Callable[[Any], None], owner: str = ""
    ) -> Subscription:
        """Subscribe ``callback`` to an absolute topic name."""
        self._check_type(topic, msg_type)
        sub = _Sub(topic, msg_type, callback, owner)
        self._subs[topic].append(sub)
        return Subscription(self, sub)

    def _remove_subscription(self, sub: _Sub) -> None:
        subs = self._subs.get(sub.topic, [])
        if sub in subs:
            subs.remove(sub)

    def remove_owner(self, owner: str) -> None:
        """Drop every subscription, publisher and service registered by ``owner`` (a node being destroyed)."""
        for topic, subs in self._subs.items():
            self._subs[topic] = [s for s in subs if s.owner != owner]
        for topic, owners in self._publishers.items():
            self._publishers[topic] = [o for o in owners if o != owner]
        for name in [n for n, s in self._services.items() if getattr(s, "owner", "") == owner]:
            del self._services[name]

    def subscription_count(self, topic: str) -> int:
        """Number of subscriptions on ``topic``."""
        return len(self._subs.get(topic, []))

    def publisher_count(self, topic: str) -> int:
        """Number of publishers (of nodes) on ``topic``; publishing from outside a node creates none."""
        return len(self._publishers.get(topic, []))

    def publisher_owners(self, topic: str) -> list[str]:
        """Node names of the publishers on ``topic``, in creation order."""
        return list(self._publishers.get(topic, []))

    def subscription_owners(self, topic: str) -> list[str]:
        """Node names of the subscriptions on ``topic``, in creation order."""
        return [s.owner for s in self._subs.get(topic, [])]

    def topic_type_name(self, topic: str) -> str | None:
        """ROS type name of ``topic`` (``"sensor_msgs/msg/JointState"``), or None if the topic is unknown."""
        return dict(self.topic_names_and_types()).get(topic)

    def similar_topics(self, topic: str, *, subscribed_only: bool = False) -> list[str]:
        """Known topic names close to ``topic`` (a misspelling), closest first."""
        if subscribed_only:
            names = [t for t, subs in self._subs.items() if subs]
        else:
            names = [t for t, _ in self.topic_names_and_types()]
        return difflib.get_close_matches(topic, [n for n in names if n != topic], n=3, cutoff=0.6)

    # ----------------------------------------------------------------- traffic
    def _keep(self, topic: str, item: Any) -> None:
        """Make ``item`` (a message, or a lazy one) the topic's latest and append it to its history."""
        self._latest[topic] = item
        hist = self._history.get(topic)
        if hist is None:
            hist = self._history[topic] = collections.deque(maxlen=self._history_depth)
        hist.append(item)

    def _publish(self, topic: str, msg: Any) -> None:
        self._keep(topic, msg)
        if self._subs.get(topic):
            self._queue.append((topic, msg))

    def publish(self, topic: str, msg: Any) -> None:
        """Publish ``msg`` on ``topic`` from outside any node (like ``ros2 topic pub``).

        The first message on a topic that nobody subscribes to logs a warning, naming the subscribed topic
        with the closest name (``no subscriber on '/forward_position_controler/commands'; did you mean
        '/forward_position_controller/commands'?``).

        Raises:
            MessageError: If the topic is not a valid ROS topic name, ``msg`` is None, the topic is known to carry
                another message type, or a field of ``msg`` is of a type its ROS message would refuse (None, a string
                for a number, ...: :func:`~rrbot_workshop.msgs.message_problem`).
        """
        problem = topic_name_problem(topic)
        if problem:
            raise MessageError(f"cannot publish on {topic!r}: it is not a valid ROS topic name ({problem}); a topic "
                               "name is parts of letters, digits and underscores separated by '/', e.g. "
                               "'/forward_position_controller/commands'")
        if msg is None:
            raise MessageError(f"cannot publish None on '{topic}'; give a message object (e.g. Float64MultiArray(...))")
        known = self._types.get(topic)
        if known is not None and not isinstance(msg, known):
            raise MessageError(f"topic '{topic}' carries {known.__name__}, got {type(msg).__name__}")
        field_problem = message_problem(msg)
        if field_problem:
            raise MessageError(f"cannot publish the {type(msg).__name__} on '{topic}': its {field_problem}")
        if not self._subs.get(topic) and topic not in self._warned_no_subscriber:
            self._warned_no_subscriber.add(topic)
            close = self.similar_topics(topic, subscribed_only=True)
            hint = f"; did you mean '{close[0]}'?" if close else " (the message is kept as its latest; nobody receives it)"
            _log.warning("no subscriber on '%s'%s", topic, hint)
        self._publish(topic, msg)

    def deliver(self) -> int:
        """Run subscriber callbacks for every queued message, oldest first.

        A callback that raises is logged with its traceback and does not stop delivery.

        Returns:
            Number of callbacks run.
        """
        count = 0
        pending = len(self._queue)
        for _ in range(pending):
            topic, msg = self._queue.popleft()
            for sub in list(self._subs.get(topic, [])):
                try:
                    sub.callback(msg)
                except Exception as exc:  # noqa: BLE001 - a subscriber's bug must not stop the bus
                    _report_callback_error(topic, sub, msg, exc)
                count += 1
        return count

    def latest(self, topic: str) -> Any:
        """Last message published on ``topic``, or None."""
        return _resolved(self._latest.get(topic))

    def history(self, topic: str) -> list[Any]:
        """Messages published on ``topic`` (at most ``history_depth``), oldest first."""
        return [_resolved(item) for item in self._history.get(topic, ())]

    def clear_history(self, topic: str | None = None) -> None:
        """Forget the history of one topic, or of all."""
        if topic is None:
            self._history.clear()
        else:
            self._history.pop(topic, None)

    def topic_names_and_types(self) -> list[tuple[str, str]]:
        """Topics with a publisher, a subscription or a message, with their ROS type names, sorted (``ros2 topic list
        -t``); the topics of an unloaded controller are gone."""
        endpoints = {t for t, s in self._subs.items() if s} | {t for t, p in self._publishers.items() if p}
        topics = endpoints | set(self._latest)

        def type_name(topic: str) -> str:
            if topic in self._types:
                return ros_type_name(self._types[topic])
            if topic in self._latest:  # published from outside any node: the message tells its type
                return ros_type_name(type(_resolved(self._latest[topic])))
            return "?"

        return sorted((t, type_name(t)) for t in topics)

    # ----------------------------------------------------------------- services
    def create_service(
        self, name: str, callback: Callable[[Any], Any], request_type: type | None = None, owner: str = ""
    ) -> Service:
        """Offer a service under an absolute name.

        A node that creates a service it already offers replaces it, as a C++ controller's ``service_ =
        create_service(...)`` in ``on_configure`` does when it is configured again after a cleanup (the old server
        goes with the pointer it replaced).

        Raises:
            MessageError: If another node (or no node) offers a service of that name.
        """
        existing = self._services.get(name)
        if existing is not None and not (owner and getattr(existing, "owner", "") == owner):
            raise MessageError(f"service '{name}' already exists")
        srv = Service(name, callback, request_type)
        srv.owner = owner  # type: ignore[attr-defined]
        self._services[name] = srv
        return srv

    def call_service(self, name: str, request: Any) -> Any:
        """Call a service and return its response.

        Raises:
            MessageError: If no such service exists or the request has the wrong type.
        """
        srv = self._services.get(name)
        if srv is None:
            raise MessageError(f"no service '{name}' (available: {', '.join(sorted(self._services)) or 'none'})")
        if srv.request_type is not None and not isinstance(request, srv.request_type):
            raise MessageError(
                f"service '{name}' takes {srv.request_type.__name__}, got {type(request).__name__}"
            )
        return srv.callback(request)

    def service_names(self) -> list[str]:
        """Names of all services, sorted."""
        return sorted(self._services)


class Node:
    """What a controller (or test publisher) uses to talk: name, topics, services, clock.

    Args:
        name: Node name (a controller's name).
        bus: The system's topic bus.
        namespace: Node namespace, ``"/"`` by default.
        clock: Callable returning the current time in [s].
    """

    def __init__(
        self, name: str, bus: TopicBus, namespace: str = "/", clock: Callable[[], float] | None = None
    ) -> None:
        self._name = name
        self._namespace = namespace
        self._bus = bus
        self._clock = clock or (lambda: 0.0)
        #: What the bus records as this node's endpoints: the name in the root namespace (as before namespaces),
        #: the fully qualified name in another, so equal names in two namespaces stay apart.
        self.owner = node_owner(name, namespace)

    def get_name(self) -> str:
        """Node name."""
        return self._name

    def get_namespace(self) -> str:
        """Node namespace."""
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        """``/<namespace>/<name>``."""
        return resolve_name("~", self._name, self._namespace)

    @property
    def bus(self) -> TopicBus:
        """The topic bus this node is attached to."""
        return self._bus

    def now(self) -> float:
        """Current time in [s] (simulated by default)."""
        return self._clock()

    def resolve_topic_name(self, topic: str) -> str:
        """Expand ``~`` and relative names against this node, then apply its remap rules as rcl does: a rule
        whose ``from``, expanded against the node, equals the expanded name gives its ``to``, expanded too."""
        expanded = resolve_name(topic, self._name, self._namespace)
        for match, replacement in self._bus.remaps(self.owner):
            if resolve_name(match, self._name, self._namespace) == expanded:
                return resolve_name(replacement, self._name, self._namespace)
        return expanded

    def create_publisher(self, msg_type: type | None, topic: str, qos: Any = 10) -> Publisher:
        """Create a publisher (argument order as in rclpy)."""
        return self._bus.create_publisher(msg_type, self.resolve_topic_name(topic), owner=self.owner)

    def create_subscription(
        self, msg_type: type | None, topic: str, callback: Callable[[Any], None], qos: Any = 10
    ) -> Subscription:
        """Create a subscription (argument order as in rclpy)."""
        return self._bus.create_subscription(msg_type, self.resolve_topic_name(topic), callback, owner=self.owner)

    def create_service(self, srv_type: type | None, name: str, callback: Callable[[Any], Any]) -> Service:
        """Create a service; ``srv_type`` is the request dataclass (e.g. ``SetBoolRequest``)."""
        return self._bus.create_service(self.resolve_topic_name(name), callback, srv_type, owner=self.owner)

    def destroy(self) -> None:
        """Remove this node's publishers, subscriptions and services from the bus."""
        self._bus.remove_owner(self.owner)


def _report_callback_error(topic: str, sub: Any, msg: Any, exc: Exception) -> None:
    """A subscriber raised. The library's own callbacks are handed malformed messages (a field of the wrong type, a
    None): one line says the message was rejected and why. Anyone else's callback gets its traceback, to debug it."""
    owner = sub.owner or "anonymous"
    module = getattr(sub.callback, "__module__", "") or ""
    if module.startswith("rrbot_workshop."):
        _log.error("'%s' rejected a %s on '%s': %s: %s", owner, type(msg).__name__, topic, type(exc).__name__, exc)
    else:
        _log.error("subscriber of '%s' (%s) raised", topic, owner, exc_info=exc)
