"""Hints follow the learner's cause: one check shows a hint, the checks that build on a failed one say so, and a
hint goes deeper only for the check that showed it on the previous version of the files and still fails.

Each grading runs a small grader written for the test in a subprocess, as a learner's self-check runs.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, check, grade
from rrbot_workshop.course.grading.hints import CheckEntry, hint_level, plan_hints
from rrbot_workshop.course.grading.pytest_process import warm_up
from rrbot_workshop.exceptions import GradingError


@pytest.fixture(scope="module", autouse=True)
def _fork_server() -> None:
    """The module's gradings are forked from one process that has imported what graders use (waited for once): each
    would otherwise be a new Python process importing pytest, numpy, MuJoCo and the library again."""
    warm_up(wait=True)


#: a.txt must say 1; b (built on a) needs b.txt to say 2; c builds on b; d is on its own (d.txt says 4).
_CHAIN = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


def _says(name):
    return (tracks.task_dir(5) / name).read_text().strip()


@graded(points=1, hint=("a idea", "a api", "a code"))
def test_a():
    assert _says("a.txt") == "1", "a.txt does not say 1"


@graded(points=1, hint=("b idea", "b api", "b code"), after=("test_a",))
def test_b():
    assert _says("a.txt") == "1" and _says("b.txt") == "2", "b.txt does not say 2 (or a is wrong)"


@graded(points=1, hint=("c idea", "c api", "c code"), after=("b",))
def test_c():
    assert _says("a.txt") == "1" and _says("b.txt") == "2", "c follows b"


@graded(points=1, hint=("d idea", "d api", "d code"))
def test_d():
    assert _says("d.txt") == "4", "d.txt does not say 4"
'''


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A course with one task (5) graded by :data:`_CHAIN`; the exercise's files all say 0."""
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(_CHAIN)
    for track in tracks.TRACKS:
        (root / track / "task05_fake").mkdir(parents=True)
        for name in ("a.txt", "b.txt", "d.txt"):
            (root / track / "task05_fake" / name).write_text("0\n")
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    for env in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV):
        monkeypatch.delenv(env, raising=False)
    tracks.set_track(None)
    return root


def _write(course: Path, **files: str) -> None:
    for name, text in files.items():
        (course / "exercises" / "task05_fake" / f"{name}.txt").write_text(text + "\n")


def _checks(rubric: Rubric) -> dict[str, object]:
    return {c.name: c for c in rubric.checks}


def test_one_cause_yields_a_hint_for_one_check_and_the_checks_built_on_it_name_it(course: Path) -> None:
    rubric = check(5, check_timeout=5.0)
    by = _checks(rubric)
    assert [c.name for c in rubric.checks if c.hint] == ["a"]
    assert by["a"].hint.startswith("a idea (hint 1 of 3")
    assert by["b"].blocked_by == "a" and by["b"].reason == "fails because a fails: fix that first"
    assert by["c"].blocked_by == "a", "a chain names its root: c waits for b, which waits for a"
    assert by["d"].blocked_by == "" and by["d"].hint == "" and by["d"].detail == "d.txt does not say 4"
    text = rubric.format()
    assert "b idea" not in text and "c idea" not in text and "d idea" not in text
    assert "why:  fails because a fails: fix that first" in text
    assert "Hints come one cause at a time: fix a first" in text
    data = json.loads(rubric.to_json())["checks"]
    blocked = next(c for c in data if c["name"] == "c")
    assert blocked["after"] == "a" and blocked["reason"] == "fails because a fails: fix that first"
    assert blocked["hint"] == ""


def test_once_the_cause_passes_the_next_one_holds_the_hint_from_its_first_level(course: Path) -> None:
    """b failed on every version before, but never showed its hint: it starts at its first level."""
    for text in ("0", "5", "6"):  # three versions on which a fails (its hint goes 1, 2, 3)
        _write(course, a=text)
        check(5, check_timeout=5.0)
    _write(course, a="1")
    by = _checks(check(5, check_timeout=5.0))
    assert by["a"].passed and by["b"].hint.startswith("b idea (hint 1 of 3")
    assert by["c"].blocked_by == "b" and by["c"].hint == "" and by["d"].hint == ""
    _write(course, b="7")  # b still fails on a new version: its own next level
    assert _checks(check(5, check_timeout=5.0))["b"].hint.startswith("b api (hint 2 of 3")


