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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from rrbot_workshop.hardware_interface.resource_loading import ComponentEntry
from rrbot_workshop.hardware_interface.resource_storage import InterfaceStorage
from rrbot_workshop.middleware.clock import rate_due
from rrbot_workshop.middleware.compiled import compile_function
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, ReturnType, State

__all__ = ["HardwareReadWriteStatus", "HardwareCycle"]

# One component's part of a compiled read or write: the implementation called directly, as the wrapper would, while
# no state changed during this cycle; the wrapper itself otherwise. The outer handler catches what the wrapper or
# settle raise (handle_exceptions).
_BLOCK = """
    entry = {which}_entry{k}
    component = {which}_component{k}
    entry.last_{which} = time
    try:
        if TRANSITIONS.value != BUILT_AT or component._exported is None:
            result = component.{which}(time, period)
        else:
            try:
                result = component._impl.{which}(time, period)
            except Exception as exc:
                result = component.settle("{which}", None, exc)
            else:
                if result is not OK:
                    result = component.settle("{which}", result)
    except Exception:
        result = raised("{which}", entry)
    if result is not OK:
        status = failed("{which}", entry, result, status)
"""

# A slower component: called through its wrapper when the rate rule says so, with the time since its last call.
_SLOW_BLOCK = """
    entry = {which}_entry{k}
    last = entry.last_{which}
    if rate_due(last, time, {which}_rate{k}, cycle.update_rate):
        entry.last_{which} = time
        try:
            result = {which}_component{k}.{which}(time, period if last is None else time - last)
        except Exception:
            result = raised("{which}", entry)
        if result is not OK:
            status = failed("{which}", entry, result, status)
"""

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
    (active, not sensors), each with its own rate when it is slower than the manager. It is made again when a lifecycle
    state changes anywhere (:data:`~rrbot_workshop.middleware.lifecycle.TRANSITIONS`) or the components change
    (:meth:`set_entries`), and compiled into two Python functions, :attr:`read` and :attr:`write`, with a block per
    component (:attr:`source` shows them). A component with a slower rate stays in the plan whatever its state, as its
    time of last call moves on in every state. A component in the plan is in a state that reads (writes), so the cycle
    calls its implementation's ``read``/``write`` itself (looked up on each call: a method replaced at run time is called
    as it is now); what the implementation raises or any result but OK goes through the wrapper's
    :meth:`~.HardwareComponent.settle` (logged, mapped to ERROR, ``error()``) and then the slow path (the rules at the
    top of this module). A slower component, or any component after a state changed during the cycle, is called
    through its lifecycle wrapper, which checks the state first.

    Args:
        update_rate: The controller manager's rate in [Hz].
        storage: The interface storage whose availability failures change.
        set_component_state: The resource manager's state setter (DEACTIVATE from ``write``).

    Attributes:
        read: ``read(time, period)``: read every component that is due; None when all returned OK, else a
            :class:`HardwareReadWriteStatus` of what failed. Time and period in [s].
        write: ``write(time, period)``: write every component that is due; None when all returned OK, else what failed
            or deactivated.
        source: The Python source of :attr:`read` and :attr:`write` (empty before the first cycle).
    """

    def __init__(self, update_rate: int, storage: InterfaceStorage,
                 set_component_state: Callable[[str, State], bool]) -> None:
        self.update_rate = update_rate
        self._storage = storage
        self._set_component_state = set_component_state
        self._entries: Sequence[ComponentEntry] = ()
        self.source = ""
        self.read: Callable[[float, float], HardwareReadWriteStatus | None] = self._compile_and_read
        self.write: Callable[[float, float], HardwareReadWriteStatus | None] = self._compile_and_write

    def set_entries(self, entries: Sequence[ComponentEntry]) -> None:
        """The components, in cycle order (after a load or a rejected load)."""
        self._entries = entries
        self.read, self.write = self._compile_and_read, self._compile_and_write

    def _plan(self) -> tuple[list[tuple[ComponentEntry, int]], list[tuple[ComponentEntry, int]]]:
        """The components that read and those that write, in cycle order, each with its own rate when it is slower
        than the manager's (else 0)."""
        readable, active = (State.INACTIVE, State.ACTIVE), State.ACTIVE
        reads, writes = [], []
        for entry in self._entries:
            component = entry.component
            state = component.get_lifecycle_state()
            slow = entry.rw_rate if entry.rw_rate < self.update_rate else 0
            # a slower component stays in the plan whatever its state: its last call time moves on as before
            if slow or state in readable:
                reads.append((entry, slow))
            if slow or (state is active and component.type != "sensor"):
                writes.append((entry, slow))
        return reads, writes

    def _compile(self) -> None:
        namespace: dict[str, Any] = {
            "OK": ReturnType.OK, "TRANSITIONS": TRANSITIONS, "BUILT_AT": TRANSITIONS.value, "cycle": self,
            "rate_due": rate_due, "raised": _raised, "failed": self._failed,
            "stale_read": self._compile_and_read, "stale_write": self._compile_and_write,
        }
        reads, writes = self._plan()
        sources = []
        for which, plan in (("read", reads), ("write", writes)):
            lines = [f"def {which}(time, period):",
                     "    if TRANSITIONS.value != BUILT_AT:  # the plan is out of date",
                     f"        return stale_{which}(time, period)",
                     "    status = None"]
            for k, (entry, slow) in enumerate(plan):
                # the component reaches the source only as names of the namespace (its name's repr in a comment)
                namespace[f"{which}_entry{k}"], namespace[f"{which}_component{k}"] = entry, entry.component
                namespace[f"{which}_rate{k}"] = slow
                block = _SLOW_BLOCK if slow else _BLOCK
                lines.append(f"    # {entry.info.name!r}" + (f" at {slow!r} Hz" if slow else ""))
                lines.extend(block.format(which=which, k=k).strip("\n").splitlines())
            lines += ["    return status", ""]
            sources.append("\n".join(lines))
        self.source = "\n".join(sources)
        self.read = compile_function(sources[0], "hardware read", "read", namespace)
        self.write = compile_function(sources[1], "hardware write", "write", namespace)

    def _compile_and_read(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        self._compile()
        return self.read(time, period)

    def _compile_and_write(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        self._compile()
        return self.write(time, period)

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


def _raised(which: str, entry: ComponentEntry) -> ReturnType:
    """What the cycle does with an exception the wrapper or ``settle`` let through (called in the handler)."""
    if not entry.component.handle_exceptions:
        raise  # noqa: PLE0704 - called inside the cycle's handler: ros2_control's handle_exceptions false propagates
    _log.error("%s of hardware '%s' raised", which, entry.info.name, exc_info=True)
    return ReturnType.ERROR


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
