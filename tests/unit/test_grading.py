"""The grading framework: weighted checks, the rubric, the pytest plugin and the subprocess runner."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import CheckResult, Rubric, check, grade, graded, graded_tasks, grader_path
from rrbot_workshop.course.grading.pytest_process import warm_up
from rrbot_workshop.course.grading.rubric import DEFAULT_POINTS, check_spec
from rrbot_workshop.exceptions import CourseError, GradingError


@pytest.fixture(scope="module", autouse=True)
def _fork_server() -> None:
    """The module's gradings are forked from one process that has imported what graders use (waited for once): each
    would otherwise be a new Python process importing pytest, numpy, MuJoCo and the library again."""
    warm_up(wait=True)


_GRADER = '''
import pytest
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


@pytest.fixture
def broken():
    raise RuntimeError("fixture broke")


@graded(points=2, hint="always fine")
def test_passes():
    assert (tracks.task_dir(5) / "answer.txt").read_text().strip() == "42"


@graded(points=3, hint="the answer is 43")
def test_fails():
    assert 1 == 2, "one is not two"


@graded(points=1, hint="loops forever")
def test_endless_loop():
    while True:
        try:
            pass
        except Exception:
            pass


@graded(points=1, hint="needs the fixture")
def test_setup_error(broken):
    pass


@graded(points=1, hint="skipped")
def test_skipped():
    pytest.skip("not today")


def test_undecorated():
    """Plain tests count one point."""
    assert True
'''


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A tiny course with one task (5) whose grader has passing, failing, looping and erroring checks."""
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER)
    for track in tracks.TRACKS:
        (root / track / "task05_fake").mkdir(parents=True)
        (root / track / "task05_fake" / "answer.txt").write_text("42\n" if track == "solutions" else "?\n")
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    monkeypatch.delenv(tracks.TRACK_ENV, raising=False)
    monkeypatch.delenv(tracks.TASK_ROOT_ENV, raising=False)
    monkeypatch.delenv(tracks.EXERCISES_ENV, raising=False)
    tracks.set_track(None)
    return root


@pytest.fixture(scope="module")
def solved(tmp_path_factory: pytest.TempPathFactory) -> Rubric:
    """The fake grader run once on the solutions track (shared: each run is a subprocess)."""
    root = tmp_path_factory.mktemp("solved") / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    (root / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER)
    (root / "solutions" / "task05_fake").mkdir(parents=True)
    (root / "solutions" / "task05_fake" / "answer.txt").write_text("42\n")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tracks.ROOT_ENV, str(root))
        mp.delenv(tracks.TASK_ROOT_ENV, raising=False)
        mp.delenv(tracks.EXERCISES_ENV, raising=False)
        return grade(5, track="solutions", check_timeout=1.0)


# ------------------------------------------------------------------------------------------- decorator, rubric


def test_graded_attaches_points_and_hint() -> None:
    @graded(points=2.5, hint="read the spec")
    def test_x() -> None: ...

    spec = check_spec(test_x)
    assert (spec.points, spec.hint) == (2.5, "read the spec")


def test_undecorated_test_is_worth_default_points_with_docstring_hint() -> None:
    def test_y() -> None:
        """First line.

        More.
        """

    assert check_spec(test_y).points == DEFAULT_POINTS
    assert check_spec(test_y).hint == "First line."


@pytest.mark.parametrize("points", [0, -1])
def test_graded_rejects_non_positive_points(points: float) -> None:
    with pytest.raises(ValueError, match="more than 0 points"):
        graded(points=points)


def test_rubric_json_has_exactly_the_documented_keys() -> None:
    rubric = Rubric(task=3, checks=[CheckResult("a", 2, True), CheckResult("b", 3, False, hint="h", detail="d")])
    data = json.loads(rubric.to_json())
    assert data == {
        "task": 3,
        "score": 2,
        "max_score": 5,
        "checks": [
            {"name": "a", "points": 2, "max_points": 2, "passed": True, "given": False, "hint": "", "reason": ""},
            {"name": "b", "points": 0.0, "max_points": 3, "passed": False, "given": False, "hint": "h", "reason": "d"},
        ],
    }


