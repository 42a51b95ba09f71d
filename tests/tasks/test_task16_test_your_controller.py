"""Grader of task 16: the learner's pytest tests of the task-8 DisplacementController, scored by the wrong controllers
they catch.

The learner's ``test_displacement_controller.py`` is run (in a fresh pytest process, each test phase with a time limit)
once per controller, each handed to the tests as the fixture ``controller_class``:

* the library's reference controller, which is correct: every test must pass on it, or nothing else is judged (a
  test that fails on a correct controller expects what the task does not say, as the workshop's own test did);
* a controller that does nothing (:class:`~rrbot_workshop.testing.NullController`);
* the wrong controllers of ``task16_public_mutants.py`` and ``task16_mutants/`` (one rule of notebook 08 broken each).

Each wrong controller is a check worth one point, passed when at least one test catches it: the test passes on the
correct controller, ran a check there (an ``assert`` that held, or ``pytest.raises``), and fails on the wrong one; a
test that passes on the do-nothing controller too must fail by a failed check, not because the code raised. The score
is the share of wrong controllers caught. A wrong controller that no test catches is reported by the rule it breaks.

A student copy of the course has no ``task16_mutants/`` (the export leaves it out): there the three public wrong
controllers are graded, and a check marked GIVEN says that the others are graded in the instructor's copy. A copy
that withholds the library's reference controller cannot grade this task: every check is GIVEN.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import task16_public_mutants as wrong_controllers

from rrbot_workshop.course.controller_tests import NOTHING, TestRuns, run_tests
from rrbot_workshop.course.grading import graded
from rrbot_workshop.course.grading.references import WITHHELD_SKIP, is_withheld, reference_or_skip

TASK = 16
FILE = "test_displacement_controller.py"
REFERENCE = "rrbot_workshop.controllers.displacement"
CORRECT = "correct"
HERE = Path(__file__).resolve().parent
GATE = "tests_pass_on_a_correct_controller"

try:  # the hidden wrong controllers register themselves
    import task16_mutants  # noqa: F401
    HIDDEN = True
except ModuleNotFoundError as exc:
    if exc.name != "task16_mutants":
        raise
    HIDDEN = False

WRONG = list({w.id: w for w in wrong_controllers.REGISTRY}.values())


@pytest.fixture(scope="module")
def runs(task_file: Callable[[int, str], Path]) -> TestRuns:
    """The learner's tests, run on the correct controller, the do-nothing one and every wrong one."""
    reference_or_skip(REFERENCE)
    path = task_file(TASK, FILE)
    against = {CORRECT: f"{REFERENCE}:DisplacementController", NOTHING: NOTHING, **{w.id: w.spec for w in WRONG}}
    return run_tests(path, against, paths=[HERE], timeout=2.0, total_timeout=120.0)


def _names(tests: list[str]) -> str:
    return ", ".join(tests[:-1]) + f" and {tests[-1]}" if len(tests) > 1 else tests[0]


def _not_runnable(runs: TestRuns) -> str:
    """Why the learner's tests cannot be judged at all ("" if they can)."""
    if runs.errors:
        return f"your {FILE} could not run: {'; '.join(runs.errors)}"
    if CORRECT in runs.load_errors:
        return f"the correct controller could not be loaded: {runs.load_errors[CORRECT]}"
    if not runs.tests:
        return (f"your {FILE} has no tests yet: pytest runs the functions whose names start with test_; write one per "
                "rule of notebook 08, each taking the fixture controller_class")
    return ""


def _failing_on_correct(runs: TestRuns) -> str:
    """The tests that fail on the correct controller, each with its line and why ("" if none)."""
    found = runs.failing_on(CORRECT)
    if not found:
        return ""
    said = "; ".join(f"{o.test} {'was skipped' if o.outcome == 'skipped' else 'fails'}: {o.why()}" for o in found)
    one = len(found) == 1
    return (f"{len(found)} of your tests do{'es' if one else ''} not pass on a correct controller, so "
            f"{'it expects' if one else 'they expect'} something the task does not say: {said}")


# --------------------------------------------------------------------------------------------- the tests themselves


@graded(given=True, points=1, hint=(
    "Task 16: a test states a rule of notebook 08, and a correct controller keeps every rule, so every test must pass "
    "on it. One that fails there expects what the task does not say, as the workshop's own test expected the "
    "displacement alone; until every test passes on a correct controller, none is scored.",
    "Run your tests on your own finished task-8 controller: pytest exercises/task16_test_your_controller -q (or the "
    "cell of notebook 16); each failure names its line. Compare what it expects with the rule in notebook 08; compare "
    "sums of floats with pytest.approx.",
    "assert h.values(['joint1/position', 'joint2/position']) == pytest.approx([1.1 + 0.5, 2.2 - 0.25])  # the "
    "states 1.1 and 2.2, plus the displacements; approx, as sums of floats are not always exact (0.1 + 0.2 != 0.3)",
))
def test_tests_pass_on_a_correct_controller(runs: TestRuns) -> None:
    problem = _not_runnable(runs) or _failing_on_correct(runs)
    if problem:
        pytest.fail(problem, pytrace=False)