def test_changing_the_files_moves_only_the_hint_that_was_shown(course: Path) -> None:
    """The learner edits one file again and again: the hint shown goes deeper; the checks that showed none stay
    without one, and d, which never showed its hint, starts at its first level once it is the cause."""
    levels = []
    for text in ("0", "8", "9"):
        _write(course, a=text)
        levels.append(_checks(check(5, check_timeout=5.0))["a"].hint.split(" (")[0])
    assert levels == ["a idea", "a api", "a code"]
    _write(course, a="1", b="2")
    by = _checks(check(5, check_timeout=5.0))
    assert [c.name for c in by.values() if not c.passed] == ["d"]
    assert by["d"].hint.startswith("d idea (hint 1 of 3")


def test_checking_the_same_files_again_uses_up_no_hint(course: Path) -> None:
    _write(course, a="3")
    hints = [_checks(check(5, check_timeout=5.0))["a"].hint for _ in range(3)]
    assert hints[0] == hints[1] == hints[2] and hints[0].startswith("a idea (hint 1 of 3")


_HINTLESS = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.rubric import fail_without_hint


@graded(points=1, hint=("the answer is 1", "really 1", "write 1"))
def test_prediction():
    if (tracks.task_dir(5) / "a.txt").read_text().strip() == "0":
        fail_without_hint("a.txt: not predicted yet", note="a hint would answer it")
    assert False, "wrong prediction"


@graded(points=1, hint=("d idea", "d api", "d code"))
def test_d():
    assert (tracks.task_dir(5) / "d.txt").read_text().strip() == "4", "d.txt does not say 4"
'''


def test_a_failure_without_hint_shows_none_and_leaves_the_hint_to_the_next_cause(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_HINTLESS)
    by = _checks(check(5, check_timeout=5.0))
    assert by["prediction"].hint == "" and by["prediction"].detail == "a.txt: not predicted yet (a hint would answer it)"
    assert by["d"].hint.startswith("d idea")
    _write(course, a="2")  # predicted, wrong: now its hint may come
    assert _checks(check(5, check_timeout=5.0))["prediction"].hint.startswith("the answer is 1")


def test_an_after_that_names_no_check_of_the_grader_is_the_graders_error(course: Path) -> None:
    grader = course / "tests" / "tasks" / "test_task05_fake.py"
    grader.write_text(_CHAIN.replace('after=("b",)', 'after=("bee",)'))
    with pytest.raises(GradingError, match=r"names \['bee'\], which are not checks of this grader"):
        grade(5, track="exercises", check_timeout=5.0)


# ------------------------------------------------------------------------------------- the rules, without a grader


def _entry(name: str, passed: bool = False, after: tuple[str, ...] = (), hintless: bool = False) -> CheckEntry:
    return CheckEntry(name, name.split("[")[0], passed, ("1", "2", "3"), after, hintless)


def test_a_parametrized_check_waits_for_any_failed_case_of_the_check_it_builds_on() -> None:
    plan = plan_hints([_entry("base[x]", True), _entry("base[y]"), _entry("top", after=("base",))])
    assert plan.blocked == {"top": "base[y]"} and plan.cause == "base[y]"


def test_a_check_whose_after_checks_pass_is_judged_on_its_own() -> None:
    plan = plan_hints([_entry("base", True), _entry("top", after=("base",)), _entry("other")])
    assert plan.blocked == {} and plan.cause == "top" and plan.others == ["other"]


def test_a_cycle_of_afters_does_not_loop() -> None:
    plan = plan_hints([_entry("a", after=("b",)), _entry("b", after=("a",))])
    assert plan.blocked == {"a": "b", "b": "a"} and plan.cause == ""


@pytest.mark.parametrize(("log", "version", "level"), [
    ([], "v1", 0),
    ([{"version": "v1", "hints": {"x": 0}}], "v1", 0),  # the same files again
    ([{"version": "v1", "hints": {"x": 0}}], "v2", 1),  # shown on the previous version, still failing
    ([{"version": "v1", "hints": {"x": 2}}], "v2", 2),  # no level past the last
    ([{"version": "v1", "hints": {"x": 1}}, {"version": "v2", "hints": {"y": 0}}], "v3", 1),  # not shown last: kept
    ([{"version": "v1", "hints": {"x": 1}}, {"version": "v2", "hints": {}}], "v2", 1),
    ([{"version": "v1", "failed": ["x"]}, {"version": "v2", "failed": ["x"]}], "v3", 0),  # a log without hints
    ([{"version": "v1", "hints": {"x": 1}}], "", 0),  # not the learner's own grading
])
def test_hint_level_from_the_attempt_log(log: list[dict[str, object]], version: str, level: int) -> None:
    assert hint_level("x", 3, log, version) == level
