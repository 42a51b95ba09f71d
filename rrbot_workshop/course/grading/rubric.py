"""Rubric: the outcome of one grader run, check by check, as text for people and JSON for tools.

A check is one test function of a grader file (``tests/tasks/test_taskNN_<name>.py``) marked with
:func:`graded`, which gives it a weight in points and a hint shown when it fails.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, NoReturn, TypeVar

__all__ = ["CheckSpec", "graded", "check_spec", "CheckResult", "Rubric", "DEFAULT_POINTS", "HintlessFailure",
           "fail_without_hint"]

#: Points of a grader test that has no :func:`graded` decorator.
DEFAULT_POINTS = 1.0

_F = TypeVar("_F", bound=Callable[..., Any])


@dataclass(frozen=True)
class CheckSpec:
    """Weight and hint of one check, and whether the exercise already satisfies it (``given``).

    Attributes:
        points: Points the check is worth (> 0).
        hint: What to look at when the check fails: the specification, in a sentence or two.
        given: The handed-out exercise already satisfies it.
        hints: The graduated hint levels.
        after: Names of the checks (test functions of the same grader) whose rules this one builds on: when one of
            them fails too, this check's failure is theirs, and it shows no hint of its own.
    """

    points: float
    hint: str
    given: bool = False
    hints: tuple[str, ...] = ()
    after: tuple[str, ...] = ()


def graded(
    points: float = DEFAULT_POINTS, hint: str | Sequence[str] = "", given: bool = False, after: Sequence[str] = ()
) -> Callable[[_F], _F]:
    """Decorator that makes a grader test a weighted check.

    Example:
        >>> @graded(points=2, hint="link1 is a cylinder 0.5 m long: joint2 sits 0.5 m above joint1.")
        ... def test_link1_length(urdf): ...

    Args:
        points: Points the check is worth (> 0).
        hint: Shown with a failed check: one text, or graduated levels (the concept, then the API to use, then the
            code), shown one at a time, a level deeper each time the learner's check fails again.
        given: The handed-out exercise already satisfies it (e.g. "the file processes"): it is still checked and
            shown, marked GIVEN, but earns no points, so an untouched exercise scores 0.
        after: Checks (test function names of the same grader) this one builds on: when one of them fails as well,
            the learner's cause is there, so this check shows no hint of its own and says which check to fix first.

    Raises:
        ValueError: If ``points`` is not positive.
    """
    if not points > 0:
        raise ValueError(f"a check must be worth more than 0 points, got {points!r}")

    def mark(func: _F) -> _F:
        levels = (hint,) if isinstance(hint, str) else tuple(hint)
        func.__rubric_check__ = CheckSpec(float(points), levels[0] if levels else "", given, levels,  # type: ignore[attr-defined]
                                          tuple(after))
        return func

    return mark


class HintlessFailure(AssertionError):
    """A check's failure that shows no hint (see :func:`fail_without_hint`).

    Attributes:
        note: Why no hint is shown, added to the reason whatever it becomes (the learner's own error, when it is the
            cause, takes the reason's place).
    """

    def __init__(self, reason: str, note: str = "") -> None:
        super().__init__(reason)
        self.note = note


def fail_without_hint(reason: str, note: str = "") -> NoReturn:
    """Fail the running check with ``reason`` and no hint.

    For a failure where any hint would hand over the answer or has nothing left to teach: a prediction not made yet
    (its hint would state the outcome), or one changed after its outcome was shown. The check leaves the hint to the
    learner's next cause.

    Args:
        reason: Why the check failed.
        note: Why it shows no hint (added to the reason in brackets).

    Raises:
        HintlessFailure: Always.
    """
    raise HintlessFailure(reason, note)


def first_failure(checks: Iterable[Callable[..., Any]], *args: Any) -> str:
    """Why the first of ``checks`` that fails on ``args`` fails (its AssertionError's text), or "" when none does.

    A grader asks this of a learner's file before its running checks: a file that breaks a rule its own checks judge is
    replaced by the reference there, so each later check is judged on its own.
    """
    for check in checks:
        try:
            check(*args)
        except AssertionError as exc:
            return str(exc)
    return ""


def check_spec(func: Callable[..., Any]) -> CheckSpec:
    """The :class:`CheckSpec` of a grader test (1 point and its docstring's first line if undecorated)."""
    spec = getattr(func, "__rubric_check__", None)
    if isinstance(spec, CheckSpec):
        return spec
    doc = (getattr(func, "__doc__", None) or "").strip().splitlines()
    return CheckSpec(DEFAULT_POINTS, doc[0] if doc else "")


def _fmt(value: float) -> str:
    return f"{value:g}"


@dataclass
class CheckResult:
    """Outcome of one check.

    Attributes:
        name: Check name (the test function's name without ``test_``).
        max_points: Points the check is worth.
        passed: Whether it passed.
        hint: The check's hint when it is the learner's first cause, else ``""``.
        detail: First lines of the failure (assertion message, error, timeout), else ``""``.
        given: The handed-out exercise already satisfies it: shown, never scored.
        same_as: An earlier failed check with the same reason (the reason is given once).
        blocked_by: The failed check this one builds on (``graded(after=...)``): its failure is that one's.
    """

    name: str
    max_points: float
    passed: bool
    hint: str = ""
    detail: str = ""
    given: bool = False
    same_as: str = ""
    blocked_by: str = ""

    @property
    def points(self) -> float:
        """Points earned: all of them or none."""
        return self.max_points if self.passed else 0.0

    @property
    def reason(self) -> str:
        """Why it failed, as the learner reads it: the check it waits for, else its own detail."""
        if self.passed:
            return ""
        return f"fails because {self.blocked_by} fails: fix that first" if self.blocked_by else self.detail

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"name", "points", "max_points", "passed", "given", "hint", "reason"}``.

        ``reason`` is why a failed check failed (``""`` when it passed); when several checks fail for the same reason
        (a file that does not parse), it is given once and the others say ``"same_as": "<first check>"``. A check that
        fails because a check it builds on fails says so as its reason and names it: ``"after": "<that check>"``.
        """
        out: dict[str, Any] = {
            "name": self.name,
            "points": self.points,
            "max_points": self.max_points,
            "passed": self.passed,
            "given": self.given,
            "hint": self.hint,
            "reason": "" if self.passed or self.same_as else self.reason,
        }
        if self.blocked_by and not self.passed:
            out["after"] = self.blocked_by
        elif self.same_as:
            out["same_as"] = self.same_as
        return out


@dataclass
class Rubric:
    """All checks of one task's grader.

    Attributes:
        task: Task number.
        checks: Check outcomes in the grader's order.
        title: Task folder name, e.g. ``"task01_description"`` (text output only).
        track: Track that was graded (text output only).
        cause: The failed check that shows its hint: the learner's first cause (``""``: none).
    """

    task: int
    checks: list[CheckResult] = field(default_factory=list)
    title: str = ""
    track: str = ""
    cause: str = ""

    @property
    def score(self) -> float:
        """Points earned (given checks earn none)."""
        return sum(c.points for c in self.checks if not c.given)

    @property
    def max_score(self) -> float:
        """Points available (given checks are not counted)."""
        return sum(c.max_points for c in self.checks if not c.given)

    @property
    def complete(self) -> bool:
        """True if every check passed."""
        return bool(self.checks) and all(c.passed for c in self.checks)

    def failed(self) -> list[CheckResult]:
        """The checks that did not pass."""
        return [c for c in self.checks if not c.passed]

    def __post_init__(self) -> None:
        self.mark_shared_reasons()

    def mark_shared_reasons(self) -> None:
        """Failed checks with the reason of an earlier failed check point to it instead of repeating it."""
        first: dict[str, str] = {}
        for c in self.checks:
            c.same_as = ""
            if c.passed or not c.detail or c.blocked_by:
                continue
            if c.detail in first:
                c.same_as = first[c.detail]
            else:
                first[c.detail] = c.name

    def to_dict(self) -> dict[str, Any]:
        """``{"task": N, "score": ..., "max_score": ..., "checks": [...]}``."""
        return {
            "task": self.task,
            "score": self.score,
            "max_score": self.max_score,
            "checks": [c.to_dict() for c in self.checks],
        }

    def to_json(self) -> str:
        """:meth:`to_dict` as JSON text."""
        return json.dumps(self.to_dict())

    def format(self, details: bool = True) -> str:
        """The rubric as text: one line per check, the hint (and why) under each failure, then the total.

        Args:
            details: Also show the first line of each failure's message.
        """
        title = self.title or f"task {self.task}"
        track = f" ({self.track} track)" if self.track else ""
        lines = [f"Task {self.task}: {title}{track}"]
        width = max((len(_fmt(c.max_points)) for c in self.checks), default=1)
        for c in self.checks:
            mark = ("GIVEN" if c.passed else "FAIL ") if c.given else ("PASS " if c.passed else "FAIL ")
            pts = f"{_fmt(c.points):>{width}}/{_fmt(c.max_points):<{width}}" if not c.given else " " * (2 * width + 1)
            lines.append(f"  {mark} {pts}  {c.name}")
            if not c.passed:
                if c.hint:
                    lines.append(f"        hint: {c.hint}")
                if c.blocked_by:
                    lines.append(f"        why:  {c.reason}")
                elif details and c.same_as:
                    lines.append(f"        why:  the same as for {c.same_as} above")
                elif details and c.detail:
                    lines.append(f"        why:  {c.detail}")
        waiting = [c.name for c in self.checks if not c.passed and not c.blocked_by and c.name != self.cause]
        if self.cause and waiting:
            lines.append(f"Hints come one cause at a time: fix {self.cause} first, then check again.")
        lines.append(f"Total: {_fmt(self.score)}/{_fmt(self.max_score)} points")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.format()

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        """Show the text rubric as a notebook cell's output."""
        printer.text(self.format())