def test_rubric_text_shows_hint_and_why_only_for_failures() -> None:
    rubric = Rubric(task=3, title="task03_x", checks=[
        CheckResult("good", 1, True), CheckResult("bad", 2, False, hint="do this", detail="because"),
    ])
    text = rubric.format()
    assert "PASS  1/1  good" in text and "FAIL  0/2  bad" in text
    assert "hint: do this" in text and "why:  because" in text
    assert text.count("hint:") == 1
    assert text.splitlines()[-1] == "Total: 1/3 points"


def test_rubric_complete_only_when_every_check_passed() -> None:
    assert Rubric(1, [CheckResult("a", 1, True)]).complete
    assert not Rubric(1, [CheckResult("a", 1, True), CheckResult("b", 1, False)]).complete
    assert not Rubric(1, []).complete


# ------------------------------------------------------------------------------------------- runner + plugin


def test_passing_check_earns_its_points(solved: Rubric) -> None:
    by_name = {c.name: c for c in solved.checks}
    assert by_name["passes"].passed and by_name["passes"].points == 2


def test_failing_check_keeps_hint_and_assertion_message(solved: Rubric) -> None:
    failed = {c.name: c for c in solved.checks}["fails"]
    assert (failed.passed, failed.points, failed.hint) == (False, 0.0, "the answer is 43")
    assert failed.detail == "one is not two"


def test_endless_loop_fails_its_check_and_grading_goes_on(solved: Rubric) -> None:
    """The per-check time limit interrupts a loop that even swallows Exception; later checks still run."""
    loop = {c.name: c for c in solved.checks}["endless_loop"]
    assert not loop.passed and "CheckTimeout" in loop.detail
    assert {c.name: c for c in solved.checks}["undecorated"].passed


def test_fixture_error_and_skip_count_as_failures(solved: Rubric) -> None:
    by_name = {c.name: c for c in solved.checks}
    assert not by_name["setup_error"].passed and "fixture broke" in by_name["setup_error"].detail
    assert not by_name["skipped"].passed and "not today" in by_name["skipped"].detail


def test_rubric_totals_and_order_follow_the_grader_file(solved: Rubric) -> None:
    assert [c.name for c in solved.checks] == [
        "passes", "fails", "endless_loop", "setup_error", "skipped", "undecorated"
    ]
    assert (solved.score, solved.max_score) == (3, 9)
    assert solved.track == "solutions" and solved.title == "task05_fake"


def test_exercises_track_is_graded_by_default(course: Path) -> None:
    rubric = check(5, check_timeout=0.5)
    assert not {c.name: c for c in rubric.checks}["passes"].passed


def test_task_root_grades_a_copy(course: Path, tmp_path: Path) -> None:
    """A folder of taskNN_* folders given as task_root is graded instead of the track's."""
    copy = tmp_path / "upload" / "task05_fake"
    copy.mkdir(parents=True)
    (copy / "answer.txt").write_text("42")
    rubric = grade(5, task_root=copy.parent, check_timeout=0.5)
    assert {c.name: c for c in rubric.checks}["passes"].passed


