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


# ------------------------------------------------------------------------------------------ kills at a random write
class Killed(BaseException):
    """Stands for the process being killed (a BaseException: no ``except Exception`` of the code under test sees it)."""


_MUTATING = {"write", "replace", "rename", "mkdir", "makedirs", "unlink", "remove", "rmdir", "symlink", "link",
             "copytree", "rmtree", "move", "copy", "copy2", "copyfile", "open"}
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT


class FaultPlan:
    """Counts every change the code under test makes to the disk, and acts (raises :class:`Killed`, or kills the
    process) just before change number ``at``; a write is cut in half first, as a kill in the middle of it would."""

    def __init__(self, at: int | None, act: Callable[[], None]) -> None:
        self.at = at
        self.count = 0
        self.act = act

    def before(self, name: str, real: Callable[..., Any], args: tuple[Any, ...]) -> None:
        if self.count == self.at:
            if name == "write":
                real(args[0], bytes(args[1])[: len(args[1]) // 2])
            self.act()
        self.count += 1


class _Faulty:
    """A stand-in for a module (``os``, ``shutil``) that lets :class:`FaultPlan` see every call that changes files."""

    def __init__(self, real: Any, plan: FaultPlan) -> None:
        self._real, self._plan = real, plan

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._real, name)
        if name not in _MUTATING or not callable(attr):
            return attr

        def call(*args: Any, **kwargs: Any) -> Any:
            if name != "open" or (len(args) > 1 and args[1] & _WRITE_FLAGS):
                self._plan.before(name, attr, args)
            return attr(*args, **kwargs)

        return call


def raise_killed() -> None:
    raise Killed


def install_faults(plan: FaultPlan) -> Callable[[], None]:
    """Route the ``os`` and ``shutil`` of the modules that write a workspace through ``plan``; return the undo."""
    import shutil

    from rrbot_workshop.classroom import course_files, launcher, workspace

    real = {"os": os, "shutil": shutil}
    saved = [(m, n, getattr(m, n)) for m in (launcher, workspace, course_files) for n in real if hasattr(m, n)]
    for module, name, _ in saved:
        setattr(module, name, _Faulty(real[name], plan))

    def undo() -> None:
        for module, name, value in saved:
            setattr(module, name, value)

    return undo
