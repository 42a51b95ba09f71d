"""Run one task's grader in a fresh Python process and read back its rubric.

A fresh process re-imports the learner's files every time, so a notebook's self-check sees the file as it is
on disk now, and nothing a grader does (or a learner's endless loop) can hurt the notebook's kernel. In a notebook's
kernel the process is forked from the kernel's clean copy (:mod:`.kernel_fork`), elsewhere as
:mod:`.pytest_process` starts it.
"""

from __future__ import annotations

import json
import logging
import os
import re
import sys
import tempfile
from pathlib import Path
from typing import Any

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import attempts, live_view
from rrbot_workshop.course.grading.hints import CheckEntry, plan_hints
from rrbot_workshop.course.grading.kernel_fork import run_pytest
from rrbot_workshop.course.grading.rubric import CheckResult, Rubric
from rrbot_workshop.exceptions import CourseError, GradingError

__all__ = ["grader_paths", "graded_tasks", "grader_path", "grade", "check", "DEFAULT_CHECK_TIMEOUT"]

logger = logging.getLogger(__name__)

#: Time limit per check phase in [s].
DEFAULT_CHECK_TIMEOUT = 30.0
#: Time limit for a whole grader process in [s] (a safety net behind the per-check limit).
DEFAULT_TOTAL_TIMEOUT = 900.0

_GRADER_RE = re.compile(r"^test_task(\d{2})_[A-Za-z0-9_]+\.py$")


def grader_paths(root: Path | None = None) -> dict[int, Path]:
    """Every grader file of the course: task number -> ``tests/tasks/test_taskNN_<name>.py``, sorted."""
    folder = (root or tracks.course_root()) / "tests" / "tasks"
    found: dict[int, Path] = {}
    if folder.is_dir():
        for child in sorted(folder.iterdir()):
            match = _GRADER_RE.match(child.name)
            if match:
                found.setdefault(int(match.group(1)), child)
    return found


def graded_tasks() -> list[int]:
    """Numbers of the tasks that have a grader, ascending."""
    return list(grader_paths())


def grader_path(task: int) -> Path:
    """The grader file of a task.

    Raises:
        CourseError: If the task has no grader; the message lists the tasks that have one.
    """
    paths = grader_paths()
    if task not in paths:
        names = tracks.task_names()
        graded = [names.get(n, f"task{n:02d}") for n in paths]
        raise CourseError("task", task, f"task {task} has no grader in tests/tasks/", graded)
    return paths[task]


def _rubric_from(task: int, data: dict[str, Any], stopped: str) -> Rubric:
    rubric = Rubric(task=task)
    for entry in data.get("checks", []):
        status = entry.get("status", "pending")
        detail = entry.get("detail", "")
        if status == "pending":
            detail = stopped
        passed = status == "passed"
        rubric.checks.append(
            CheckResult(
                name=str(entry["name"]),
                max_points=float(entry["max_points"]),
                passed=passed,
                detail="" if passed else detail,
                given=bool(entry.get("given", False)),
            )
        )
    rubric.mark_shared_reasons()
    return rubric


def _assign_hints(rubric: Rubric, entries: list[dict[str, Any]], log: list[dict[str, Any]], version: str) -> dict[str, int]:
    """Give the hint to the learner's first cause and mark the checks that wait for another (see :mod:`.hints`);
    returns ``{check: level}`` of the hint shown, for the attempt log."""
    checks = [
        CheckEntry(name=result.name, function=str(entry.get("function") or result.name), passed=result.passed,
                   levels=tuple(str(h) for h in entry.get("hints") or [entry.get("hint", "")] if h),
                   after=tuple(str(a) for a in entry.get("after") or ()), hintless=bool(entry.get("hintless")))
        for entry, result in zip(entries, rubric.checks, strict=True)
    ]
    plan = plan_hints(checks, log, version)
    for check, result in zip(checks, rubric.checks, strict=True):
        result.blocked_by = plan.blocked.get(result.name, "")
        if result.name != plan.cause:
            continue
        rubric.cause = result.name
        if len(check.levels) < 2:
            result.hint = check.levels[0]
            continue
        # graduated: the concept first, then the API, the code last; one level deeper per changed version of the
        # learner's files on which this check showed its hint and still fails (the same files show the same hint)
        more = "; change your files and check again for the next hint" if plan.level < len(check.levels) - 1 else ""
        result.hint = f"{check.levels[plan.level]} (hint {plan.level + 1} of {len(check.levels)}{more})"
    rubric.mark_shared_reasons()
    return plan.shown()


