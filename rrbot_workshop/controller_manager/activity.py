"""``/controller_manager/activity``: the states of every controller and hardware component, each time one changes.

Jazzy's controller manager publishes ``controller_manager_msgs/msg/ControllerManagerActivity`` on ``~/activity``
whenever a controller or a hardware component changes lifecycle state (a load, a switch, a failure in the loop), with
transient-local durability so a late subscriber gets the last message. Here the bus keeps the latest message of the
topic (``bus.latest``), which serves the late subscriber, and a message is published only when the states differ
from the last one sent.
"""

from __future__ import annotations

import functools
import operator
from collections.abc import Callable, Mapping
from typing import Any, Protocol, TypeVar

from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.clock import Clock
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, State
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import ControllerManagerActivity, Header, LifecycleState, NamedLifecycleState

__all__ = ["ACTIVITY_TOPIC", "ActivityReporter", "ActivitySink", "reports_activity"]

#: The topic, as ``~/activity`` of the node ``/controller_manager``.
ACTIVITY_TOPIC = "/controller_manager/activity"

#: A record's lifecycle state, read in C (a snapshot of a thousand controllers is taken at each request).
_STATE_OF_SPEC = operator.attrgetter("controller._state")

_Names = tuple[tuple[str, ...], tuple[State, ...]]
_Snapshot = tuple[_Names, _Names]


def _named(items: _Names) -> list[NamedLifecycleState]:
    names, states = items
    return [NamedLifecycleState(name, LifecycleState(state.id, state.label))
            for name, state in zip(names, states, strict=True)]


class ActivitySink(Protocol):
    """Told after every request that may have changed a state (the ``~/activity`` publisher)."""

    def check(self) -> bool: ...


_F = TypeVar("_F", bound=Callable[..., Any])


def reports_activity(method: _F) -> _F:
    """Decorates a method of an object that has an ``activity`` sink: after the call, successful or not, the sink is
    told (it publishes the activity message if a state changed)."""

    @functools.wraps(method)
    def wrapper(self: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        finally:
            self.activity.check()

    return wrapper  # type: ignore[return-value]


class ActivityReporter:
    """Publishes the manager's activity message when a state changed since the last one.

    Args:
        bus: The bus the message is published on.
        clock: The stamp of each message.
        controllers: The manager's loaded controllers by name (the live mapping), reported in load order.
        rm: The resource manager whose hardware components are reported.
        topic: Where it publishes: ``<manager's fully qualified name>/activity``.
        owner: The manager's node on the bus.
    """

    def __init__(self, bus: TopicBus, clock: Clock, controllers: Mapping[str, ControllerSpec],
                 rm: ResourceManager, topic: str = ACTIVITY_TOPIC, owner: str = "controller_manager") -> None:
        self._clock = clock
        self._controllers = controllers
        self._rm = rm
        self.topic = topic
        self._pub = bus.create_publisher(ControllerManagerActivity, topic, owner=owner)
        self._last: _Snapshot | None = None
        self._last_key: tuple[Any, ...] | None = None

    def _snapshot(self) -> _Snapshot:
        rm = self._rm
        specs = self._controllers
        # two flat tuples (names, states), not a pair per controller: nothing for the garbage collector to track
        controllers = (tuple(specs), tuple(map(_STATE_OF_SPEC, specs.values())))
        names = tuple(rm.component_names())
        hardware = (names, tuple(rm.get_component(name).get_lifecycle_state() for name in names))
        return controllers, hardware

    def check(self) -> bool:
        """Publish if any state changed; returns whether a message was published.

        Every state change moves ``TRANSITIONS`` and every load or unload changes the names: when neither moved,
        nothing is looked at (a manager with many controllers answers each request without walking them all twice).
        The message is built when someone reads the topic.
        """
        key = (TRANSITIONS.value, tuple(self._controllers), tuple(self._rm.component_names()))
        if key == self._last_key:
            return False
        self._last_key = key
        snapshot = self._snapshot()
        if snapshot == self._last:
            return False
        self._last = snapshot
        self._pub.publish_lazy(_activity_message, self._clock.now(), snapshot)
        return True


def _activity_message(stamp: float, snapshot: _Snapshot) -> ControllerManagerActivity:
    return ControllerManagerActivity(header=Header(stamp=stamp), controllers=_named(snapshot[0]),
                                     hardware_components=_named(snapshot[1]))
