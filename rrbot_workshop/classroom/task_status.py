"""Where a learner stands on a task: not started, working, stuck or passed, from their self-check records alone.

This is the status model of the instructor's views (``rrbot-workshop class-report`` today, the live view of a hub
later). It reads no file and asks no clock: :func:`classify` is a pure function of a task's attempt records, the time
``now`` and the option ``stuck_after``, so any source of records (a learner's ``exercises/.progress/taskNN.json``,
a result posted to a service) is classified the same way.

A learner × task is exactly one of:

* **not started** (:data:`NOT_STARTED`): no self-check of the learner's own work. Either no attempt at all, or every
  attempt graded the exercise as handed out (its files' version is one of ``untouched``, see
  :func:`rrbot_workshop.course.grading.attempts.files_version`): a notebook's self-check cell run before the learner
  changed anything is not a start.
* **passed** (:data:`PASSED`): some attempt got every point (the task stays passed if a later change breaks it; the
  record's ``points`` show the latest attempt).
* **stuck** (:data:`STUCK`): not passed, and a check that fails in the learner's latest attempt on their own files
  has failed in every such attempt since a time at least ``stuck_after`` seconds before ``now``. Each check keeps its
  own clock, from the first attempt of its unbroken run of failures: fixing one check resets no other's, and a check
  that fails again after passing starts anew.
* **working** (:data:`WORKING`): started, not passed, not stuck.

The time to pass is shown only when it means something: from the first attempt on the learner's own files to the
first full score, and None when that first attempt already passed (a first-try pass, ``first_try``).

Example:
    >>> a = [Attempt(time=0.0, score=0, max_score=10, failed=("limits",), version="v1"),
    ...      Attempt(time=900.0, score=0, max_score=10, failed=("limits",), version="v2")]
    >>> classify(a, now=1000.0, stuck_after=600.0).status
    'stuck'
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime
from typing import Any

from rrbot_workshop.exceptions import CourseError

__all__ = ["NOT_STARTED", "WORKING", "STUCK", "PASSED", "STATUSES", "DEFAULT_STUCK_AFTER_S", "Attempt", "TaskState",
           "classify", "last_activity", "local_time", "MAX_CHECKS", "MAX_NAME_CHARS", "MAX_REASON_CHARS"]

NOT_STARTED = "not started"
WORKING = "working"
STUCK = "stuck"
PASSED = "passed"
#: Every status, in the order a task goes through them.
STATUSES = (NOT_STARTED, WORKING, STUCK, PASSED)
#: How long the same check must keep failing before the learner counts as stuck [s] (10 minutes).
DEFAULT_STUCK_AFTER_S = 600.0

#: Most failed checks one attempt may name (a task's grader has a few dozen).
MAX_CHECKS = 200
#: Longest check name and version kept [characters].
MAX_NAME_CHARS = 200
#: Longest reason kept [characters] (the attempt log keeps 300); longer ones are cut.
MAX_REASON_CHARS = 300
#: Latest time an attempt may carry [s since the epoch] (year 5138): beyond it a record is not a time.
_MAX_TIME = 1e11
#: Most points a task may carry.
_MAX_POINTS = 1e6


@dataclass(frozen=True)
class Attempt:
    """One self-check of one task, as the learner's attempt log records it.

    Attributes:
        time: When it ran [s since the epoch].
        score: Points earned.
        max_score: Points available.
        failed: Names of the checks that failed.
        reasons: Why each failed check failed (check -> reason), as the grader stated it.
        version: Digest of the graded files (``""`` when unknown).
    """

    time: float
    score: float
    max_score: float
    failed: tuple[str, ...] = ()
    reasons: Mapping[str, str] = field(default_factory=dict)
    version: str = ""

    @property
    def full(self) -> bool:
        """Whether the attempt got every point."""
        return self.max_score > 0 and self.score >= self.max_score

    @classmethod
    def from_record(cls, record: Any) -> Attempt:
        """An attempt from one entry of an attempt log (``{"time": ..., "score": ..., ...}``), checked.

        Args:
            record: The entry, as JSON gives it.

        Raises:
            ValueError: If the entry is not an attempt: not an object, a time or score that is not a finite number in
                range, a score above the points available, or failed checks that are not a list of names. The
                message says which.
        """
        if not isinstance(record, dict):
            raise ValueError(f"an attempt is an object, not {type(record).__name__}")
        time = _number(record.get("time"), "time", 0.0, _MAX_TIME)
        max_score = _number(record.get("max_score", 0.0), "max_score", 0.0, _MAX_POINTS)
        score = _number(record.get("score", 0.0), "score", 0.0, max_score)
        failed = record.get("failed", [])
        if not isinstance(failed, list) or len(failed) > MAX_CHECKS or not all(isinstance(c, str) for c in failed):
            raise ValueError(f"'failed' must be a list of at most {MAX_CHECKS} check names")
        reasons = record.get("reasons", {})
        reasons = reasons if isinstance(reasons, dict) else {}
        names = tuple(sorted({c[:MAX_NAME_CHARS] for c in failed}))
        kept = {c: str(reasons.get(c, ""))[:MAX_REASON_CHARS] if isinstance(reasons.get(c, ""), str) else ""
                for c in names}
        version = record.get("version", "")
        return cls(time, score, max_score, names, kept, version[:MAX_NAME_CHARS] if isinstance(version, str) else "")


def _number(value: Any, name: str, low: float, high: float) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"'{name}' must be a number, not {type(value).__name__}")
    try:
        number = float(value)
    except OverflowError:
        raise ValueError(f"'{name}' is out of range") from None
    if not math.isfinite(number) or not low <= number <= high:
        raise ValueError(f"'{name}' must be between {low:g} and {high:g}")
    return number


@dataclass(frozen=True)
class TaskState:
    """Where one learner stands on one task (see the module's documentation for the statuses).

    Attributes:
        status: One of :data:`STATUSES`.
        attempts: Self-checks run (all of them, the untouched exercise's too).
        points: Points of the latest attempt (0 without one).
        max_points: Points available at the latest attempt (0 without one).
        first_check: Time of the first attempt [s since the epoch], or None.
        last_check: Time of the latest attempt [s since the epoch], or None.
        passed_at: Time of the first full score [s since the epoch], or None.
        first_try: Whether the first attempt on the learner's own files got every point.
        time_to_pass_s: Seconds from the first attempt on the learner's own files to the first full score; None when
            not passed or passed at the first try.
        failing: The latest attempt's failed checks -> reason (empty once passed).
        failing_since: Each failed check of the latest attempt on the learner's own files -> since when it has failed
            in every such attempt [s since the epoch] (empty once passed or when not started).
        stuck_on: The checks failing for ``stuck_after`` or longer, longest first (empty unless :data:`STUCK`).
    """

    status: str
    attempts: int = 0
    points: float = 0.0
    max_points: float = 0.0
    first_check: float | None = None
    last_check: float | None = None
    passed_at: float | None = None
    first_try: bool = False
    time_to_pass_s: float | None = None
    failing: Mapping[str, str] = field(default_factory=dict)
    failing_since: Mapping[str, float] = field(default_factory=dict)
    stuck_on: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (``failing`` as a sorted list of check names)."""
        return {"status": self.status, "attempts": self.attempts, "points": self.points,
                "max_points": self.max_points, "first_check": self.first_check, "last_check": self.last_check,
                "passed_at": self.passed_at, "first_try": self.first_try, "time_to_pass_s": self.time_to_pass_s,
                "failing": sorted(self.failing), "failing_since": dict(sorted(self.failing_since.items())),
                "stuck_on": list(self.stuck_on)}


def classify(attempts: Sequence[Attempt], now: float, stuck_after: float = DEFAULT_STUCK_AFTER_S,
             untouched: Collection[str] = ()) -> TaskState:
    """Where a learner stands on one task, from that task's attempts.

    Args:
        attempts: The task's attempts, in any order (they are taken in time order).
        now: The time the status is for [s since the epoch].
        stuck_after: How long the same check must keep failing for :data:`STUCK` [s].
        untouched: Versions of the task's files as handed out: attempts on them are not a start.

    Returns:
        The task's state.

    Raises:
        CourseError: If ``now`` or ``stuck_after`` is not a finite number, or ``stuck_after`` is negative.
    """
    if isinstance(now, bool) or not isinstance(now, int | float) or not math.isfinite(now):
        raise CourseError("now", now, f"now={now!r} must be a finite time in seconds since the epoch")
    if (isinstance(stuck_after, bool) or not isinstance(stuck_after, int | float) or not math.isfinite(stuck_after)
            or stuck_after < 0):
        raise CourseError("stuck_after", stuck_after,
                          f"stuck_after={stuck_after!r} must be a finite number of seconds, 0 or more")
    ordered = sorted(attempts, key=lambda a: a.time)
    if not ordered:
        return TaskState(NOT_STARTED)
    base: dict[str, Any] = {"attempts": len(ordered), "first_check": ordered[0].time, "last_check": ordered[-1].time}
    own = [a for a in ordered if not (a.version and a.version in untouched)]
    passed = next((a for a in ordered if a.full), None)
    latest = own[-1] if own else ordered[-1]
    base.update(points=latest.score, max_points=latest.max_score)
    if passed is not None:
        first_own = own[0] if own else passed
        first_try = first_own is passed or first_own.time >= passed.time
        to_pass = None if first_try else round(passed.time - first_own.time, 1)
        return TaskState(PASSED, passed_at=passed.time, first_try=first_try, time_to_pass_s=to_pass, **base)
    failing = {c: latest.reasons.get(c, "") for c in latest.failed}
    if not own:
        return TaskState(NOT_STARTED, failing=failing, **base)
    since: dict[str, float] = {}
    for check in latest.failed:
        start = latest.time
        for attempt in reversed(own):
            if check not in attempt.failed:
                break
            start = attempt.time
        since[check] = start
    stuck_on = tuple(sorted((c for c in since if now - since[c] >= stuck_after), key=lambda c: (since[c], c)))
    return TaskState(STUCK if stuck_on else WORKING, failing=failing, failing_since=since, stuck_on=stuck_on, **base)


def last_activity(attempts: Iterable[Attempt]) -> float | None:
    """The time of the latest self-check among ``attempts`` (any task) [s since the epoch], or None."""
    return max((a.time for a in attempts), default=None)


def local_time(when: float | None) -> str:
    """``when`` [s since the epoch] as local time, ``2026-05-04 10:32:05 +0200``; ``""`` for None."""
    if when is None:
        return ""
    return datetime.fromtimestamp(when).astimezone().strftime("%Y-%m-%d %H:%M:%S %z")
