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
from rrbot_workshop.middleware.lifecycle import ReturnType, State

__all__ = ["HardwareReadWriteStatus", "read_or_write"]

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


def read_or_write(
    which: str,
    entries: Sequence[ComponentEntry],
    time: float,
    period: float,
    update_rate: int,
    storage: InterfaceStorage,
    set_component_state: Callable[[str, State], bool],
) -> HardwareReadWriteStatus:
    """Call ``read`` or ``write`` (``which``) on every component that is due this cycle.

    Args:
        which: ``"read"`` or ``"write"``.
        entries: The components, in cycle order.
        time: Current time in [s].
        period: Controller manager period in [s].
        update_rate: Controller manager rate in [Hz].
        storage: The interface storage whose availability failures change.
        set_component_state: The resource manager's state setter (DEACTIVATE from ``write``).
    """
    status = HardwareReadWriteStatus()
    reading = which == "read"
    for entry in entries:
        if entry.rw_rate >= update_rate:  # the common case: every cycle, the manager's period
            own_period = period
        else:
            last = entry.last_read if reading else entry.last_write
            if not rate_due(last, time, entry.rw_rate, update_rate):
                continue
            own_period = period if last is None else time - last
        if reading:
            entry.last_read = time
        else:
            entry.last_write = time
        component = entry.component
        try:
            result = component.read(time, own_period) if reading else component.write(time, own_period)
        except Exception:  # noqa: BLE001 - handle_exceptions
            _log.error("%s of hardware '%s' raised:\n%s", which, entry.info.name, traceback.format_exc())
            result = ReturnType.ERROR
        if result is ReturnType.OK:
            continue
        status.ok = False
        if result is ReturnType.DEACTIVATE and which == "write":
            _log.warning("hardware '%s' asked to be deactivated from write", entry.info.name)
            set_component_state(entry.info.name, State.INACTIVE)
            status.failed_hardware_names.append(entry.info.name)
            continue
        for failed in _group_of(entry, entries):
            _fail(failed, which, result, storage)
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
