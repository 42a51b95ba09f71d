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
from collections.abc import Callable, Mapping
from time import perf_counter
from typing import Any

from rrbot_workshop.controller_interface.base import ControllerInterface
from rrbot_workshop.controller_manager.chains import ChainGraph
from rrbot_workshop.controller_manager.spec import ControllerSpec
from rrbot_workshop.controller_manager.statistics import ControllerStatistics
from rrbot_workshop.middleware.clock import rate_due
from rrbot_workshop.middleware.compiled import compile_function
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, ReturnType, State

__all__ = ["ControllerLoop"]


# One active controller's part of the compiled loop. ``{due}`` is ``ctrl._state is ACTIVE`` for a controller at the
# manager's rate, with the rate rule added for a slower one; ``{period}`` computes its period.
_BLOCK = """
    ctrl = c{k}
    if {due}:
        spec = s{k}
        last = spec.last_update_time
        ctrl_period = {period}
        if last is None:
            st{k}.reset()
        spec.last_update_time = time
        started = clock()
        try:
            result = ctrl.update(time, ctrl_period)
        except Exception:
            if not loop.handle_exceptions:
                raise
            result = raised(n{k})
        p{k}.extend(((clock() - started) * 1e6, ctrl_period))
        if len(p{k}) >= FOLD_AT:
            st{k}.fold()
        if result is not OK:
            failed = not_ok(failed, n{k}, result)
"""


# The controller manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.controller_manager.manager")


class ControllerLoop:
    """The controllers' part of the cycle, compiled: the active controllers in chain order, prepared once.

    The loop owns its plan: for each active controller, its record, its instance and its own rate when it is slower
    than the manager's. When a lifecycle state changes anywhere (:data:`~rrbot_workshop.middleware.lifecycle.TRANSITIONS`)
    or the chain graph changes its order, the plan is made again and compiled into one Python function, :attr:`update`,
    with one block per active controller (:attr:`source` shows it). A cycle still checks that each controller is
    active before it updates it, calls ``update`` through the instance (a controller whose method is replaced at run
    time is called as it is now), records the statistics (two floats on ``ControllerStatistics.pending``), and hands the
    controllers that failed (an exception or a result other than OK) to ``on_failed``, the manager's slow path.

    Compiling spares each cycle the loop over the plan and its bookkeeping: about half a microsecond per cycle with
    two controllers, a tenth of the whole mock RRBot cycle (``benchmarks/bench_loop.py``).

    Args:
        controllers: The manager's loaded controllers by name (the live mapping).
        chains: The manager's chain graph (the update order).
        update_rate: The manager's rate in [Hz].
        on_failed: Called with the names of the controllers that failed in a cycle, in update order.
        handle_exceptions: Catch what ``update`` raises (ros2_control's parameter); otherwise it propagates.

    Attributes:
        update: ``update(time, period)``: update each active controller that is due, in chain order, then hand over
            the failures. Time and period in [s]. The compiled function of the current plan (before the first cycle,
            and whenever the plan is out of date, it first compiles the plan).
        source: The Python source of :attr:`update` (empty before the first cycle).
    """

    def __init__(self, controllers: Mapping[str, ControllerSpec], chains: ChainGraph, update_rate: int,
                 on_failed: Callable[[list[str]], None], handle_exceptions: bool = True) -> None:
        self._controllers = controllers
        self._chains = chains
        self.update_rate = update_rate
        self._on_failed = on_failed
        self.handle_exceptions = handle_exceptions
        self.update: Callable[[float, float], None] = self._compile_and_update
        self.source = ""

    def _plan(self) -> list[tuple[str, ControllerSpec, ControllerInterface, int]]:
        """The active controllers in chain order, each with its own rate when it is slower than the manager's (else
        0)."""
        cm_rate = self.update_rate
        plan = []
        for name in self._chains.order:
            spec = self._controllers[name]
            ctrl = spec.controller
            if ctrl._state is State.ACTIVE:  # noqa: SLF001 - the loop reads the lifecycle state the cycle relies on
                rate = ctrl._update_rate or cm_rate  # noqa: SLF001
                plan.append((name, spec, ctrl, rate if rate < cm_rate else 0))
        return plan

    def _compile_and_update(self, time: float, period: float) -> None:
        """Compile the current plan into :attr:`update`, then run it for this cycle."""
        self.update = self._compile(self._plan())
        self.update(time, period)

    def _compile(self, plan: list[tuple[str, ControllerSpec, ControllerInterface, int]]) -> Callable[[float, float], None]:
        namespace: dict[str, Any] = {
            "ACTIVE": State.ACTIVE, "OK": ReturnType.OK, "TRANSITIONS": TRANSITIONS, "BUILT_AT": TRANSITIONS.value,
            "chains": self._chains, "VERSION": self._chains.version, "loop": self, "clock": perf_counter,
            "rate_due": rate_due, "raised": _raised, "not_ok": _not_ok, "on_failed": self._on_failed,
            "stale": self._compile_and_update, "FOLD_AT": ControllerStatistics.FOLD_AT,
        }
        lines = ["def update(time, period):",
                 "    if TRANSITIONS.value != BUILT_AT or chains.version != VERSION:  # the plan is out of date",
                 "        return stale(time, period)",
                 "    failed = None"]
        for k, (name, spec, ctrl, slow) in enumerate(plan):
            # names and numbers reach the source only as names of the namespace (and a name's repr in a comment):
            # a controller called "x\nimport os" stays a string
            namespace.update({f"n{k}": name, f"s{k}": spec, f"c{k}": ctrl, f"st{k}": spec.statistics,
                              f"p{k}": spec.statistics.pending, f"r{k}": slow})
            if slow:  # Jazzy: a slower controller's first update gets its own nominal period, 1/rate
                due = f"ctrl._state is ACTIVE and rate_due(s{k}.last_update_time, time, r{k}, loop.update_rate)"
                own_period = f"1.0 / r{k} if last is None else time - last"
            else:
                due, own_period = "ctrl._state is ACTIVE", "period"
            lines.append(f"    # {name!r}" + (f" at {slow!r} Hz" if slow else ""))
            lines.extend(_BLOCK.format(k=k, due=due, period=own_period).strip("\n").splitlines())
        lines += ["    if failed:", "        on_failed(failed)", ""]
        source = "\n".join(lines)
        self.source = source
        return compile_function(source, "controller loop", "update", namespace)


def _raised(name: str) -> ReturnType:
    """What the loop does with an exception from ``update`` when it handles exceptions (called in the handler)."""
    _log.error("update of controller '%s' raised", name, exc_info=True)
    return ReturnType.ERROR


def _not_ok(failed: list[str] | None, name: str, result: Any) -> list[str]:
    """Add ``name`` to the failed controllers of this cycle (``result`` is not OK)."""
    if result is not ReturnType.ERROR:
        _log.error("update of controller '%s' returned %r", name, result)
    return [name] if failed is None else [*failed, name]
