"""Clocks that drive the control loop: simulated (default) or paced to the wall clock.

ros2_control's ``ros2_control_node`` wakes up once per period and runs ``read -> update -> write``. Here
the loop is driven by a clock object. :class:`SimClock` advances time by exactly one period per cycle
and never sleeps, so every run gives the same numbers and runs as fast as the CPU allows.
:class:`WallClock` keeps the same simulated time stamps but sleeps so that cycles also happen in real
time (for live demos); a cycle that starts late is an *overrun*, logged, never raised.

Time is kept exactly, so it does not drift by rounding however long the loop runs: the number of cycles (a cycle
happens at ``cycles / update_rate``), and the time run since the last cycle as a fraction (:meth:`Clock.plan`,
:meth:`Clock.advance`). A duration given as a float is read as the simplest fraction that is that float (``1/30``
is one thirtieth), so six runs of ``1/30`` s on a 10 Hz loop advance the clock by 0.2 s and run two cycles, as one
run of 0.2 s does.
"""

from __future__ import annotations

import logging
import math
import numbers
import time as _time
from collections.abc import Callable
from fractions import Fraction

from rrbot_workshop.exceptions import ArgumentError

__all__ = ["Clock", "SimClock", "WallClock", "make_clock", "rate_due", "exact_seconds"]

_log = logging.getLogger(__name__)

#: Largest denominator of the fraction a duration is read as (see :func:`exact_seconds`).
_DENOMINATOR = 10**12


def exact_seconds(seconds: float) -> Fraction:
    """``seconds`` as the simplest fraction within 10^-12 of a billionth of it: ``1/30`` -> 1/30, ``0.1`` -> 1/10.

    Raises:
        ValueError: If ``seconds`` is negative or not finite.
    """
    if not isinstance(seconds, numbers.Real) or isinstance(seconds, bool) or not math.isfinite(seconds) or seconds < 0:
        raise ValueError(f"cannot run for {seconds!r} s: give a finite duration of 0 s or more")
    exact = seconds if isinstance(seconds, numbers.Rational) else float(seconds)
    return Fraction(exact).limit_denominator(_DENOMINATOR)


class Clock:
    """Simulated time of a control loop running at ``update_rate``.

    Args:
        update_rate: Loop rate in [Hz]; one :meth:`tick` advances time by ``1 / update_rate`` [s].

    Raises:
        ValueError: If ``update_rate`` is not a positive integer.
    """

    def __init__(self, update_rate: int = 100) -> None:
        if not isinstance(update_rate, int) or isinstance(update_rate, bool) or update_rate <= 0:
            raise ValueError(f"update_rate must be a positive integer in [Hz], got {update_rate!r}")
        self._rate = update_rate
        self._cycles = 0
        self._since = Fraction(0)  # time run since the last cycle in [s], less than a period

    @property
    def update_rate(self) -> int:
        """Loop rate in [Hz]."""
        return self._rate

    @property
    def period(self) -> float:
        """Loop period in [s]."""
        return 1.0 / self._rate

    @property
    def cycles(self) -> int:
        """Number of ticks so far."""
        return self._cycles

    def now(self) -> float:
        """Current time in [s]: the last cycle's time plus the time run since it (see :meth:`advance`)."""
        if not self._since:
            return self._cycles / self._rate
        return float(Fraction(self._cycles, self._rate) + self._since)

    def tick(self) -> float:
        """Advance to the next cycle's time, ``(cycles + 1) / update_rate``, and return it in [s]."""
        self._cycles += 1
        self._since = Fraction(0)
        return self._cycles / self._rate

    def cycles_for(self, seconds: float) -> int:
        """Whole cycles that make up ``seconds`` [s] (rounded to the nearest cycle).

        Raises:
            ValueError: If ``seconds`` is negative.
        """
        if seconds < 0:
            raise ValueError(f"cannot run for a negative duration ({seconds} s)")
        return int(round(seconds * self._rate))

    def plan(self, seconds: float) -> tuple[int, Fraction]:
        """How ``seconds`` [s] more of time would run: the cycles whose time falls within them, and the time left
        after the last of them [s] (to give :meth:`advance` once those cycles ran). See :func:`exact_seconds`.

        Raises:
            ValueError: If ``seconds`` is negative or not finite.
        """
        total = self._since + exact_seconds(seconds)
        cycles = math.floor(total * self._rate)
        return cycles, total - Fraction(cycles, self._rate)

    def advance(self, since: Fraction) -> float:
        """Set the time run since the last cycle [s] (the second value of :meth:`plan`); return the time in [s].

        Raises:
            ValueError: If ``since`` is not within one period (0 s or more, less than ``1 / update_rate``).
        """
        since = Fraction(since)
        if not 0 <= since * self._rate < 1:
            raise ValueError(f"time since the last cycle must be within one period ({self.period} s), got "
                             f"{float(since)} s")
        self._since = since
        return self.now()


