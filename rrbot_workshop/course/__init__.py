"""What a learner meets: tracks (exercises or solutions), the learner's helpers, the notebook magics, the fault lab,
grading, and the course's commands (grade, progress, tasks, reset, export).

The names below are what notebook cells use to reach the learner's files (``rw.course.load_module(3,
"answers.py")``; see :mod:`rrbot_workshop.course.learner`), to say where the learner's code raised
(:class:`~rrbot_workshop.course.tracebacks.LearnerErrors`), and to know whether this copy of the course withheld a
library reference a cell would fall back on (``rw.course.is_withheld("rrbot_workshop.motion")``).
"""

from rrbot_workshop.course.grading.references import is_withheld
from rrbot_workshop.course.learner import (
    ask,
    function,
    load_module,
    mine_or_reference,
    run,
    short_error,
    shown,
    step,
    task_file,
)
from rrbot_workshop.course.tracebacks import LearnerErrors

__all__ = ["ask", "function", "load_module", "mine_or_reference", "run", "short_error", "shown", "step", "task_file",
           "LearnerErrors", "is_withheld"]
