"""Cycle hooks: callables run after every control cycle (recorders, viewers, plots)."""

from __future__ import annotations

import logging
from collections.abc import Callable

__all__ = ["CycleHook", "CycleHooks"]

# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")

CycleHook = Callable[[float, float], None]


class CycleHooks:
    """The hooks of one manager, in the order they were added; one that raises is logged and the others run."""

    def __init__(self) -> None:
        self._hooks: list[CycleHook] = []

    def add(self, fn: CycleHook) -> Callable[[], None]:
        """Call ``fn(time, period)`` after every cycle. Returns a remover."""
        self._hooks.append(fn)

        def remove() -> None:
            if fn in self._hooks:
                self._hooks.remove(fn)

        return remove

    def run(self, time: float, period: float) -> None:
        """Call every hook (a hook may remove itself or add another while they run)."""
        if self._hooks:
            for hook in list(self._hooks):
                try:
                    hook(time, period)
                except Exception:  # noqa: BLE001 - a plotting hook must not stop the robot
                    _log.error("cycle hook %r raised", hook, exc_info=True)
