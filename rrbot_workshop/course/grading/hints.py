"""Which failed check shows a hint, and how deep: hints follow the learner's first cause.

A grader's checks build on each other (``graded(after=...)``): when the description does not process, every check of
its joints fails too, and their hints would send the learner to places that are right. So, on each grading:

* a failed check whose ``after`` check also failed is *blocked*: its reason becomes "fails because <check> fails: fix
  that first" (the root of the chain is named), and it shows no hint of its own;
* of the failed checks that are not blocked, only the first (in the grader's order) shows a hint: the learner's first
  cause. A check that fails with :func:`~rrbot_workshop.course.grading.rubric.fail_without_hint` (a prediction not made
  yet: any hint would answer it) never shows one, and leaves the hint to the next cause;
* a check's graduated hint goes one level deeper only when that check showed its hint on the previous version of the
  learner's files and still fails. Checking the same files again shows the same hint; a check that showed no hint on
  the previous version (it passed, it was blocked, another cause held the hint) shows the level it last reached.

The attempt log (:mod:`~rrbot_workshop.course.grading.attempts`) records, per attempt, the check that showed its hint
and the level shown: that is all this module reads of the past.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ["CheckEntry", "HintPlan", "plan_hints", "hint_level"]


@dataclass(frozen=True)
class CheckEntry:
    """What the hint plan needs of one check of a grader run.

    Attributes:
        name: The check's name (``"switch_end_states"``, ``"case[2]"`` for a parametrized one).
        function: Its test function's name without ``test_`` (what ``after`` names).
        passed: Whether it passed.
        levels: Its graduated hint levels (empty: no hint).
        after: The checks (function names, with or without ``test_``) it builds on.
        hintless: It failed with ``fail_without_hint``: no hint for this failure.
    """

    name: str
    function: str
    passed: bool
    levels: tuple[str, ...] = ()
    after: tuple[str, ...] = ()
    hintless: bool = False


@dataclass
class HintPlan:
    """The outcome of :func:`plan_hints`.

    Attributes:
        blocked: Check name -> the failed check it waits for (the root of its chain).
        cause: The check that shows a hint, or ``""`` when none does.
        level: The 0-based level of that hint.
        others: Failed, unblocked checks after :attr:`cause` that could show a hint once it passes.
    """

    blocked: dict[str, str] = field(default_factory=dict)
    cause: str = ""
    level: int = 0
    others: list[str] = field(default_factory=list)

    def shown(self) -> dict[str, int]:
        """``{cause: level}`` for the attempt log, or ``{}``."""
        return {self.cause: self.level} if self.cause else {}


def _function(name: str) -> str:
    return name[len("test_"):] if name.startswith("test_") else name


def _roots(entries: Sequence[CheckEntry]) -> dict[str, str]:
    """Check name -> the root failed check it waits for, for every failed check whose ``after`` check failed."""
    by_function: dict[str, list[CheckEntry]] = {}
    for entry in entries:
        by_function.setdefault(entry.function, []).append(entry)

    def root(entry: CheckEntry, seen: frozenset[str]) -> str | None:
        for dep in entry.after:
            for other in by_function.get(_function(dep), []):
                if other.passed or other.name in seen or other.name == entry.name:
                    continue
                deeper = root(other, seen | {other.name})
                return deeper or other.name
        return None

    found: dict[str, str] = {}
    for entry in entries:
        if not entry.passed:
            waits_for = root(entry, frozenset({entry.name}))
            if waits_for is not None:
                found[entry.name] = waits_for
    return found


def hint_level(check: str, count: int, attempts: Sequence[Mapping[str, Any]], version: str) -> int:
    """The level (0-based, below ``count``) of ``check``'s hint on files at ``version``, from the attempt log.

    Args:
        check: The check that shows its hint now.
        count: How many levels it has.
        attempts: The task's logged attempts, oldest first (each may carry ``"version"`` and ``"hints"``).
        version: The digest of the learner's files now (``""``: nothing is known, the first level).
    """
    if not version or count < 1:
        return 0

    def shown(attempt: Mapping[str, Any]) -> int | None:
        hints = attempt.get("hints")
        value = hints.get(check) if isinstance(hints, Mapping) else None
        return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else None

    last = attempts[-1] if attempts else None
    if last is not None:
        before = shown(last)
        if str(last.get("version") or "") == version:
            if before is not None:
                return min(before, count - 1)  # the same files again: the same hint
        elif before is not None:
            return min(before + 1, count - 1)  # it showed its hint on the previous version and still fails
    reached = [level for level in (shown(a) for a in attempts) if level is not None]
    return min(max(reached), count - 1) if reached else 0


def plan_hints(entries: Sequence[CheckEntry], attempts: Sequence[Mapping[str, Any]] = (), version: str = "") -> HintPlan:
    """Decide which failed checks are blocked, which one shows its hint, and at which level.

    Args:
        entries: The grader's checks in its order.
        attempts: The task's attempt log, oldest first (empty: not a learner's own grading).
        version: The digest of the graded files (``""``: not a learner's own grading: the first level).
    """
    plan = HintPlan(blocked=_roots(entries))
    for entry in entries:
        if entry.passed or entry.name in plan.blocked or entry.hintless or not any(entry.levels):
            continue
        if not plan.cause:
            plan.cause = entry.name
            plan.level = hint_level(entry.name, len(entry.levels), attempts, version)
        else:
            plan.others.append(entry.name)
    return plan
