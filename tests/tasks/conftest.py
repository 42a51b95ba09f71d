"""Shared fixtures of the graders in tests/tasks/.

A grader finds the learner's files through :mod:`rrbot_workshop.course.tracks` (never by importing ``solutions/``), so
the same grader grades ``exercises/``, ``solutions/`` or a copy named by ``$RRBOT_WORKSHOP_TASK_ROOT``. Run a
grader with ``rrbot-workshop grade N`` (or ``rrbot_workshop.course.grading.check(N)``): that adds the rubric plugin
with its per-check time limit. Plain ``pytest tests/tasks/...`` also works, without points or time limits.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks


@pytest.fixture(scope="session")
def track() -> str:
    """The track being graded: ``"exercises"`` or ``"solutions"``."""
    return tracks.current_track()


@pytest.fixture(scope="session")
def task_file() -> Callable[[int, str], Path]:
    """``task_file(n, "rrbot_description/urdf/rrbot.urdf.xacro")``: a file of task n on the graded track.

    The check fails (not errors) with a clear message if the file does not exist.
    """

    def find(task: int, relative: str) -> Path:
        path = tracks.task_dir(task) / relative
        if not path.is_file():
            pytest.fail(f"missing file {path}: task {task} expects '{relative}' in its folder", pytrace=False)
        return path

    return find
