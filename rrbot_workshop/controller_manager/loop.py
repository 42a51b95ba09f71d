"""The controllers' part of a control cycle: who updates, with which period, and what a failure stops.

Active controllers update in chain order. A controller with an ``update_rate`` below the manager's
updates only on the cycles :func:`~rrbot_workshop.middleware.clock.rate_due` picks, and its period is then the
time since its last update. As with ros2_control's ``handle_exceptions``, a controller whose
``update`` raises or does not return OK is deactivated with its chain group, the traceback is
logged, and its ``fallback_controllers`` are activated in one strict switch. Hardware that fails in
``read`` or ``write`` deactivates the active controllers holding its interfaces, with their chain groups; hardware
that deactivates itself from ``write`` stops only the controllers commanding it (if
``deactivate_controllers_on_hardware_self_deactivate``, Jazzy's default). The loop finds the failed controllers;
what they stop is :class:`~rrbot_workshop.controller_manager.failures.FailurePath`'s.
"""

from __future__ import annotations

import logging
import traceback
from collections.abc import Callable, Mapping
from time import perf_counter

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.controller_manager.statistics import ControllerStatistics
from rrbot_workshop.middleware.clock import rate_due
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, ReturnType, State

__all__ = ["ControllerLoop"]


# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class ControllerLoop:
    """The controllers' part of the cycle, compiled: the active controllers in chain order, prepared once.

    The loop owns its plan: for each active controller, its record, its instance and its own rate when it is slower
    than the manager's. The plan is rebuilt when a lifecycle state changes anywhere
    (:data:`~rrbot_workshop.middleware.lifecycle.TRANSITIONS`) or the chain graph changes its order. A cycle still
    checks that each controller is active before it updates it, calls ``update`` through the instance (a controller
    whose method is replaced at run time is called as it is now), records the statistics, and hands the controllers
    that failed (an exception or a result other than OK) to ``on_failed``, the manager's slow path.

    Args:
        controllers: The manager's loaded controllers by name (the live mapping).
        chains: The manager's chain graph (the update order).
        update_rate: The manager's rate in [Hz].
        on_failed: Called with the names of the controllers that failed in a cycle, in update order.
        handle_exceptions: Catch what ``update`` raises (ros2_control's parameter); otherwise it propagates.
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], chains: ChainGraph, update_rate: int,
                 on_failed: Callable[[list[str]], None], handle_exceptions: bool = True) -> None:
        self._controllers = controllers
        self._chains = chains
        self.update_rate = update_rate
        self._on_failed = on_failed
        self.handle_exceptions = handle_exceptions
        self._plan: list[tuple[str, ControllerSpec, ControllerInterface, int, ControllerStatistics]] = []
        self._built_at = -1  # TRANSITIONS.value when the plan was built
        self._built_version = -1  # the chain graph's version then

    def _build(self) -> None:
        cm_rate = self.update_rate
        plan = []
        for name in self._chains.order:
            spec = self._controllers[name]
            ctrl = spec.controller
            if ctrl._state is State.ACTIVE:  # noqa: SLF001 - the loop reads the lifecycle state the cycle relies on
                rate = ctrl._update_rate or cm_rate  # noqa: SLF001
                plan.append((name, spec, ctrl, rate if rate < cm_rate else 0, spec.statistics))
        self._plan = plan
        self._built_at, self._built_version = TRANSITIONS.value, self._chains.version

    def update(self, time: float, period: float) -> None:
        """Update each active controller that is due, in chain order, then hand over the failures.

        Args:
            time: Current time in [s].
            period: Manager period in [s].
        """
        if self._built_at != TRANSITIONS.value or self._built_version != self._chains.version:
            self._build()
        failed: list[str] | None = None
        active, ok = State.ACTIVE, ReturnType.OK
        clock = perf_counter
        for name, spec, ctrl, slow, stats in self._plan:
            if ctrl._state is not active:  # noqa: SLF001 - changed during this cycle
                continue
            last = spec.last_update_time
            if not slow:
                ctrl_period = period
            elif not rate_due(last, time, slow, self.update_rate):
                continue
            else:  # Jazzy: a slower controller's first update gets its own nominal period, 1/rate
                ctrl_period = 1.0 / slow if last is None else time - last
            if last is None:
                stats.reset()
            spec.last_update_time = time
            started = clock()
            try:
                result = ctrl.update(time, ctrl_period)
            except Exception:
                if not self.handle_exceptions:
                    raise
                _log.error("update of controller '%s' raised:\n%s", name, traceback.format_exc())
                result = ReturnType.ERROR
            stats.record((clock() - started) * 1e6, ctrl_period)
            if result is not ok:
                if result is not ReturnType.ERROR:
                    _log.error("update of controller '%s' returned %r", name, result)
                if failed is None:
                    failed = []
                failed.append(name)
        if failed:
            self._on_failed(failed)
