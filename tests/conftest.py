"""Shared pytest hooks: conformance tallies printed at the end of the run.

A conformance test records each case with the ``conformance_tally`` fixture:
``conformance_tally("ros2_control parser", case, expected="accept", got="reject", note="...")``.
The terminal summary then prints one line per suite, plus every case whose outcome differs from the reference.
Under pytest-xdist each worker sends its cases to the controller when it finishes, which prints them all.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pytest


@dataclass(frozen=True)
class _Outcome:
    case: str
    expected: str
    got: str
    note: str


_TALLIES: dict[str, dict[str, _Outcome]] = {}


@pytest.fixture(scope="session")
def conformance_tally() -> Callable[..., None]:
    """Record one conformance case: ``(suite, case, expected=..., got=..., note="")``."""

    def record(suite: str, case: str, *, expected: str, got: str, note: str = "") -> None:
        _TALLIES.setdefault(suite, {})[case] = _Outcome(case, expected, got, note)

    return record


#: Test files that take the longest, run first so that no worker is left with a long one at the end of a run
#: spread over the cores (pytest-xdist hands out whole files in collection order).
_LONG_FIRST = ("notebooks/", "test_grader_task", "test_room", "test_learner_workflow", "test_course_in_browser",
               "test_graders", "test_ros2_control_demos", "test_grading", "test_withheld_references")


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items: list[pytest.Item]) -> None:
    """Long files first; the order of the items inside a file (a notebook's cells) is kept."""
    def rank(item: pytest.Item) -> int:
        path = item.nodeid.split("::", 1)[0]
        return next((i for i, part in enumerate(_LONG_FIRST) if part in path), len(_LONG_FIRST))

    items.sort(key=rank)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """An xdist worker hands its cases to the controller (``workeroutput`` travels back when the worker ends)."""
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput["conformance_tallies"] = [
            [suite, o.case, o.expected, o.got, o.note] for suite, cases in _TALLIES.items() for o in cases.values()
        ]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """The controller takes in the cases a worker recorded (called only where pytest-xdist runs)."""
    for suite, case, expected, got, note in getattr(node, "workeroutput", {}).get("conformance_tallies", []):
        _TALLIES.setdefault(suite, {})[case] = _Outcome(case, expected, got, note)


def pytest_terminal_summary(terminalreporter: Any, exitstatus: int, config: pytest.Config) -> None:
    """Print ``<suite> conformance: same/total cases as the reference (per expectation), differences``."""
    for suite, outcomes in sorted(_TALLIES.items()):
        same = [o for o in outcomes.values() if o.expected == o.got]
        per_kind = []
        for kind in sorted({o.expected for o in outcomes.values()}):
            total = sum(1 for o in outcomes.values() if o.expected == kind)
            matched = sum(1 for o in same if o.expected == kind)
            word = f"{kind}ed" if kind in ("accept", "reject") else kind
            per_kind.append(f"{word} {matched}/{total}")
        terminalreporter.write_sep("-", f"{suite} conformance")
        terminalreporter.write_line(
            f"{suite} conformance: {len(same)}/{len(outcomes)} cases as the reference ({', '.join(per_kind)})"
        )
        for outcome in sorted(outcomes.values(), key=lambda o: o.case):
            if outcome.expected != outcome.got:
                note = f": {outcome.note}" if outcome.note else ""
                terminalreporter.write_line(
                    f"  differs: {outcome.case} (reference {outcome.expected}s, we {outcome.got}){note}"
                )
