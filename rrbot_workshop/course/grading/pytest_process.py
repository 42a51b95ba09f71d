"""A fresh pytest process for each grading, forked from one that has already imported what graders use.

A grader runs in a process of its own, so it sees the learner's files as they are on disk and nothing a notebook
changed in the library. Starting Python and importing pytest, numpy, MuJoCo, the URDF model and the library costs
about a second and a half of CPU per grading, and a test run grades hundreds of variants, a room thirty learners at
once. So gradings are forked from a *fork server*: a process started once (with ``sys.executable``, never a copy of the
caller, which a notebook may have changed) that imports :data:`PRELOAD` and then only forks. Each child sets the
grading's working folder, environment and ``sys.path``, runs :func:`pytest.main` and exits: it is as fresh as a new
process, without paying for the imports again.

The fork server is worth starting only where more gradings follow: :func:`warm_up` starts it in the background (a test
run that grades many variants, ``progress``), and until it is ready
each grading starts a new Python process as before. Where fork is not available (Windows), or with
``RRBOT_WORKSHOP_GRADE_FORK=0``, a new Python process is always started; the outcome is the same. (A notebook's
self-check forks from a copy of its own kernel instead: see :mod:`.kernel_fork`.)
"""

from __future__ import annotations

import contextlib
import importlib
import multiprocessing
import os
import subprocess
import sys
import tempfile
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["PRELOAD", "FORK_ENV", "run_pytest", "warm_up", "ready"]

#: Modules the fork server imports once: what graders and the grading plugin import (each is optional).
PRELOAD = (
    "pytest", "_pytest.python", "_pytest.fixtures", "hypothesis", "numpy", "yaml", "lxml.etree", "xacro",
    "rrbot_workshop.course.grading.plugin", "rrbot_workshop.bringup", "rrbot_workshop.controllers",
    "rrbot_workshop.hardware", "rrbot_workshop.testing", "rrbot_workshop.tools.lint", "rrbot_workshop.description",
    "mujoco", "yourdfpy",
)
#: Set to ``0`` to start a new Python process for every grading instead of forking one.
FORK_ENV = "RRBOT_WORKSHOP_GRADE_FORK"

_CONTEXT: Any = None
_LOCK = threading.Lock()
_READY = threading.Event()
_WARMING: list[threading.Thread] = []


def preload(names: Sequence[str] = PRELOAD) -> None:
    """Import ``names`` (each that imports): :data:`PRELOAD` in the fork server, once, by importing ``fork_preload``;
    a kernel's copy imports its own list (:mod:`.kernel_fork`)."""
    for name in names:
        with contextlib.suppress(Exception):
            importlib.import_module(name)


def _context() -> Any:
    global _CONTEXT
    with _LOCK:
        if _CONTEXT is None:
            context = multiprocessing.get_context("forkserver")
            context.set_forkserver_preload(["rrbot_workshop.course.grading.fork_preload"])
            _CONTEXT = context
        return _CONTEXT


def _noop() -> None:
    """A child that only proves the fork server answers."""


def _warm() -> None:
    with contextlib.suppress(Exception):
        process = _context().Process(target=_noop)
        process.start()
        process.join()
        if process.exitcode == 0:
            _READY.set()


def warm_up(wait: bool = False) -> None:
    """Start the fork server in the background (once), for the gradings that follow; ``wait`` until it is ready."""
    if not _forking():
        return
    with _LOCK:
        if not _WARMING:
            _WARMING.append(threading.Thread(target=_warm, name="rrbot_workshop grading fork server", daemon=True))
            _WARMING[0].start()
    if wait:
        _WARMING[0].join()


def ready() -> bool:
    """Whether gradings are forked now (the fork server answered)."""
    return _READY.is_set() and _forking()


def _forking() -> bool:
    return (os.environ.get(FORK_ENV, "1") != "0" and "forkserver" in multiprocessing.get_all_start_methods()
            and hasattr(os, "fork"))


def _child(args: list[str], cwd: str, env: dict[str, str], output: str, drop: list[str]) -> None:
    """In the forked child: become a fresh ``python -m pytest ARGS`` run in ``cwd`` with ``env``; never returns."""
    code = 70
    try:
        fd = os.open(output, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(fd, 1)
        os.dup2(fd, 2)
        os.close(fd)
        # the streams on those descriptors (a copy of a notebook's kernel has the kernel's own streams)
        sys.stdout = open(1, "w", encoding="utf-8", errors="backslashreplace", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", encoding="utf-8", errors="backslashreplace", closefd=False)  # noqa: SIM115
        os.chdir(cwd)
        os.environ.clear()
        os.environ.update(env)
        if "hypothesis" in sys.modules and "HYPOTHESIS_STORAGE_DIRECTORY" not in env:
            # imported before the chdir, it took the old folder for its .hypothesis/: the run's own folder, as in a
            # new process
            os.environ["HYPOTHESIS_STORAGE_DIRECTORY"] = os.path.join(cwd, ".hypothesis")
        sys.dont_write_bytecode = env.get("PYTHONDONTWRITEBYTECODE", "") != ""
        # as `python -m pytest` run in cwd: the folder first, never the caller's test folders
        sys.path[:] = [cwd, *(p for p in sys.path if p and os.path.abspath(p) not in drop)]
        sys.argv = ["pytest", *args]
        import pytest

        code = int(pytest.main(args))
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:  # noqa: BLE001 - a crash of pytest itself: said on the output, like a process's traceback
        import traceback

        traceback.print_exc()
        code = 70
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


def _subprocess(args: Sequence[str], cwd: Path, env: dict[str, str], timeout: float) -> tuple[int | None, str]:
    try:
        proc = subprocess.run([sys.executable, "-m", "pytest", *args], cwd=cwd, env=env, capture_output=True, text=True,
                              timeout=timeout, check=False)
    except subprocess.TimeoutExpired as exc:
        out = [x.decode(errors="replace") if isinstance(x, bytes) else (x or "") for x in (exc.stdout, exc.stderr)]
        return None, "".join(out)
    return proc.returncode, proc.stdout + proc.stderr


def run_pytest(args: Sequence[str], cwd: Path, env: dict[str, str], timeout: float,
               drop_paths: Sequence[str | os.PathLike[str]] = ()) -> tuple[int | None, str]:
    """Run ``python -m pytest ARGS`` in ``cwd`` with exactly the environment ``env``, forked from the fork server.

    Args:
        args: pytest's arguments.
        cwd: The working folder (first on ``sys.path``, as ``python -m`` puts it).
        env: The whole environment of the run.
        timeout: Wall-clock limit in [s]; the run is killed after it.
        drop_paths: Folders of the caller's ``sys.path`` the run must not see (a test run's own test folders).

    Returns:
        pytest's exit status (None when it was killed at ``timeout``) and what it printed.
    """
    if not ready():
        return _subprocess(args, cwd, env, timeout)
    drop = [os.path.abspath(p) for p in drop_paths]
    with tempfile.TemporaryDirectory(prefix="rrbot_workshop_pytest_") as tmp:
        output = str(Path(tmp) / "output.txt")
        try:
            process = _context().Process(target=_child, args=(list(args), str(cwd), dict(env), output, drop),
                                         daemon=False)
            process.start()
        except (OSError, ValueError, RuntimeError):  # the fork server could not start: a new process instead
            return _subprocess(args, cwd, env, timeout)
        process.join(timeout)
        code: int | None = process.exitcode
        if process.is_alive():
            process.kill()
            process.join()
            code = None
        text = Path(output).read_text(encoding="utf-8", errors="replace") if os.path.exists(output) else ""
    return code, text