@graded(given=True, points=1, hint=(
    "Task 16: a test earns its points by failing on a wrong controller with a failed check: an assert (or "
    "pytest.raises) that a correct controller satisfies. A test that only runs the controller, or asserts what a "
    "controller that does nothing satisfies too, shows only that nothing raised.",
    "assert what the rule says must happen (h.values, h.latest('~/state'), h.configure() is State.UNCONFIGURED, "
    "math.isnan, caplog.records), or with pytest.raises(ParameterError) for what loading must refuse; each test takes "
    "controller_class, itself or through a fixture of yours.",
    "h.update()  # this line checks nothing\nassert h.values(['joint1/position']) == pytest.approx([1.1 + 0.5])  # "
    "this one checks a rule",
))
def test_every_test_checks_something(runs: TestRuns) -> None:
    problem = _not_runnable(runs)
    if problem:
        pytest.fail(problem, pytrace=False)
    said = []
    for test in runs.without_fixture():
        said.append(f"{test} does not take the fixture controller_class, so it always tests the same controller and "
                    "cannot catch a wrong one")
    for outcome in runs.checks_nothing(CORRECT):
        if outcome.asserts:
            said.append(f"{outcome.test} ran no check on a correct controller: its asserts are in code that did not "
                        "run")
        else:
            said.append(f"{outcome.test} checks nothing: it has no assert and no pytest.raises, so it can fail only "
                        "when the code raises")
    if HIDDEN:  # with every wrong controller here, a test that catches none of them checks nothing they break
        catching = {t for w in WRONG for t in runs.catchers(w.id, CORRECT, NOTHING)}
        vacuous = {o.test for o in runs.checks_nothing(CORRECT)} | set(runs.without_fixture())
        for test in runs.tests:
            idle = runs.outcome(test, NOTHING)
            if test not in catching | vacuous and idle is not None and idle.passed:
                said.append(f"{test} catches no wrong controller and passes on a controller that does nothing at all "
                            "(every method succeeds, nothing moves): it cannot tell a controller that works from one "
                            "that does nothing")
    if said:
        pytest.fail("these tests earn nothing: " + "; ".join(said), pytrace=False)


# --------------------------------------------------------------------------------------------- one check per rule


def _judge(runs: TestRuns, wrong: wrong_controllers.WrongController) -> None:
    problem = _not_runnable(runs)
    if problem:
        pytest.fail(problem, pytrace=False)
    if runs.failing_on(CORRECT):
        pytest.fail(f"not judged yet: first make every test pass on a correct controller (see {GATE})",
                    pytrace=False)
    if wrong.id in runs.load_errors:
        pytest.fail(f"the grader's wrong controller could not be loaded: {runs.load_errors[wrong.id]}", pytrace=False)
    if runs.catchers(wrong.id, CORRECT, NOTHING):
        return
    reason = f"a controller that breaks this rule passes all your tests: {wrong.rule}"
    raised = runs.raised_only(wrong.id, CORRECT, NOTHING)
    if raised:
        reason += (f" ({_names([o.test for o in raised])} fail{'s' if len(raised) == 1 else ''} on it only because the "
                   f"code raised ({raised[0].message}), and pass{'es' if len(raised) == 1 else ''} on a controller that "
                   "does nothing: that shows an exception, not the rule; assert the rule)")
    elif runs.tests and len(runs.checks_nothing(CORRECT)) + len(runs.without_fixture()) == len(runs.tests):
        reason += " (none of your tests checks anything: see every_test_checks_something)"
    pytest.fail(reason, pytrace=False)


def _check(wrong: wrong_controllers.WrongController) -> Callable[[TestRuns], None]:
    def check(runs: TestRuns) -> None:
        _judge(runs, wrong)

    check.__name__ = check.__qualname__ = f"test_{wrong.id}"
    check.__doc__ = f"Some test fails on a controller that breaks the rule: {wrong.rule}."
    return graded(points=1, hint=wrong.hints, after=(GATE,))(check)


for _wrong in WRONG:
    globals()[f"test_{_wrong.id}"] = _check(_wrong)


if not HIDDEN:
    @graded(given=True, points=1, hint=(
        "Task 16: this copy of the course holds the public wrong controllers only; the instructor's copy grades the "
        "others, one per rule of notebook 08.",
        "Test every rule of notebook 08, not only the ones the public wrong controllers break.",
        "def test_a_refused_message_changes_nothing(controller_class): ...  # one test per rule, as for the public ones",
    ))
    def test_hidden_wrong_controllers() -> None:
        if is_withheld(REFERENCE):
            reference_or_skip(REFERENCE)
        pytest.skip(f"{WITHHELD_SKIP} this copy of the course leaves out the grader's other wrong controllers (one per "
                    "rule of notebook 08); your instructor's copy grades your tests on them too")