def test_whole_grader_time_limit_marks_unfinished_checks(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(
        "import time\n\ndef test_first():\n    assert True\n\ndef test_hangs():\n    while True:\n"
        "        time.sleep(0.05)\n\ndef test_never_reached():\n    pass\n"
    )
    # the grader's process must start and collect within the limit however busy the machine; the hang costs no CPU
    rubric = grade(5, check_timeout=0, total_timeout=15.0)
    outcome = {c.name: (c.passed, c.detail) for c in rubric.checks}
    assert list(outcome) == ["first", "hangs", "never_reached"]
    assert not outcome["hangs"][0] and "stopped after 15 s" in outcome["hangs"][1]
    assert not outcome["never_reached"][0]


def test_grading_freezes_what_it_inherited_and_still_collects_what_it_makes(course: Path) -> None:
    """The plugin hides the objects alive at configure from the garbage collector (its walks cost a quarter of a short
    grading); a cycle a check makes is still collected."""
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(
        "import gc\nimport weakref\n\nclass Node:\n    pass\n\n"
        "def test_inherited_objects_are_frozen():\n    assert gc.get_freeze_count() > 1000\n\n"
        "def test_a_new_cycle_is_collected():\n    node = Node()\n    node.me = node\n    ref = weakref.ref(node)\n"
        "    del node\n    gc.collect()\n    assert ref() is None\n"
    )
    rubric = grade(5, track="solutions", check_timeout=5.0)
    assert [(c.name, c.passed, c.detail) for c in rubric.checks] == [
        ("inherited_objects_are_frozen", True, ""), ("a_new_cycle_is_collected", True, "")]


def test_grader_rewritten_once_into_the_named_folder_and_read_by_the_next_grading(
        course: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """With ``$RRBOT_WORKSHOP_GRADER_PYCACHE`` naming a folder, the first grading keeps the grader's rewritten bytecode
    there (nothing in the course) and the next one reads it instead of rewriting it."""
    from rrbot_workshop.course.grading.plugin import PYCACHE_ENV

    folder = tmp_path / "pycache"
    monkeypatch.setenv(PYCACHE_ENV, str(folder))
    first = grade(5, track="solutions", check_timeout=5.0)
    (kept,) = folder.rglob("test_task05_fake.*pytest*.pyc")
    written = kept.stat()
    second = grade(5, track="solutions", check_timeout=5.0)
    assert [(c.name, c.passed) for c in second.checks] == [(c.name, c.passed) for c in first.checks]
    assert (kept.stat().st_ino, kept.stat().st_mtime_ns) == (written.st_ino, written.st_mtime_ns), "rewritten again"
    assert not list(course.rglob("__pycache__"))


def test_grader_that_cannot_be_collected_raises_grading_error(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text("def broken(:\n")
    with pytest.raises(GradingError, match="could not be collected"):
        grade(5)


def test_grader_without_checks_raises_grading_error(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text("X = 1\n")
    with pytest.raises(GradingError, match="has no checks"):
        grade(5)


def test_unknown_task_lists_tasks_with_a_grader(course: Path) -> None:
    with pytest.raises(CourseError, match="task05_fake") as info:
        grader_path(7)
    assert info.value.what == "task" and info.value.value == 7


def test_grading_a_missing_track_folder_is_a_course_error(course: Path) -> None:
    import shutil

    shutil.rmtree(course / "solutions")
    with pytest.raises(CourseError, match="no 'solutions/' folder"):
        grade(5, track="solutions")


def test_unknown_track_is_a_course_error(course: Path) -> None:
    with pytest.raises(CourseError, match="unknown course track 'answers'"):
        grade(5, track="answers")


def test_graded_tasks_lists_grader_files(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task12_tips.py").write_text("def test_a():\n    pass\n")
    (course / "tests" / "tasks" / "helpers.py").write_text("")
    assert graded_tasks() == [5, 12]


def test_grader_writes_no_bytecode_into_the_course(course: Path) -> None:
    grade(5, track="solutions", check_timeout=0.5)
    assert not list(course.rglob("__pycache__")) and not (course / ".pytest_cache").exists()


def test_real_course_has_a_task01_grader() -> None:
    """The repository's own task-1 grader is found without any registration."""
    assert grader_path(1).name == "test_task01_description.py"


def test_failure_reason_keeps_the_reasons_listed_after_a_colon() -> None:
    """A SwitchError's reasons (listed under its first line) reach the rubric's 'why' line."""
    from rrbot_workshop.course.grading.plugin import _first_line
    from rrbot_workshop.exceptions import SwitchError

    text = _first_line(str(SwitchError(["'a' claims joint1/position", "'b' claims joint1/position"])))
    assert "'a' claims joint1/position" in text and "'b' claims joint1/position" in text
    assert _first_line("a\n  b") == "a b"


@pytest.mark.parametrize(("message", "reason"), [
    ("expected 1\nassert 0 == 1", "expected 1"),
    ("joint1 at 0.3 rad, expected 0.5 rad\nassert 0.3 == 0.5 ± 5.0e-07\n  +  where 0.3 = f()", "joint1 at 0.3 rad, expected 0.5 rad"),
    ("a long reason " + "x" * 400 + " that ends here", "a long reason " + "x" * 400 + " that ends here"),
    ("switch rejected, no controller changed state:\n  'a' holds joint1/position", "switch rejected, no controller changed state: 'a' holds joint1/position"),
])
def test_a_reason_is_the_graders_whole_message_without_pytests_expression(message: str, reason: str) -> None:
    from rrbot_workshop.course.grading.plugin import _describe

    assert _describe(AssertionError(message)) == reason


def test_one_reason_for_checks_that_fail_for_the_same_reason_and_given_checks_score_nothing() -> None:
    """A file that does not parse fails every check with one error: it is reported once; given checks (what the
    handed-out exercise already satisfies) are shown but neither earn nor cost points."""
    rubric = Rubric(task=3, checks=[
        CheckResult("parses", 1, False, detail="malformed XML at line 3", given=True),
        CheckResult("a", 2, False, detail="malformed XML at line 3"),
        CheckResult("b", 2, False, detail="malformed XML at line 3"),
        CheckResult("free", 1, True, given=True),
    ])
    text = rubric.format()
    assert text.count("malformed XML at line 3") == 1 and "the same as for parses above" in text
    data = json.loads(rubric.to_json())
    assert [c.get("same_as") for c in data["checks"]] == [None, "parses", "parses", None]
    assert (rubric.score, rubric.max_score) == (0, 4)
    assert "GIVEN" in text


# ------------------------------------------------------------------------------- graduated hints, attempt log

_GRADER_GRADUATED = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


@graded(points=2, hint=("the concept", "the API", "the code"))
def test_answer():
    assert (tracks.task_dir(5) / "answer.txt").read_text().strip() == "42", "not 42 yet"


@graded(points=1, hint="one level only")
def test_other():
    assert False, "never"
'''


def test_graduated_hints_go_one_level_deeper_per_new_failing_version_and_the_log_records_them(course: Path) -> None:
    """Checking the same files again (a re-run self-check cell) keeps the hint; each changed, still failing version of
    the learner's files shows the next level."""
    from rrbot_workshop.course.grading import attempts

    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_GRADUATED)
    answer_file = course / "exercises" / "task05_fake" / "answer.txt"
    seen = []
    for text in ("?", "?", "41", "41", "40", "39"):
        answer_file.write_text(text + "\n")
        answer = {c.name: c for c in check(5, check_timeout=2.0).checks}["answer"]
        seen.append(answer.hint)
    assert seen[0] == seen[1] and seen[0].startswith("the concept (hint 1 of 3; change your files and check again")
    assert seen[2] == seen[3] and seen[2].startswith("the API (hint 2 of 3")
    assert seen[4] == seen[5] == "the code (hint 3 of 3)"
    log = attempts.load(5)["attempts"]
    assert len(log) == 6 and all(a["failed"] == ["answer", "other"] and a["score"] == 0 for a in log)
    assert len({a["version"] for a in log}) == 4
    assert (course / "exercises" / ".progress" / "task05.json").is_file()
    answer_file.write_text("42\n")
    check(5, check_timeout=2.0)
    summary = attempts.summary(5)
    assert summary["attempts"] == 7 and summary["passed"] is False  # 'other' still fails: not a full score
    assert attempts.failures(5, "answer") == 6
    answer_file.write_text("43\n")  # wrong again after being right: the hint goes on from where it was
    answer = {c.name: c for c in check(5, check_timeout=2.0).checks}["answer"]
    assert answer.hint == "the code (hint 3 of 3)"


def test_the_first_hint_stays_while_the_handed_out_file_is_unchanged(course: Path) -> None:
    """A notebook's self-check cell run many times on the untouched exercise never moves past the first hint."""
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_GRADUATED)
    hints = {c.name: c for c in check(5, check_timeout=2.0).checks}["answer"].hint
    for _ in range(2):
        assert {c.name: c for c in check(5, check_timeout=2.0).checks}["answer"].hint == hints
    assert hints.startswith("the concept (hint 1 of 3")


def test_files_version_follows_contents_and_names_not_caches(tmp_path: Path) -> None:
    from rrbot_workshop.course.grading.attempts import files_version

    (tmp_path / "a.py").write_text("x = 1\n")
    first = files_version(tmp_path)
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "__pycache__" / "a.cpython-311.pyc").write_bytes(b"\0")
    assert files_version(tmp_path) == first
    (tmp_path / "a.py").write_text("x = 2\n")
    assert files_version(tmp_path) != first
    (tmp_path / "a.py").write_text("x = 1\n")
    assert files_version(tmp_path) == first
    (tmp_path / "a.py").rename(tmp_path / "b.py")
    assert files_version(tmp_path) != first


def test_progress_does_not_count_as_an_attempt_and_reports_the_log(course: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rrbot_workshop.cli import main
    from rrbot_workshop.course.grading import attempts

    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_GRADUATED.replace("assert False", "assert True"))
    attempts.record(5, 0.0, 3.0, ["answer"], now=1000.0)
    (course / "exercises" / "task05_fake" / "answer.txt").write_text("42\n")
    attempts.record(5, 3.0, 3.0, [], now=1095.0)
    assert main(["progress", "--json", "--timeout", "2"]) == 0
    report = json.loads(capsys.readouterr().out)
    task = next(t for t in report["tasks"] if t["task"] == 5)
    assert task["attempts"] == {"attempts": 2, "passed": True, "time_to_pass_s": 95.0}
    assert len(attempts.load(5)["attempts"]) == 2


def test_no_attempt_log_for_the_solutions_track_a_copy_or_when_switched_off(
    course: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rrbot_workshop.course.grading import attempts

    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_GRADUATED)
    grade(5, track="solutions", check_timeout=2.0)
    grade(5, task_root=course / "exercises", check_timeout=2.0)
    monkeypatch.setenv(attempts.ENV, "0")
    hint = {c.name: c for c in check(5, check_timeout=2.0).checks}["answer"].hint
    assert hint.startswith("the concept (hint 1 of 3")
    assert not (course / "exercises" / ".progress").exists()


def test_an_unreadable_attempt_log_is_an_empty_one(course: Path) -> None:
    from rrbot_workshop.course.grading import attempts

    path = attempts.log_path(5)
    path.parent.mkdir(parents=True)
    path.write_text("{not json")
    assert attempts.load(5) == {"attempts": []} and attempts.summary(5)["attempts"] == 0
    attempts.record(5, 1.0, 2.0, ["x"])
    assert attempts.failures(5, "x") == 1


# ------------------------------------------------------------------------------- the learner's error first

_GRADER_LEARNER_CODE = '''
import logging

import rrbot_workshop as rw
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


def _module():
    module = rw.course.load_module(5, "code.py", quiet=True)
    assert module is not None, "code.py does not import"
    return module


@graded(points=1, hint=("idea", "api", "code"))
def test_direct():
    assert _module().answer() == 42, "answer() must return 42"


@graded(points=1, hint=("idea", "api", "code"))
def test_caught_by_the_library():
    module = _module()
    try:
        module.answer()
    except Exception:
        logging.getLogger("rrbot_workshop.fake").error("answer() raised; treated as ERROR", exc_info=True)
    assert False, "the switch was rejected"
'''


@pytest.mark.parametrize(("code", "direct", "caught"), [
    ("def answer():\n    return {}['x']\n",
     "your code.py, line 2, in answer: KeyError: 'x'",
     "your code.py, line 2, in answer: KeyError: 'x'; then: the switch was rejected"),
    ("def answer():\n    return helper(\n\ndef helper():\n    pass\n",
     "your code.py, line 2: SyntaxError: '(' was never closed; then: code.py does not import",
     "your code.py, line 2: SyntaxError: '(' was never closed; then: code.py does not import"),
])
def test_a_failure_caused_by_the_learners_code_names_their_file_line_function_and_exception_first(
    course: Path, code: str, direct: str, caught: str
) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_LEARNER_CODE)
    (course / "exercises" / "task05_fake" / "code.py").write_text(code)
    checks = {c.name: c for c in grade(5, check_timeout=5.0, record=False).checks}
    assert checks["direct"].detail == direct
    caught_check = checks["caught_by_the_library"]
    # a reason equal to an earlier check's is given once ('same_as')
    assert caught_check.detail == caught and (caught_check.same_as == "direct") == (caught == direct)


def test_a_grader_failure_without_learner_code_involved_keeps_the_graders_words(course: Path) -> None:
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_LEARNER_CODE)
    (course / "exercises" / "task05_fake" / "code.py").write_text("def answer():\n    return 41\n")
    checks = {c.name: c for c in grade(5, check_timeout=5.0, record=False).checks}
    assert checks["direct"].detail == "answer() must return 42"
    assert checks["caught_by_the_library"].detail == "the switch was rejected"


_GRADER_SHARED_FIXTURE = '''
import logging

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course.grading import graded


def _answer():
    module = rw.course.load_module(5, "code.py", quiet=True)
    try:
        return module.answer()
    except Exception:
        logging.getLogger("rrbot_workshop.fake").error("answer() raised; treated as ERROR", exc_info=True)
        return None


@pytest.fixture(scope=SCOPE)
def answer():
    return _answer()


@graded(points=1, hint=("idea", "api", "code"))
def test_first(answer):
    assert answer == 42, "the system did not come up"


@graded(points=1, hint=("idea", "api", "code"))
def test_second(answer):
    assert answer == 42, "the second check found no system either"


@graded(points=1, hint=("idea", "api", "code"))
def test_unrelated():
    assert False, "an unrelated rule is broken"
'''


@pytest.mark.parametrize("scope", ["module", "function"])
def test_a_learner_error_met_by_a_shared_fixture_leads_the_checks_it_served_and_no_others(
    course: Path, scope: str
) -> None:
    """A module-scoped fixture set up once (in the first check) met the learner's error: the second check, given what
    it left, names it too; a check that does not use it keeps its own reason, whatever the fixture's scope."""
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(_GRADER_SHARED_FIXTURE.replace("SCOPE", repr(scope)))
    (course / "exercises" / "task05_fake" / "code.py").write_text("def answer():\n    return 1 / 0\n")
    checks = {c.name: c for c in grade(5, check_timeout=5.0, record=False).checks}
    learner = "your code.py, line 2, in answer: ZeroDivisionError: division by zero"
    assert checks["first"].detail == f"{learner}; then: the system did not come up"
    assert checks["second"].detail == f"{learner}; then: the second check found no system either"
    assert checks["unrelated"].detail == "an unrelated rule is broken"


def test_hypothesis_draws_constants_from_the_learners_files_not_the_librarys(course: Path) -> None:
    """Installed from a folder the library would be local code to Hypothesis; in a grading it never is."""
    (course / "exercises" / "task05_fake" / "mine.py").write_text("ANSWER = 41\n")
    (course / "tests" / "tasks" / "test_task05_fake.py").write_text(
        "import rrbot_workshop.bringup\nfrom hypothesis.internal.constants_ast import is_local_module_file\n"
        "from rrbot_workshop.course import tracks\n\n\ndef test_library_is_not_local():\n"
        "    assert not is_local_module_file(rrbot_workshop.bringup.__file__)\n\n\n"
        "def test_learners_file_is_local():\n"
        "    assert is_local_module_file(str(tracks.task_dir(5) / 'mine.py'))\n")
    rubric = grade(5, check_timeout=30.0, record=False)
    assert [(c.name, c.passed) for c in rubric.checks] == [("library_is_not_local", True),
                                                          ("learners_file_is_local", True)]


def test_first_failure_names_the_first_check_that_fails_and_nothing_when_all_pass() -> None:
    """The text of the first AssertionError, in the order the checks are given; "" when none fails; other errors
    are not a check's verdict and reach the caller."""
    from rrbot_workshop.course.grading import first_failure

    calls: list[str] = []

    def ok(value: int) -> None:
        calls.append(f"ok {value}")

    def too_small(value: int) -> None:
        calls.append(f"too_small {value}")
        if value <= 5:  # raised, not asserted: pytest's rewriting would add the compared values to the text
            raise AssertionError(f"{value} is not above 5")

    def never(value: int) -> None:
        raise AssertionError("not reached")

    assert first_failure((ok, too_small, never), 3) == "3 is not above 5"
    assert calls == ["ok 3", "too_small 3"]
    assert first_failure((ok, too_small), 9) == ""

    def broken(value: int) -> None:
        raise KeyError(value)

    with pytest.raises(KeyError):
        first_failure((broken,), 1)
