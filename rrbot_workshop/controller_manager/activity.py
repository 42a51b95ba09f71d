"""``/controller_manager/activity``: the states of every controller and hardware component, each time one changes.

Jazzy's controller manager publishes ``controller_manager_msgs/msg/ControllerManagerActivity`` on ``~/activity``
whenever a controller or a hardware component changes lifecycle state (a load, a switch, a failure in the loop), with
transient-local durability so a late subscriber gets the last message. Here the bus keeps the latest message of the
topic (``bus.latest``), which serves the late subscriber, and a message is published only when the states differ
from the last one sent.
"""

from __future__ import annotations

from rrbot_workshop.controller_manager.context import ManagerContext
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import ControllerManagerActivity, Header, LifecycleState, NamedLifecycleState

__all__ = ["ACTIVITY_TOPIC", "ActivityReporter"]

#: The topic, as ``~/activity`` of the node ``/controller_manager``.
ACTIVITY_TOPIC = "/controller_manager/activity"

_Snapshot = tuple[tuple[tuple[str, State], ...], tuple[tuple[str, State], ...]]


def _named(items: tuple[tuple[str, State], ...]) -> list[NamedLifecycleState]:
    return [NamedLifecycleState(name, LifecycleState(state.id, state.label)) for name, state in items]


class ActivityReporter:
    """Publishes the manager's activity message when a state changed since the last one.

    Args:
        cm: The controller manager whose controllers and hardware components are reported.
    """

    def __init__(self, cm: ManagerContext) -> None:
        self._cm = cm
        self._pub = cm.bus.create_publisher(ControllerManagerActivity, ACTIVITY_TOPIC, owner="controller_manager")
        self._last: _Snapshot | None = None

    def _snapshot(self) -> _Snapshot:
        rm = self._cm.resource_manager
        controllers = tuple((name, spec.state) for name, spec in self._cm.controllers.items())
        hardware = tuple((name, rm.get_component(name).get_lifecycle_state()) for name in rm.component_names())
        return controllers, hardware

    def check(self) -> bool:
        """Publish if any state changed; returns whether a message was published."""
        snapshot = self._snapshot()
        if snapshot == self._last:
            return False
        self._last = snapshot
        self._pub.publish(ControllerManagerActivity(
            header=Header(stamp=self._cm.clock.now()),
            controllers=_named(snapshot[0]),
            hardware_components=_named(snapshot[1]),
        ))
        return True
