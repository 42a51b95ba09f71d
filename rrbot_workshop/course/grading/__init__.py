"""Self-checks for the course: graders, rubrics, and tools to reset and hand out exercises.

A task's grader is ``tests/tasks/test_taskNN_<name>.py``: pytest tests marked with :func:`graded` (points, graduated
hints, and the checks each builds on). :func:`grade` runs one in a fresh process on the selected track and returns a
:class:`Rubric`, in which only the learner's first cause shows a hint (:mod:`.hints`); :func:`check` is the same, for a
notebook cell. :func:`fail_without_hint` fails a check with no hint (a prediction not made yet); :func:`first_failure`
says why a learner's file breaks a rule its own checks judge; :mod:`.sealed` keeps predictions as they were before
their outcomes were shown. :func:`reset_exercise` and :func:`export_student_copy` are the
instructor's tools behind ``rrbot-workshop reset`` and ``rrbot-workshop export``.
"""

from rrbot_workshop.course.grading.course import export_student_copy, pristine_files, reset_exercise
from rrbot_workshop.course.grading.rubric import (
    CheckResult,
    CheckSpec,
    Rubric,
    fail_without_hint,
    first_failure,
    graded,
)
from rrbot_workshop.course.grading.runner import DEFAULT_CHECK_TIMEOUT, check, grade, graded_tasks, grader_path

__all__ = [
    "graded",
    "fail_without_hint",
    "first_failure",
    "CheckSpec",
    "CheckResult",
    "Rubric",
    "grade",
    "check",
    "graded_tasks",
    "grader_path",
    "DEFAULT_CHECK_TIMEOUT",
    "reset_exercise",
    "pristine_files",
    "export_student_copy",
]
