"""Gradings forked from a clean copy of the notebook's own kernel, which has already imported the library.

A notebook's self-check (``check(N)``) grades in a process of its own (see :mod:`.pytest_process`). Starting that
process costs more CPU than the grading: Python's start and importing numpy, the library, pytest and hypothesis take
about a second, on a room's busiest minute, for every learner. The kernel has most of that imported already, but it is
no place to grade: the learner's code ran in it, and may have changed the library's modules or registries.

So ``%load_ext rrbot_workshop`` (the first line of every notebook) forks the kernel once, before any of the learner's
code has run: the *copy* is the kernel as it was then, idle, with the library imported. It waits on a socket. For
each grading it imports what graders use (once, on the first request), forks a child that becomes a fresh
``python -m pytest ARGS`` run (:func:`.pytest_process._child`: the grading's folder, environment and ``sys.path``,
the learner's files read from disk as they are now), waits for it and says how it ended. The kernel keeps the
grading's time limit: it kills the child when it is over, and on an interrupt. The copy never runs a learner's code
itself, so a grading that raises or hangs harms neither the kernel nor the copy.

The copy ends with the kernel (the socket closes; on Linux the kernel's death also kills it), and each child with
the copy. Only on Linux, in a kernel that loaded the extension, and not with ``RRBOT_WORKSHOP_GRADE_FORK=0``;
anywhere else, or if the copy is gone, a grading runs as :func:`.pytest_process.run_pytest` runs it. The outcome is
the same.
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import signal
import socket
import sys
import tempfile
import threading
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rrbot_workshop.course.grading import pytest_process

__all__ = ["start", "running", "run_pytest", "KERNEL_PRELOAD"]

#: What the copy imports before its first grading: what every grader and the grading plugin import. Heavy modules
#: only some graders use (MuJoCo, yourdfpy with trimesh and scipy) are imported by the gradings that need them.
KERNEL_PRELOAD = tuple(name for name in pytest_process.PRELOAD if name not in ("mujoco", "yourdfpy"))

_PR_SET_PDEATHSIG = 1
_LOCK = threading.Lock()
_COPY: list[_Copy] = []


class _Copy:
    """The kernel's end: the copy's process id, the socket to it, and how many messages it still owes (the copy sends
    a grading's process id, then how it ended; an interrupt can leave some unread)."""

    def __init__(self, pid: int, sock: socket.socket) -> None:
        self.pid = pid
        self.sock = sock
        self.buffer = b""
        self.owed = 0
        self.broken = False

    def alive(self) -> bool:
        if self.broken:
            return False
        with contextlib.suppress(ChildProcessError):
            done, _ = os.waitpid(self.pid, os.WNOHANG)
            if done:
                self.broken = True
        return not self.broken

    def read(self, timeout: float | None) -> dict[str, Any]:
        """The next message; raises TimeoutError after ``timeout`` [s] (the message stays owed)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while b"\n" not in self.buffer:
            self.sock.settimeout(None if deadline is None else max(deadline - time.monotonic(), 0.001))
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("the kernel's copy for gradings ended")
            self.buffer += data
        line, self.buffer = self.buffer.split(b"\n", 1)
        self.owed -= 1
        return dict(json.loads(line))

    def settle(self, timeout: float) -> None:
        """Read what an interrupted grading left owed, killing its child."""
        while self.owed > 0:
            message = self.read(timeout)
            if "pid" in message:
                _kill(int(message["pid"]))


def _die_with_parent() -> None:
    """Linux: be killed when the parent process ends (a copy with its kernel, a grading with the copy)."""
    with contextlib.suppress(Exception):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)


def _send(sock: socket.socket, message: dict[str, Any]) -> None:
    sock.sendall((json.dumps(message) + "\n").encode("utf-8"))


def _serve(sock: socket.socket, parent: int) -> None:
    """In the copy: answer grading requests until the kernel closes the socket; never returns."""
    code = 0
    try:
        _die_with_parent()
        if os.getppid() != parent:  # the kernel ended before the line above
            os._exit(0)
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # an interrupt of the kernel is the kernel's (and the grading's)
        quiet = os.open(os.devnull, os.O_RDWR)  # the kernel's output streams are not the copy's to write to
        for fd in (0, 1, 2):
            os.dup2(quiet, fd)
        sys.stdout = sys.stderr = open(1, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
        reader = sock.makefile("r", encoding="utf-8")
        preloaded = False
        for line in reader:
            request = json.loads(line)
            if not preloaded:
                pytest_process.preload(KERNEL_PRELOAD)
                preloaded = True
            gc.freeze()  # what the copy holds is never garbage: a grading's collections skip it (and leave it shared)
            child = os.fork()
            if child == 0:
                _die_with_parent()
                signal.signal(signal.SIGINT, signal.default_int_handler)
                with contextlib.suppress(Exception):
                    reader.close()
                    sock.close()
                pytest_process._child(request["args"], request["cwd"], request["env"], request["output"],
                                      request["drop"])
            _send(sock, {"pid": child})
            _, status = os.waitpid(child, 0)
            exit_code = os.waitstatus_to_exitcode(status)
            _send(sock, {"exit": exit_code})
    except BaseException:  # noqa: BLE001 - the copy ends quietly; the kernel grades the usual way then
        code = 1
    finally:
        os._exit(code)


def start() -> bool:
    """Fork the kernel's copy for gradings (once; call before any of the learner's code runs).

    Returns:
        Whether a copy is running now.
    """
    if sys.platform != "linux" or os.environ.get(pytest_process.FORK_ENV, "1") == "0" or not hasattr(os, "fork"):
        return False
    with _LOCK:
        if _COPY:
            return _COPY[0].alive()
        ours, theirs = socket.socketpair()
        parent = os.getpid()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # Python 3.12+: fork of a process with threads
            pid = os.fork()
        if pid == 0:
            ours.close()
            _serve(theirs, parent)
        theirs.close()
        _COPY.append(_Copy(pid, ours))
        return True


def running() -> bool:
    """Whether this process has a copy that gradings fork from."""
    with _LOCK:
        return bool(_COPY) and _COPY[0].alive()


def _kill(pid: int) -> None:
    with contextlib.suppress(OSError):
        os.kill(pid, signal.SIGKILL)


def _run_in_copy(copy: _Copy, args: Sequence[str], cwd: Path, env: dict[str, str], timeout: float,
                 drop: list[str]) -> tuple[int | None, str]:
    copy.settle(10.0)
    with tempfile.TemporaryDirectory(prefix="rrbot_workshop_pytest_") as tmp:
        output = str(Path(tmp) / "output.txt")
        deadline = time.monotonic() + timeout
        _send(copy.sock, {"args": list(args), "cwd": str(cwd), "env": dict(env), "output": output, "drop": drop})
        copy.owed = 2
        child = None
        code: int | None
        try:
            child = int(copy.read(max(timeout, 1.0))["pid"])
            code = int(copy.read(max(deadline - time.monotonic(), 0.001))["exit"])
        except TimeoutError:
            if child is None:
                raise
            _kill(child)
            copy.settle(10.0)
            code = None
        except BaseException:  # an interrupt: the grading ends with it
            if child is not None:
                _kill(child)
            with contextlib.suppress(Exception):
                copy.settle(10.0)
            raise
        text = Path(output).read_text(encoding="utf-8", errors="replace") if os.path.exists(output) else ""
    return code, text


def run_pytest(args: Sequence[str], cwd: Path, env: dict[str, str], timeout: float,
               drop_paths: Sequence[str | os.PathLike[str]] = ()) -> tuple[int | None, str]:
    """Run ``python -m pytest ARGS`` as :func:`.pytest_process.run_pytest` does (same arguments, same result), forked
    from the kernel's copy if this process has one (see the module's description)."""
    with _LOCK:
        copy = _COPY[0] if _COPY and _COPY[0].alive() else None
        if copy is not None:
            drop = [os.path.abspath(p) for p in drop_paths]
            try:
                return _run_in_copy(copy, args, cwd, env, timeout, drop)
            except (OSError, ValueError, KeyError):  # the copy is gone or did not answer: the usual way
                copy.broken = True
                _kill(copy.pid)
    return pytest_process.run_pytest(args, cwd, env, timeout, drop_paths=drop_paths)
