"""Per-controller timing statistics: the period each update received and the time the update took.

ros2_control (Kilted and later) publishes the execution time and periodicity of each controller on
``~/statistics``; the course keeps the same two figures per controller, since its activation:

* **period** in [s], on the manager's clock (simulated time by default, so the figures are reproducible): the
  ``period`` argument each ``update`` received; a controller with a lower ``update_rate`` shows its own period;
* **execution time** in [µs] of each ``update`` call, measured on the wall clock (it varies from run to run).

``%control statistics`` prints them; ``cm.controller_statistics()`` returns them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["RunningStats", "ControllerStatistics"]


@dataclass
class RunningStats:
    """Count, mean, minimum and maximum of a stream of numbers, in constant memory."""

    count: int = 0
    total: float = 0.0
    minimum: float = math.inf
    maximum: float = -math.inf
    last: float = math.nan

    def add(self, value: float) -> None:
        """Account for one more value."""
        self.count += 1
        self.total += value
        self.last = value
        if value < self.minimum:
            self.minimum = value
        if value > self.maximum:
            self.maximum = value

    @property
    def mean(self) -> float:
        """The mean, NaN before the first value."""
        return self.total / self.count if self.count else math.nan


@dataclass
class ControllerStatistics:
    """The timing of one controller's updates since its last activation.

    Attributes:
        period: The ``period`` passed to ``update`` in [s].
        execution_time: Wall-clock duration of ``update`` in [µs].
    """

    period: RunningStats = field(default_factory=RunningStats)
    execution_time: RunningStats = field(default_factory=RunningStats)

    def record(self, execution_us: float, period: float) -> None:
        """Account for one update: its execution time [µs] and the period it received [s] (inline: it runs in every
        cycle for every controller)."""
        e, p = self.execution_time, self.period
        e.count += 1
        e.total += execution_us
        e.last = execution_us
        if execution_us < e.minimum:
            e.minimum = execution_us
        if execution_us > e.maximum:
            e.maximum = execution_us
        p.count += 1
        p.total += period
        p.last = period
        if period < p.minimum:
            p.minimum = period
        if period > p.maximum:
            p.maximum = period

    def reset(self) -> None:
        """Start over (at activation)."""
        self.period = RunningStats()
        self.execution_time = RunningStats()
