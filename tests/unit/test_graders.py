"""Every grader in tests/tasks/ gives full marks to solutions/, and can fail: untouched exercises and wrong answers.

Each grading runs in a process of its own, as a learner's would: forked from the grading fork server, which the module
waits for once (a grading started before it answers imports pytest, numpy, MuJoCo and the library again). A grader
added as tests/tasks/test_taskNN_*.py is picked up here without any registration.
"""

from __future__ import annotations

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade, graded_tasks
from rrbot_workshop.course.grading.pytest_process import warm_up

GRADED = graded_tasks()
HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
needs_solutions = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


@pytest.fixture(scope="module", autouse=True)
def _fork_server() -> None:
    """The 2 x 16 gradings below are forked from one process that has imported what graders use."""
    warm_up(wait=True)


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


def _report(rubric: Rubric) -> str:
    return rubric.format()


@needs_solutions
@pytest.mark.parametrize("task", GRADED)
def test_solution_gets_full_marks(task: int) -> None:
    rubric = grade(task, track="solutions")
    assert rubric.max_score > 0
    assert rubric.score == rubric.max_score, _report(rubric)


@pytest.mark.parametrize("task", GRADED)
def test_untouched_exercise_does_not_get_full_marks(task: int) -> None:
    rubric = grade(task, track="exercises")
    if rubric.checks and all(c.given and c.passed for c in rubric.checks):
        pytest.skip(f"every check of task {task} needs a reference this copy of the course withholds")
    assert rubric.score == 0 < rubric.max_score, _report(rubric)  # free checks are marked given, not scored