class SimClock(Clock):
    """Deterministic simulated clock: never sleeps (the default)."""


class WallClock(Clock):
    """Simulated time stamps, paced to real time: :meth:`tick` sleeps until the cycle's deadline.

    Args:
        update_rate: Loop rate in [Hz].
        sleep: Sleep function (injectable for tests); defaults to :func:`time.sleep`.
        monotonic: Time source in [s] (injectable for tests); defaults to :func:`time.monotonic`.
    """

    def __init__(
        self,
        update_rate: int = 100,
        sleep: Callable[[float], None] | None = None,
        monotonic: Callable[[], float] | None = None,
    ) -> None:
        super().__init__(update_rate)
        self._sleep = sleep or _time.sleep
        self._monotonic = monotonic or _time.monotonic
        self._start: float | None = None
        self._start_cycle = 0
        self.overruns = 0

    def reset_pacing(self) -> None:
        """Forget the real-time reference (call after a pause, e.g. between two ``spin`` calls)."""
        self._start = None

    def tick(self) -> float:
        """Sleep until the next deadline, then advance by one period. Logs overruns."""
        real = self._monotonic()
        if self._start is None:
            self._start = real
            self._start_cycle = self._cycles
        deadline = self._start + (self._cycles + 1 - self._start_cycle) / self._rate
        delay = deadline - real
        if delay > 0:
            self._sleep(delay)
        elif -delay > self.period:
            self.overruns += 1
            _log.warning(
                "control cycle %d overran: %.1f ms late at %d Hz", self._cycles + 1, -delay * 1e3, self._rate
            )
        return super().tick()


def make_clock(kind: str | Clock, update_rate: int) -> Clock:
    """A clock from ``"sim"`` or ``"wall"`` (or a ready clock, returned as is).

    Raises:
        ArgumentError: If ``kind`` is neither ``"sim"``, ``"wall"`` nor a clock (a :class:`ValueError` too).
    """
    if isinstance(kind, Clock):
        return kind
    if kind == "sim":
        return SimClock(update_rate)
    if kind == "wall":
        return WallClock(update_rate)
    raise ArgumentError("bringup", "clock", kind, "'sim', 'wall' or a clock object")


def rate_due(last: float | None, time: float, rate: int, cm_rate: int) -> bool:
    """Whether something running at ``rate`` inside a loop at ``cm_rate`` is due at ``time``.

    ros2_control's rule for controllers and hardware with a lower rate: run when
    ``|T*r - 1| <= |(T + 1/cm)*r - 1|``, T being the time since the last run, i.e. when running now
    keeps the period closer to ``1/r`` than waiting one more cycle would. The first call always runs.

    Args:
        last: Time of the last run in [s], or None if it never ran.
        time: Current time in [s].
        rate: Own rate in [Hz].
        cm_rate: Loop rate in [Hz].
    """
    if last is None or rate <= 0 or rate >= cm_rate:
        return True
    elapsed = time - last
    return abs(elapsed * rate - 1.0) <= abs((elapsed + 1.0 / cm_rate) * rate - 1.0)
