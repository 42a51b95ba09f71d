"""Rubric: the outcome of one grader run, check by check, as text for people and JSON for tools.

A check is one test function of a grader file (``tests/tasks/test_taskNN_<name>.py``) marked with
:func:`graded`, which gives it a weight in points and a hint shown when it fails.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TypeVar

__all__ = ["CheckSpec", "graded", "check_spec", "CheckResult", "Rubric", "DEFAULT_POINTS"]

#: Points of a grader test that has no :func:`graded` decorator.
DEFAULT_POINTS = 1.0

_F = TypeVar("_F", bound=Callable[..., Any])


@dataclass(frozen=True)
class CheckSpec:
    """Weight and hint of one check.

    Attributes:
        points: Points the check is worth (> 0).
        hint: What to look at when the check fails: the specification, in a sentence or two.
    """

    points: float
    hint: str


def graded(points: float = DEFAULT_POINTS, hint: str = "") -> Callable[[_F], _F]:
    """Decorator that makes a grader test a weighted check.

    Example:
        >>> @graded(points=2, hint="link1 is a cylinder 0.5 m long: joint2 sits 0.5 m above joint1.")
        ... def test_link1_length(urdf): ...

    Args:
        points: Points the check is worth (> 0).
        hint: Shown with a failed check.

    Raises:
        ValueError: If ``points`` is not positive.
    """
    if not points > 0:
        raise ValueError(f"a check must be worth more than 0 points, got {points!r}")

    def mark(func: _F) -> _F:
        func.__rubric_check__ = CheckSpec(float(points), hint)  # type: ignore[attr-defined]
        return func

    return mark


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
        hint: The check's hint when it failed, else ``""``.
        detail: First lines of the failure (assertion message, error, timeout), else ``""``.
    """

    name: str
    max_points: float
    passed: bool
    hint: str = ""
    detail: str = ""

    @property
    def points(self) -> float:
        """Points earned: all of them or none."""
        return self.max_points if self.passed else 0.0

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"name", "points", "max_points", "passed", "hint"}``."""
        return {
            "name": self.name,
            "points": self.points,
            "max_points": self.max_points,
            "passed": self.passed,
            "hint": self.hint,
        }


@dataclass
class Rubric:
    """All checks of one task's grader.

    Attributes:
        task: Task number.
        checks: Check outcomes in the grader's order.
        title: Task folder name, e.g. ``"task01_description"`` (text output only).
        track: Track that was graded (text output only).
    """

    task: int
    checks: list[CheckResult] = field(default_factory=list)
    title: str = ""
    track: str = ""

    @property
    def score(self) -> float:
        """Points earned."""
        return sum(c.points for c in self.checks)

    @property
    def max_score(self) -> float:
        """Points available."""
        return sum(c.max_points for c in self.checks)

    @property
    def complete(self) -> bool:
        """True if every check passed."""
        return bool(self.checks) and all(c.passed for c in self.checks)

    def failed(self) -> list[CheckResult]:
        """The checks that did not pass."""
        return [c for c in self.checks if not c.passed]

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
            mark = "PASS" if c.passed else "FAIL"
            pts = f"{_fmt(c.points):>{width}}/{_fmt(c.max_points):<{width}}"
            lines.append(f"  {mark}  {pts}  {c.name}")
            if not c.passed:
                if c.hint:
                    lines.append(f"        hint: {c.hint}")
                if details and c.detail:
                    lines.append(f"        why:  {c.detail}")
        lines.append(f"Total: {_fmt(self.score)}/{_fmt(self.max_score)} points")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.format()

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        """Show the text rubric as a notebook cell's output."""
        printer.text(self.format())
