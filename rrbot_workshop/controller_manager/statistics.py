"""Per-controller timing statistics: the period each update received and the time the update took.

ros2_control (Kilted and later) publishes the execution time and periodicity of each controller on
``~/statistics``; the course keeps the same two figures per controller, since its activation:

* **periodicity** in [Hz], on the manager's clock (simulated time by default, so the figures are reproducible):
  ``1 / period`` of the ``period`` argument each ``update`` received, the first update after activation left out (it
  has no previous update to measure from), as Jazzy's ``periodicity_statistics``; a controller with a lower
  ``update_rate`` shows its own rate;
* **execution time** in [µs] of each ``update`` call, measured on the wall clock (it varies from run to run).

``%control statistics`` prints them; ``cm.controller_statistics()`` returns them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["RunningStats", "ControllerStatistics"]


@dataclass
class RunningStats:
    """Count, mean, minimum and maximum of a stream of numbers, in constant memory."""

    count: int = 0
    total: float = 0.0
    minimum: float = math.inf
    maximum: float = -math.inf
    last: float = math.nan

    def merge(self, values: Sequence[float]) -> None:
        """Account for ``values`` at once, in their order (the total is summed by ``sum``)."""
        if not values:
            return
        self.count += len(values)
        self.total = sum(values, self.total)
        self.last = values[-1]
        low, high = min(values), max(values)
        if low < self.minimum:
            self.minimum = low
        if high > self.maximum:
            self.maximum = high

    @property
    def mean(self) -> float:
        """The mean, NaN before the first value."""
        return self.total / self.count if self.count else math.nan


class ControllerStatistics:
    """The timing of one controller's updates since its last activation.

    The controller loop records an update by appending its two figures to :attr:`pending` (two floats on a list, the
    cheapest record Python has, and nothing the garbage collector has to look at) and calls :meth:`fold` once the list
    holds ``FOLD_AT`` figures (memory stays bounded in a long run); reading :attr:`period` or :attr:`execution_time`
    folds them too, in the order they came.

    Attributes:
        pending: ``execution_us, period`` of each update not folded in yet, one after the other.
    """

    FOLD_EVERY = 4096
    #: Length of :attr:`pending` at which the loop folds: ``FOLD_EVERY`` updates, two figures each.
    FOLD_AT = 2 * FOLD_EVERY

    __slots__ = ("_period", "_execution_time", "pending", "_skip_first")

    def __init__(self) -> None:
        self._period = RunningStats()
        self._execution_time = RunningStats()
        self.pending: list[float] = []
        self._skip_first = True

    @property
    def periodicity(self) -> RunningStats:
        """The rate of the updates in [Hz] (``1 / period``), the first update since activation not counted."""
        if self.pending:
            self.fold()
        return self._period

    @property
    def period(self) -> RunningStats:
        """The same figures as :attr:`periodicity` (in [Hz]; the name of earlier versions of the course)."""
        return self.periodicity

    @property
    def execution_time(self) -> RunningStats:
        """Wall-clock duration of ``update`` in [µs]."""
        if self.pending:
            self.fold()
        return self._execution_time

    def fold(self) -> None:
        """Fold the pending figures into the running ones, oldest first (builtins over the whole batch: folding costs
        next to nothing per update)."""
        if self.pending:
            self._execution_time.merge(self.pending[0::2])
            periods = self.pending[1::2]
            if self._skip_first:
                self._skip_first = False
                del periods[0]
            self._period.merge([1.0 / p if p > 0.0 else math.inf for p in periods])
            self.pending.clear()

    def reset(self) -> None:
        """Start over (at activation)."""
        self._period = RunningStats()
        self._execution_time = RunningStats()
        self.pending.clear()
        self._skip_first = True

    def __repr__(self) -> str:
        return f"ControllerStatistics(periodicity={self.periodicity!r}, execution_time={self.execution_time!r})"
