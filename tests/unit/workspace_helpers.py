"""Helpers of the workspace tests: a small installed course, hashes of a folder tree, a guard against hangs."""

from __future__ import annotations

import hashlib
import json
import os
import stat
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

GRADER = '''
from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import graded


@graded(points=1, hint=("idea", "api", "code"))
def test_answer():
    assert (tracks.task_dir(1) / "a.py").read_text().strip() == "x = 42", "a.py must say x = 42"
'''


def notebook(text: str) -> str:
    """A one-cell notebook saying ``text``."""
    return json.dumps({"cells": [{"cell_type": "markdown", "metadata": {}, "source": [text]}], "metadata": {},
                       "nbformat": 4, "nbformat_minor": 5})


def make_course(course: Path) -> Path:
    """A course installed for a room: two tasks, two notebooks, a grader, descriptions; solutions beside."""
    files = {
        "exercises/README.md": "# Exercises\n",
        "exercises/task01_fake/a.py": "x = None  # TODO\n",
        "exercises/task01_fake/b.py": "y = 1\n",
        "exercises/task01_fake/config/c.yaml": "c: 1\n",
        "exercises/task02_more/d.py": "z = None\n",
        "solutions/task01_fake/a.py": "x = 42\n",
        "notebooks/01_fake.ipynb": notebook("one"),
        "notebooks/02_more.ipynb": notebook("two"),
        "descriptions/robot/r.urdf": "<robot name='r'/>",
        "tests/tasks/test_task01_fake.py": GRADER,
        "tests/conftest.py": "",
        "README.md": "# Course\n",
    }
    for rel, text in files.items():
        (course / rel).parent.mkdir(parents=True, exist_ok=True)
        (course / rel).write_text(text)
    return course


def tree(root: Path) -> dict[str, str]:
    """Every entry under ``root``, relative POSIX path -> what it is: a file's sha256, a link's target, ``dir``,
    ``fifo``; links are never followed."""
    out: dict[str, str] = {}
    for folder, dirs, files in os.walk(root, followlinks=False):
        for name in dirs + files:
            path = Path(folder) / name
            rel = path.relative_to(root).as_posix()
            mode = os.lstat(path).st_mode
            if stat.S_ISLNK(mode):
                out[rel] = "link:" + os.readlink(path)
            elif stat.S_ISDIR(mode):
                out[rel] = "dir"
            elif stat.S_ISREG(mode):
                out[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
            else:
                out[rel] = "special"
    return out


def contents(root: Path) -> set[bytes]:
    """The contents of every regular file under ``root`` (links not followed)."""
    found = set()
    for folder, _, files in os.walk(root, followlinks=False):
        for name in files:
            path = Path(folder) / name
            if stat.S_ISREG(os.lstat(path).st_mode):
                found.add(path.read_bytes())
    return found


def no_hang(fn: Callable[..., Any], *args: Any, limit: float = 120.0, release: Callable[[], None] | None = None,
            **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)``, failing the test if it has not returned after ``limit`` seconds (a guard that turns a
    hang into a failure, not a measure of speed); ``release`` then unblocks the thread (opens a FIFO, say)."""
    outcome: dict[str, Any] = {}

    def run() -> None:
        try:
            outcome["value"] = fn(*args, **kwargs)
        except BaseException as exc:  # noqa: BLE001 - handed back to the test
            outcome["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(limit)
    if thread.is_alive():
        if release is not None:
            release()
        raise AssertionError(f"{getattr(fn, '__name__', fn)} hung (still running after {limit} s)")
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("value")