def grade(
    task: int,
    *,
    track: str | None = None,
    task_root: str | os.PathLike[str] | None = None,
    check_timeout: float = DEFAULT_CHECK_TIMEOUT,
    total_timeout: float = DEFAULT_TOTAL_TIMEOUT,
    verbose: bool = False,
    record: bool = True,
) -> Rubric:
    """Run a task's grader in a fresh process (forked from one that has imported what graders use) and return its rubric.

    Args:
        task: Task number.
        track: ``"exercises"`` or ``"solutions"``; default :func:`rrbot_workshop.course.tracks.current_track`.
        task_root: Grade the ``taskNN_*`` folder found in this folder instead of the track's.
        check_timeout: Time limit per check phase in [s]; a check that runs longer fails.
        total_timeout: Time limit of the whole grader process in [s]; unfinished checks fail.
        verbose: Log pytest's own output at INFO level.
        record: A learner's own check (the exercises track, no ``task_root``): log the attempt in
            ``exercises/.progress/`` and deepen the hint of the check that showed it on the previous version of the
            files (see :mod:`~rrbot_workshop.course.grading.hints`). ``progress`` grades with ``record=False``.

    Returns:
        The rubric; the grading ran even if the score is 0.

    Raises:
        CourseError: If the task has no grader, or the track is unknown or not part of this copy of the course.
        GradingError: If the grader itself could not be collected or pytest did not start.
    """
    root = tracks.course_root()
    path = grader_path(task)
    chosen = tracks.current_track() if track is None else track
    if chosen not in tracks.TRACKS:
        raise CourseError("track", chosen, f"unknown course track '{chosen}'", tracks.TRACKS)
    if task_root is None and not (root / chosen).is_dir():
        available = [t for t in tracks.TRACKS if (root / t).is_dir()]
        raise CourseError("track", chosen, f"this copy of the course has no '{chosen}/' folder", available)

    env = dict(os.environ)
    env[tracks.TRACK_ENV] = chosen
    env[tracks.ROOT_ENV] = str(root)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    # Graders need no third-party pytest plugins; nbval alone costs about a second of start-up.
    env["PYTEST_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    if task_root is not None:
        env[tracks.TASK_ROOT_ENV] = str(Path(task_root).expanduser().resolve())
    else:
        env.pop(tracks.TASK_ROOT_ENV, None)

    with tempfile.TemporaryDirectory(prefix="rrbot_workshop_grade_") as tmp:
        out = Path(tmp) / "rubric.json"
        args = [
            str(path),
            "-p", "rrbot_workshop.course.grading.plugin",
            "-p", "no:cacheprovider",
            "-o", "addopts=",
            "-q", "--no-header", "-rN", "--color=no",
            "--rootdir", str(root),
            "--rubric-json", str(out),
            "--check-timeout", f"{check_timeout:g}",
        ]
        # the caller's own test folders (a test run that grades) are not the grader's
        tests = (root / "tests").resolve()
        drop = [p for p in sys.path if p and Path(p).resolve().is_relative_to(tests)]
        returncode, output = run_pytest(args, root, env, total_timeout, drop_paths=drop)
        stopped = "the check did not run: the grader stopped before it"
        if returncode is None:
            stopped = f"the check did not run: the grader was stopped after {total_timeout:g} s"
        if verbose:
            logger.info("grader output (exit status %s):\n%s", returncode, output)
        if not out.is_file():
            raise GradingError(f"the grader {path.name} did not start (exit status {returncode}):\n{output[-3000:]}")
        data = json.loads(out.read_text(encoding="utf-8"))

    if data.get("errors"):
        raise GradingError(f"the grader {path.name} could not be collected:\n" + "\n".join(data["errors"]))
    if not data.get("checks"):
        raise GradingError(f"the grader {path.name} has no checks (pytest exit status {returncode}):\n{output[-3000:]}")
    rubric = _rubric_from(task, data, stopped)
    rubric.title = tracks.task_names().get(task, path.stem[len("test_"):])
    rubric.track = chosen if task_root is None else str(task_root)
    learner = record and attempts.recording_enabled(chosen, task_root)
    version = attempts.files_version(tracks.task_dir(task, chosen)) if learner else ""
    shown = _assign_hints(rubric, data.get("checks", []), attempts.load(task)["attempts"] if learner else [], version)
    if learner:
        failed = rubric.failed()
        reasons = {c.name: c.detail for c in failed}
        attempt = attempts.record(task, rubric.score, rubric.max_score, [c.name for c in failed], version=version,
                                  reasons=reasons, hints=shown)
        live_view.post_attempt(task, attempt)  # on a hub: to the instructor's live view, in the background
    return rubric


def check(task: int, *, track: str | None = None, check_timeout: float = DEFAULT_CHECK_TIMEOUT) -> Rubric:
    """Self-check for a notebook cell: grade ``task`` on the current track and return the rubric.

    The rubric shows itself as the cell's output (each check, PASS/FAIL, points, the hint of each failure).

    Args:
        task: Task number.
        track: Track to grade; default the current one (see :func:`rrbot_workshop.course.tracks.set_track`).
        check_timeout: Time limit per check phase in [s].

    Raises:
        CourseError: If the task has no grader.
        GradingError: If the grader could not run.
    """
    return grade(task, track=track, check_timeout=check_timeout)
