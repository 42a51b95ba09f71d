"""The hardware side of a control cycle: ``read`` and ``write`` on every component, and failures.

Components are called in cycle order (actuators, sensors, systems). One with ``rw_rate`` below the
manager's rate is called only on the cycles :func:`~rrbot_workshop.middleware.clock.rate_due` picks, with the
time since its last call as its period. A call that returns ERROR or raises puts the component
through ``error()`` and makes its interfaces unavailable (a ``<group>`` fails together); DEACTIVATE
from ``write`` makes it INACTIVE (from ``read`` it counts as an error). The others keep running, and
the names of the components taken out are reported.
"""

from __future__ import annotations

import logging
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from rrbot_workshop.hardware_interface.resource_loading import ComponentEntry
from rrbot_workshop.hardware_interface.resource_storage import InterfaceStorage
from rrbot_workshop.middleware.clock import rate_due
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, ReturnType, State

__all__ = ["HardwareReadWriteStatus", "HardwareCycle"]

# The resource manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.hardware_interface.resource_manager")


@dataclass
class HardwareReadWriteStatus:
    """Result of :meth:`ResourceManager.read` / :meth:`ResourceManager.write`.

    Attributes:
        ok: False if any component failed or deactivated itself.
        failed_hardware_names: Components taken out (error) or deactivated (DEACTIVATE) in this call.
    """

    ok: bool = True
    failed_hardware_names: list[str] = field(default_factory=list)


class HardwareCycle:
    """The hardware side of the control cycle, compiled: who reads and who writes, prepared once.

    The plan lists, in cycle order, the components that ``read`` (inactive or active) and those that ``write``
    (active, not sensors), each with its own rate when it is slower than the manager. It is rebuilt when a lifecycle
    state changes anywhere (:data:`~rrbot_workshop.middleware.lifecycle.TRANSITIONS`) or the components change
    (:meth:`set_entries`); a component with a slower rate stays in it whatever its state, as its time of last call
    moves on in every state. A cycle then only calls the components. A component in the plan is in a state that
    reads (writes), so the cycle calls its implementation's ``read``/``write`` itself (looked up on each call: a method
    replaced at run time is called as it is now); what the implementation raises or any result but OK goes through
    the wrapper's :meth:`~.HardwareComponent.settle` (logged, mapped to ERROR, ``error()``) and then the slow path (the
    rules at the top of this module). A slower component, or any component after a state changed during the cycle,
    is called through its lifecycle wrapper, which checks the state first.

    Args:
        update_rate: The controller manager's rate in [Hz].
        storage: The interface storage whose availability failures change.
        set_component_state: The resource manager's state setter (DEACTIVATE from ``write``).
    """

    def __init__(self, update_rate: int, storage: InterfaceStorage,
                 set_component_state: Callable[[str, State], bool]) -> None:
        self.update_rate = update_rate
        self._storage = storage
        self._set_component_state = set_component_state
        self._entries: Sequence[ComponentEntry] = ()
        self._reads: list[tuple[ComponentEntry, Any, int]] = []
        self._writes: list[tuple[ComponentEntry, Any, int]] = []
        self._built_at = -1

    def set_entries(self, entries: Sequence[ComponentEntry]) -> None:
        """The components, in cycle order (after a load or a rejected load)."""
        self._entries = entries
        self._built_at = -1

    def _build(self) -> None:
        readable, active = (State.INACTIVE, State.ACTIVE), State.ACTIVE
        self._reads, self._writes = [], []
        for entry in self._entries:
            component = entry.component
            state = component.get_lifecycle_state()
            slow = entry.rw_rate if entry.rw_rate < self.update_rate else 0
            # a slower component stays in the plan whatever its state: its last call time moves on as before
            if slow or state in readable:
                self._reads.append((entry, component, slow))
            if slow or (state is active and component.type != "sensor"):
                self._writes.append((entry, component, slow))
        self._built_at = TRANSITIONS.value

    def read(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        """Read every component that is due; None when all returned OK, else what failed."""
        if self._built_at != TRANSITIONS.value:
            self._build()
        return self._run(self._reads, True, time, period)

    def write(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        """Write every component that is due; None when all returned OK, else what failed or deactivated."""
        if self._built_at != TRANSITIONS.value:
            self._build()
        return self._run(self._writes, False, time, period)

    def _run(self, plan: list[tuple[ComponentEntry, Any, int]], reading: bool, time: float,
             period: float) -> HardwareReadWriteStatus | None:
        status = None
        ok = ReturnType.OK
        built = self._built_at
        which = "read" if reading else "write"
        for entry, component, slow in plan:
            own_period = period
            if slow:
                last = entry.last_read if reading else entry.last_write
                if not rate_due(last, time, slow, self.update_rate):
                    continue
                own_period = period if last is None else time - last
            if reading:
                entry.last_read = time
            else:
                entry.last_write = time
            try:  # the wrapper (or settle) catches what the implementation raises; this catches what they raise
                if slow or built != TRANSITIONS.value or component._exported is None:  # noqa: SLF001
                    # a slower component (any state), or a state changed during this cycle: the wrapper decides
                    result = component.read(time, own_period) if reading else component.write(time, own_period)
                else:  # in the plan, so in a state that reads (or writes): call the implementation as it is now
                    impl = component._impl  # noqa: SLF001 - the cycle calls the implementation, as the wrapper would
                    try:
                        result = impl.read(time, own_period) if reading else impl.write(time, own_period)
                    except Exception as exc:  # noqa: BLE001 - learner code may raise anything (handle_exceptions)
                        result = component.settle(which, None, exc)
                    else:
                        if result is not ok:
                            result = component.settle(which, result)
            except Exception:  # noqa: BLE001 - handle_exceptions
                _log.error("%s of hardware '%s' raised:\n%s", which, entry.info.name, traceback.format_exc())
                result = ReturnType.ERROR
            if result is not ok:
                status = self._failed(which, entry, result, status)
        return status

    def _failed(self, which: str, entry: ComponentEntry, result: Any,
                status: HardwareReadWriteStatus | None) -> HardwareReadWriteStatus:
        """The slow path: the rules at the top of this module for a result that is not OK."""
        status = status or HardwareReadWriteStatus()
        status.ok = False
        if result is ReturnType.DEACTIVATE and which == "write":
            _log.warning("hardware '%s' asked to be deactivated from write", entry.info.name)
            self._set_component_state(entry.info.name, State.INACTIVE)
            status.failed_hardware_names.append(entry.info.name)
            return status
        for failed in _group_of(entry, self._entries):
            _fail(failed, which, result, self._storage)
            if failed.info.name not in status.failed_hardware_names:
                status.failed_hardware_names.append(failed.info.name)
        return status


def _group_of(entry: ComponentEntry, entries: Sequence[ComponentEntry]) -> list[ComponentEntry]:
    group = entry.info.group
    if not group:
        return [entry]
    return [entry] + [e for e in entries if e is not entry and e.info.group == group]


def _fail(entry: ComponentEntry, which: str, result: Any, storage: InterfaceStorage) -> None:
    comp = entry.component
    if comp.get_lifecycle_state() in (State.INACTIVE, State.ACTIVE):
        comp.error()
    storage.set_available(entry.state_names, entry.command_names, False)
    _log.error(
        "hardware '%s' failed in %s (%s); it is now '%s' and its interfaces are unavailable",
        entry.info.name, which, getattr(result, "value", result), comp.get_lifecycle_state().label,
    )
