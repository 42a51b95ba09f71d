"""The learner's attempt log: how often each task was checked, which checks failed, when it first passed.

One small JSON file per task next to the learner's files, ``exercises/.progress/taskNN.json`` (git-ignored), written
each time a learner grades their own exercises (``check(N)`` or ``rrbot-workshop grade N`` on the exercises track).
It drives the graduated hints (each attempt records the check that showed its hint and the level shown; the next
level comes only when that check still fails on a new version of the learner's files, see
:mod:`~rrbot_workshop.course.grading.hints`: grading an unchanged file again, or re-running a notebook's self-check
cell, does not move it), holds the predictions sealed before their outcomes were shown
(:mod:`~rrbot_workshop.course.grading.sealed`), and gives the instructor, through ``rrbot-workshop progress --json``, the number of attempts and the time it took to pass.
Grading a copy (``--root``), the solutions track or the course's own tests records nothing.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path
from typing import Any

from rrbot_workshop.course import tracks

__all__ = ["log_path", "load", "record", "failures", "files_version", "summary", "recording_enabled", "write"]

#: Set to "0" to grade without writing the log (the course's tests do).
ENV = "RRBOT_WORKSHOP_RECORD_ATTEMPTS"


def recording_enabled(track: str, task_root: object) -> bool:
    """Record only the learner grading their own exercises in the course folder."""
    return (track == "exercises" and task_root is None and not os.environ.get(tracks.TASK_ROOT_ENV)
            and not os.environ.get(tracks.EXERCISES_ENV) and os.environ.get(ENV, "1") != "0")


def log_path(task: int, exercises: str | os.PathLike[str] | None = None) -> Path:
    """``.progress/taskNN.json`` in ``exercises`` (default: the course folder's ``exercises/``)."""
    folder = Path(exercises) if exercises is not None else tracks.course_root() / "exercises"
    return folder / ".progress" / f"task{task:02d}.json"


def load(task: int, exercises: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """The task's log (``{"attempts": [...]}``), empty if there is none or it cannot be read."""
    try:
        data = json.loads(log_path(task, exercises).read_text())
    except (OSError, ValueError):
        return {"attempts": []}
    return data if isinstance(data, dict) and isinstance(data.get("attempts"), list) else {"attempts": []}


def files_version(folder: Path) -> str:
    """A digest of the learner's files in a task folder (names and contents; caches and the log left out)."""
    digest = hashlib.sha256()
    if folder.is_dir():
        for path in sorted(p for p in folder.rglob("*") if p.is_file()):
            rel = path.relative_to(folder)
            if any(part in ("__pycache__", ".progress", ".ipynb_checkpoints") for part in rel.parts):
                continue
            try:
                data = path.read_bytes()
            except OSError:
                continue
            digest.update(rel.as_posix().encode() + b"\0" + hashlib.sha256(data).digest())
    return digest.hexdigest()[:16]


def write(task: int, data: dict[str, Any], exercises: str | os.PathLike[str] | None = None) -> bool:
    """Write the task's log (atomically); False if it cannot be written (a read-only course folder only loses it)."""
    path = log_path(task, exercises)
    tmp = path.with_name(path.name + ".tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps(data, indent=1) + "\n")
        os.replace(tmp, path)
    except OSError:
        return False
    return True


def record(task: int, score: float, max_score: float, failed: list[str], now: float | None = None,
           version: str = "", reasons: dict[str, str] | None = None,
           hints: dict[str, int] | None = None) -> dict[str, Any]:
    """Append one attempt; never raises (a read-only course folder only loses the log).

    Args:
        task: Task number.
        score: Points earned.
        max_score: Points available.
        failed: Names of the checks that failed.
        now: Time of the attempt (seconds since the epoch); default now.
        version: :func:`files_version` of the graded files.
        reasons: Why each failed check failed (for the instructor's room report), at most 300 characters each.
        hints: The check that showed its hint -> the level shown (0-based).

    Returns:
        The attempt as recorded.
    """
    data = load(task)
    attempt = {"time": time.time() if now is None else now, "score": score, "max_score": max_score,
               "failed": sorted(failed), "version": version,
               "reasons": {k: str(v)[:300] for k, v in sorted((reasons or {}).items())},
               "hints": dict(hints or {})}
    data["attempts"].append(attempt)
    write(task, data)
    return attempt


def failures(task: int, check: str) -> int:
    """How many recorded attempts failed ``check``."""
    return sum(check in a.get("failed", []) for a in load(task)["attempts"])


def summary(task: int, exercises: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """``{"attempts": n, "passed": bool, "time_to_pass_s": seconds from the first attempt to the first full score}``.

    Args:
        task: Task number.
        exercises: The learner's exercises folder (``--root`` of ``progress``); default the course's.
    """
    attempts = load(task, exercises)["attempts"]
    out: dict[str, Any] = {"attempts": len(attempts), "passed": False, "time_to_pass_s": None}
    for a in attempts:
        if a.get("max_score") and a.get("score") == a.get("max_score"):
            out["passed"] = True
            out["time_to_pass_s"] = round(float(a["time"]) - float(attempts[0]["time"]), 1)
            break
    return out
