"""The task-16 grader on test files written as learners write them: each gets the share of wrong controllers it
catches, and the reasons name the rules it let through.

Each learner's file is the handed-out exercise with tests added (what a learner does); the rules a file's tests catch
are worked out from what each test sets up (the comments say why), not read off a run. Grading runs as a learner's
does: ``grade(16, task_root=...)`` in a subprocess.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from grader_variants import Variant, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.controller_tests import run_tests
from rrbot_workshop.course.grading import Rubric, grade

ROOT = tracks.course_root()
GRADERS = ROOT / "tests" / "tasks"
HAS_SOLUTIONS = (ROOT / "solutions").is_dir()
HAS_HIDDEN = (GRADERS / "task16_mutants").is_dir()
pytestmark = pytest.mark.skipif(not (HAS_SOLUTIONS and HAS_HIDDEN),
                                reason="this copy of the course has no solutions/ or no hidden wrong controllers")

FILE = "test_displacement_controller.py"
EXERCISE = (ROOT / "exercises" / "task16_test_your_controller" / FILE).read_text() if HAS_SOLUTIONS else ""
GATE, INFO = "tests_pass_on_a_correct_controller", "every_test_checks_something"


def _wrong_controllers() -> dict[str, object]:
    sys.path.insert(0, str(GRADERS))
    try:
        import task16_mutants  # noqa: F401 - registers the hidden ones
        import task16_public_mutants
    finally:
        sys.path.remove(str(GRADERS))
    return {w.id: w for w in task16_public_mutants.REGISTRY}


WRONG = _wrong_controllers() if HAS_HIDDEN else {}


def learner(tests: str) -> str:
    return EXERCISE + "\n" + tests.strip("\n") + "\n"


ASSERTS_NOTHING = learner('''
def test_configure(controller_class):
    h = make_harness(controller_class)
    h.configure()
    h.activate()


def test_a_jog_runs(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.1, 0.1]))
    h.update()
    h.latest("~/state").set_point


def test_effort_is_accepted(controller_class):
    make_harness(controller_class, interface="effort").configure()
''')

# The notebook's rules first: the arithmetic (states 1.1 and 2.2, so only a controller that adds them passes), slow
# mode (halved: only a controller that reads the mode in update, and adds the state, passes), NaN on both joints.
FIRST_TESTS = learner('''
def test_command_is_state_plus_displacement(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.5]))
    assert h.update() is ReturnType.OK
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.6, 2.7])


def test_slow_mode_halves(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.bus.call_service(f"/{h.name}/set_slow_control_mode", SetBoolRequest(data=True))
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[1.0, 1.0]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.6, 2.7])


def test_nan_after_deactivation(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.deactivate()
    assert all(math.isnan(v) for v in h.values(["joint1/position", "joint2/position"]))
''')
FIRST_CATCHES = {"command_is_state_plus_displacement", "slow_mode_halves", "nan_on_deactivate",
                 "nan_on_every_command"}  # NaN checked on both joints: the controller that writes only the first fails

# Messages: joints named out of order (also catches the controller that forgets the state: the values differ), a
# message for one joint (refused: the controller that takes some joints moves joint1), two messages before an update.
MESSAGE_TESTS = learner('''
def test_matched_by_name(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint2", "joint1"], displacements=[1.0, 10.0]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([11.1, 3.2])


def test_one_joint_is_not_enough(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1"], displacements=[5.0]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == [0.0, 0.0]


def test_the_last_message_wins(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.5]))
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.3, -0.2]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.4, 2.0])
''')
MESSAGE_CATCHES = {"matched_by_name", "command_is_state_plus_displacement", "wrong_joint_count_refused",
                   "newer_message_replaces_the_pending_one"}

# The workshop's own test: it expects the displacement alone, so it fails on a correct controller and nothing is scored.
ORIGINAL = learner('''
def test_update_logic_fast(controller_class):
    h = ControllerHarness(controller_class(), "test_displacement_controller",
                          {"joints": ["joint1"], "interface_name": "acceleration"},
                          state_values={"joint1/acceleration": 1.1}, command_values={"joint1/acceleration": 101.101})
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1"], displacements=[23.24]))
    assert h.update() is ReturnType.OK
    assert h.value("joint1/acceleration") == 23.24


def test_command_is_state_plus_displacement(controller_class):
    h = make_harness(controller_class)
    h.configure(); h.activate()
    h.publish("~/reference", JointJog(joint_names=["joint1", "joint2"], displacements=[0.5, 0.5]))
    h.update()
    assert h.values(["joint1/position", "joint2/position"]) == pytest.approx([1.6, 2.7])
''')

# Asserts that hold on any controller that does not raise: the controller that claims the RRBot's joints makes
# activation raise, which shows an exception, not the rule; the test that builds the library's class itself tests it
# whatever the grader hands over.
RAISES_ONLY = learner('''
from rrbot_workshop.controllers.displacement import DisplacementController


def test_three_velocity_joints_run(controller_class):
    h = make_harness(controller_class, joints=["a", "b", "c"], interface="velocity")
    h.configure()
    h.activate()
    assert h.update() is ReturnType.OK


def test_the_library_controller_configures():
    h = make_harness(DisplacementController)
    assert h.configure() is State.INACTIVE
''')

LEARNERS = {
    "asserts_nothing": (ASSERTS_NOTHING, set()),
    "first_tests": (FIRST_TESTS, FIRST_CATCHES),
    "message_tests": (MESSAGE_TESTS, MESSAGE_CATCHES),
    "the_workshops_own_test": (ORIGINAL, set()),
    "exceptions_only": (RAISES_ONLY, set()),
}


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    variants = [Variant(name, {FILE: text}) for name, (text, _) in LEARNERS.items()]
    return grade_variants(16, variants, tmp_path_factory.mktemp("task16"))


def _reasons(rubric: Rubric) -> dict[str, str]:
    first = {c.name: c.detail for c in rubric.checks if not c.passed and not c.same_as}
    return {c.name: first.get(c.same_as, c.detail) for c in rubric.checks if not c.passed}


def test_the_solution_gets_full_marks() -> None:
    rubric = grade(16, track="solutions", record=False)
    assert rubric.score == rubric.max_score == len(WRONG) >= 18, rubric.format()
    assert all(c.passed for c in rubric.checks), rubric.format()


def test_the_exercise_as_handed_out_scores_0_and_says_it_has_no_tests() -> None:
    rubric = grade(16, track="exercises", record=False)
    assert rubric.score == 0 < rubric.max_score, rubric.format()
    assert "has no tests yet" in _reasons(rubric)[GATE]


@pytest.mark.parametrize("name", list(LEARNERS))
def test_a_learners_file_gets_the_share_it_catches(rubrics: dict[str, Rubric], name: str) -> None:
    rubric, caught = rubrics[name], LEARNERS[name][1]
    passed = {c.name for c in rubric.checks if c.passed and not c.given}
    assert passed == caught, rubric.format()
    assert rubric.score == len(caught) and rubric.max_score == len(WRONG), rubric.format()


@pytest.mark.parametrize("name", ["first_tests", "message_tests"])
def test_each_rule_let_through_is_named_never_the_code(rubrics: dict[str, Rubric], name: str) -> None:
    reasons = _reasons(rubrics[name])
    for rule_id, wrong in WRONG.items():
        if rule_id in LEARNERS[name][1]:
            continue
        reason = reasons[rule_id]
        assert wrong.rule in reason and "passes all your tests" in reason, reason  # type: ignore[attr-defined]
        assert not re.search(r"\bdef |\bself\.|class |\.py\b|_on_reference|set_value", reason), reason


def test_a_file_that_asserts_nothing_scores_0_and_says_why(rubrics: dict[str, Rubric]) -> None:
    rubric = rubrics["asserts_nothing"]
    info = _reasons(rubric)[INFO]
    for test in ("test_configure", "test_a_jog_runs", "test_effort_is_accepted"):
        assert f"{test} checks nothing" in info, info
    assert "none of your tests checks anything" in _reasons(rubric)["matched_by_name"]
    assert rubric.score == 0


def test_a_test_that_fails_on_a_correct_controller_is_named_with_its_line(rubrics: dict[str, Rubric]) -> None:
    rubric = rubrics["the_workshops_own_test"]
    reasons = _reasons(rubric)
    assert "test_update_logic_fast fails: line" in reasons[GATE], reasons[GATE]
    assert 'assert h.value("joint1/acceleration") == 23.24' in reasons[GATE]
    assert "test_command_is_state_plus_displacement" not in reasons[GATE]
    assert reasons["command_is_state_plus_displacement"].startswith("not judged yet")  # a right test is not scored
    assert rubric.score == 0


def test_a_failure_that_is_only_an_exception_catches_nothing_and_says_so(rubrics: dict[str, Rubric]) -> None:
    reasons = _reasons(rubrics["exceptions_only"])
    claims = reasons["claims_the_joints_it_is_given"]
    assert "test_three_velocity_joints_run fails on it only because the code raised (InterfaceNotFound" in claims
    assert "does not take the fixture controller_class" in reasons[INFO]
    assert "test_three_velocity_joints_run catches no wrong controller and passes on a controller that does nothing" \
        in reasons[INFO]


def test_every_check_has_a_hint_example_for_another_rule_that_passes_on_its_wrong_controller(tmp_path: Path) -> None:
    """The third hint of a check shows a test for another rule: it passes on the correct controller and on the wrong
    controller it is shown for (it would not give the missing test away)."""
    import task16_public_mutants as public

    for key, example in public.EXAMPLES.items():
        shown_for = [w for w in WRONG.values() if w.example == key]  # type: ignore[attr-defined]
        path = tmp_path / key / FILE
        path.parent.mkdir()
        path.write_text(learner(example))
        against = {"correct": "rrbot_workshop.controllers.displacement:DisplacementController",
                   **{w.id: w.spec for w in shown_for}}  # type: ignore[attr-defined]
        runs = run_tests(path, against)
        assert runs.tests and not runs.errors, runs.table()
        assert all(o.passed for o in runs.outcomes), f"example {key}:\n{runs.table()}"
        assert all(example in w.hints[2] for w in shown_for)  # type: ignore[attr-defined]


def test_every_wrong_controller_breaks_its_rule_only_for_the_solution() -> None:
    """Each wrong controller is caught by the solution's tests, and none is the correct controller in disguise."""
    path = ROOT / "solutions" / "task16_test_your_controller" / FILE
    against = {"correct": "rrbot_workshop.controllers.displacement:DisplacementController", "idle": "nothing",
               **{w.id: w.spec for w in WRONG.values()}}  # type: ignore[attr-defined]
    runs = run_tests(path, against)
    assert not runs.failing_on("correct") and not runs.load_errors, runs.table()
    for rule_id in WRONG:
        assert runs.catchers(rule_id, "correct", "idle"), f"no test of the solution catches {rule_id}"


def test_there_are_enough_wrong_controllers_and_a_public_few() -> None:
    public = [w for w in WRONG.values() if w.public]  # type: ignore[attr-defined]
    assert len(WRONG) - len(public) >= 15 and 1 <= len(public) <= 5
