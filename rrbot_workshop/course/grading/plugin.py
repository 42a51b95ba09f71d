"""pytest plugin that turns a grader run into rubric results, with a time limit per check.

The runner starts ``python -m pytest <grader> -p rrbot_workshop.course.grading.plugin --rubric-json FILE
--check-timeout S``. For every collected test the plugin records its weight and hint (see
:func:`~rrbot_workshop.course.grading.rubric.graded`), then its outcome; the file is rewritten after each check, so a
run that is killed still says which checks finished.

Each phase of a check (fixture set-up, the test, tear-down) gets ``--check-timeout`` seconds. On POSIX a
``SIGALRM`` timer raises :class:`CheckTimeout` inside the running Python code, so an endless loop in a
learner's file fails that check and grading goes on. :class:`CheckTimeout` derives from ``BaseException``,
so a learner's ``except Exception:`` cannot swallow it. Where ``SIGALRM`` does not exist (Windows), a
watchdog thread records the timeout and ends the process; the runner marks the checks that did not run.

A grading is usually forked from a process that has imported pytest, numpy, MuJoCo and the library (see
:mod:`.pytest_process`): hundreds of thousands of objects that live as long as the grading. At configure the plugin
moves them out of the garbage collector's sight (:func:`gc.freeze`), so its collections (automatic ones during the
checks, and pytest's own at the end of the session) walk only what the grading made; this was about a quarter of a
short grading's CPU time. Nothing is collected less: every object made after configure is collected as before.

pytest rewrites the grader's ``assert`` statements at every grading (a twentieth of a short one), and a grading writes
no bytecode. When ``$RRBOT_WORKSHOP_GRADER_PYCACHE`` names a folder (a test run that grades hundreds of times sets it),
the grader file is imported with that folder as Python's ``sys.pycache_prefix`` and bytecode writing on, for that
import only: the first grading writes the rewritten grader there, the next ones read it (pytest checks it against the
source's hash). Nothing is written next to the course's or the learner's files.
"""

from __future__ import annotations

import gc
import json
import logging
import os
import signal
import sys
import threading
from collections.abc import Generator, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from rrbot_workshop.course.grading.learner_errors import LEARNER_LOGGER, LearnerErrorLog, learner_location, learner_root
from rrbot_workshop.course.grading.references import WITHHELD_SKIP
from rrbot_workshop.course.grading.rubric import HintlessFailure, check_spec

__all__ = ["CheckTimeout", "RubricCollector"]

#: Names a folder where gradings keep the grader file rewritten by pytest (see the module docstring).
PYCACHE_ENV = "RRBOT_WORKSHOP_GRADER_PYCACHE"
#: Exit status of a grader process ended by the watchdog (platforms without SIGALRM).
WATCHDOG_EXIT = 86
#: A check may wait (not compute) this many times its CPU-time limit before it is stopped.
WALL_FACTOR = 10.0


class CheckTimeout(BaseException):  # noqa: N818 - reads as an event, like KeyboardInterrupt
    """Raised inside a check that ran longer than its time limit."""


def _first_line(text: str) -> str:
    """The message as one line: every non-empty line, stripped, joined by spaces (nothing is cut)."""
    return " ".join(line.strip() for line in text.strip().splitlines() if line.strip())


def _assertion_text(text: str) -> str:
    """A failed ``assert``'s own message, without the expression pytest's rewriting appends (``assert 1 == 2``,
    ``+  where ...``): the grader's words are the reason, pytest's are not."""
    kept = []
    for line in text.strip().splitlines():
        if line.startswith(("assert ", "AssertionError: assert ")) or line.lstrip().startswith(("+  where", "+    ")):
            break
        kept.append(line)
    return _first_line("\n".join(kept))


def _describe(exc: BaseException) -> str:
    if isinstance(exc, AssertionError):
        return _assertion_text(str(exc)) or "assertion failed"
    message = _first_line(str(exc))
    name = type(exc).__name__
    if name == "Failed":  # pytest.fail(...): the grader's own words
        return message or "failed"
    return f"{name}: {message}" if message else name


class RubricCollector:
    """Collects per-check results and writes them to a JSON file.

    Args:
        path: Output file, or ``None`` to keep results in memory only.
        timeout: Time limit per check phase in [s]; 0 disables it.
    """

    def __init__(self, path: Path | None, timeout: float) -> None:
        self.path = path
        self.timeout = timeout
        self.checks: dict[str, dict[str, Any]] = {}
        self.errors: list[str] = []
        self.finished = False
        self._current: str | None = None
        self.root = learner_root()
        #: The learner's exceptions the library caught and logged in the current check ...
        self.learner_log = LearnerErrorLog(self.root)
        #: ... and in the set-up of fixtures shared by several checks (a module's system): "<module>::<fixture>"
        #: ("*::<fixture>" for a session's).
        self._shared_errors: dict[str, list[str]] = {}

    def start_logging(self) -> None:
        """Keep the learner's exceptions that the library logs (see :class:`LearnerErrorLog`)."""
        logging.getLogger().addHandler(self.learner_log)
        logging.getLogger(LEARNER_LOGGER).setLevel(logging.DEBUG)

    def _learner_error(self, item: pytest.Item, exc: BaseException | None) -> str | None:
        """The learner's error behind a failure: in the exception itself, else logged by the library."""
        found = learner_location(exc, self.root)
        if found is not None:
            return found
        first = self.learner_log.first()
        if first is not None:
            return first
        module = str(getattr(item, "module", None))
        for name in getattr(item, "fixturenames", ()):  # only the shared fixtures this check was given
            shared = self._shared_errors.get(f"{module}::{name}") or self._shared_errors.get(f"*::{name}")
            if shared:
                return shared[0]
        return None

    # ------------------------------------------------------------------ output
    def dump(self) -> None:
        """Write the current results (atomically) to :attr:`path`."""
        if self.path is None:
            return
        data = {"checks": list(self.checks.values()), "errors": self.errors, "finished": self.finished}
        tmp = self.path.with_name(self.path.name + ".tmp")
        tmp.write_text(json.dumps(data), encoding="utf-8")
        os.replace(tmp, self.path)

    def _fail(self, nodeid: str, detail: str) -> None:
        entry = self.checks.get(nodeid)
        if entry is None:
            return
        if entry["status"] != "failed":
            entry["status"] = "failed"
            entry["detail"] = detail

    # ------------------------------------------------------------------ time limit
    @contextmanager
    def time_limit(self, nodeid: str, phase: str) -> Iterator[None]:
        """Raise :class:`CheckTimeout` in the block once it has used :attr:`timeout` seconds of CPU.

        The limit is CPU time, not wall-clock time, so an endless loop is stopped while a slow or busy machine (a room of
        learners grading at once, a test run on every core) is not taken for one. A block that waits without computing
        (a learner's code blocked on a read) is stopped after :data:`WALL_FACTOR` times the limit in wall-clock time.
        """
        if self.timeout <= 0:
            yield
            return
        message = f"the check's {phase} used more than {self.timeout:g} s of CPU time (an endless loop?)"
        waited = (f"the check's {phase} waited more than {self.timeout * WALL_FACTOR:g} s without finishing (is "
                  "something blocked, waiting for input?)")
        if hasattr(signal, "SIGPROF") and threading.current_thread() is threading.main_thread():

            def on_cpu(signum: int, frame: Any) -> None:
                raise CheckTimeout(message)

            def on_wall(signum: int, frame: Any) -> None:
                raise CheckTimeout(waited)

            previous = signal.signal(signal.SIGPROF, on_cpu), signal.signal(signal.SIGALRM, on_wall)
            signal.setitimer(signal.ITIMER_PROF, self.timeout)
            signal.setitimer(signal.ITIMER_REAL, self.timeout * WALL_FACTOR)
            try:
                yield
            finally:
                signal.setitimer(signal.ITIMER_PROF, 0)
                signal.setitimer(signal.ITIMER_REAL, 0)
                signal.signal(signal.SIGPROF, previous[0])
                signal.signal(signal.SIGALRM, previous[1])
            return
        message = f"the check's {phase} took longer than {self.timeout * WALL_FACTOR:g} s (an endless loop?)"

        def expire() -> None:
            self._fail(nodeid, f"CheckTimeout: {message}")
            self.dump()
            os._exit(WATCHDOG_EXIT)

        watchdog = threading.Timer(self.timeout * WALL_FACTOR, expire)
        watchdog.daemon = True
        watchdog.start()
        try:
            yield
        finally:
            watchdog.cancel()

    # ------------------------------------------------------------------ hooks
    def pytest_collectreport(self, report: pytest.CollectReport) -> None:
        if report.failed:
            self.errors.append(f"{report.nodeid or 'grader'}: {_first_line(str(report.longrepr))[:2000]}")
            self.dump()

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        for item in session.items:
            func = getattr(item, "function", None)
            spec = check_spec(func) if func is not None else check_spec(lambda: None)
            name = item.name[len("test_"):] if item.name.startswith("test_") else item.name
            function = getattr(item, "originalname", item.name)
            self.checks[item.nodeid] = {
                "nodeid": item.nodeid,
                "name": name,
                "function": function[len("test_"):] if function.startswith("test_") else function,
                "max_points": spec.points,
                "hint": spec.hint,
                "hints": list(spec.hints),
                "given": spec.given,
                "after": [a[len("test_"):] if a.startswith("test_") else a for a in spec.after],
                "status": "pending",
                "detail": "",
            }
        functions = {entry["function"] for entry in self.checks.values()}
        for entry in self.checks.values():
            unknown = [a for a in entry["after"] if a not in functions]
            if unknown:  # a grader's own mistake: the chain of causes would silently lose a link
                self.errors.append(f"{entry['nodeid']}: graded(after=...) names {unknown}, which are not checks of "
                                   f"this grader; its checks are {sorted(functions)}")
        self.dump()

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_setup(self, item: pytest.Item) -> Generator[None, Any, Any]:
        self.learner_log.clear()
        with self.time_limit(item.nodeid, "set-up"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_fixture_setup(self, fixturedef: Any, request: Any) -> Generator[None, Any, Any]:
        """A fixture shared by several checks (module or session scope) that met the learner's error while it was set
        up: the later checks that fail without an error of their own were given what it left, so they name it too."""
        before = len(self.learner_log.found)
        try:
            return (yield)
        finally:
            found = self.learner_log.found[before:]
            if found and fixturedef.scope != "function":
                module = getattr(request.node, "module", None)
                key = f"{module if module is not None else '*'}::{fixturedef.argname}"
                self._shared_errors.setdefault(key, []).extend(found)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_call(self, item: pytest.Item) -> Generator[None, Any, Any]:
        with self.time_limit(item.nodeid, "test"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_teardown(self, item: pytest.Item, nextitem: pytest.Item | None) -> Generator[None, Any, Any]:
        with self.time_limit(item.nodeid, "tear-down"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_makereport(
        self, item: pytest.Item, call: pytest.CallInfo[None]
    ) -> Generator[None, pytest.TestReport, pytest.TestReport]:
        report = yield
        entry = self.checks.get(item.nodeid)
        if entry is None:
            return report
        if report.failed:
            exc = call.excinfo.value if call.excinfo is not None else None
            detail = _describe(exc) if exc is not None else "failed"
            learner = self._learner_error(item, exc)
            if learner is not None and learner_location(exc, self.root) is not None:
                detail = learner  # the learner's exception reached the check: it is the reason
            elif learner is not None and learner not in detail:
                detail = f"{learner}; then: {detail}"
            if call.when != "call":
                detail = f"in {call.when}: {detail}"
            if isinstance(exc, HintlessFailure) and entry["status"] != "failed":
                entry["hintless"] = True  # a prediction not made yet: any hint would answer it
                detail = f"{detail} ({exc.note})" if exc.note else detail
            self._fail(item.nodeid, detail)
        elif report.skipped:
            reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
            reason = reason.removeprefix("Skipped: ")
            if reason.startswith(WITHHELD_SKIP):  # the reference it compares with is not in this copy
                entry["given"], entry["status"], entry["detail"] = True, "passed", ""
            else:
                self._fail(item.nodeid, _first_line(f"skipped: {reason}"))
        elif call.when == "call" and entry["status"] == "pending":
            entry["status"] = "passed"
        if call.when == "teardown" and entry["status"] == "pending":
            # A check whose test never ran (nothing failed, nothing passed) did not earn its points.
            entry["status"] = "failed"
            entry["detail"] = "the check did not run"
        if call.when == "teardown":
            self.dump()
        return report

    def pytest_sessionfinish(self, session: pytest.Session, exitstatus: int) -> None:
        self.finished = True
        self.dump()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("rrbot_workshop", "rrbot_workshop grading")
    group.addoption("--rubric-json", default=None, help="write per-check results to this JSON file")
    group.addoption(
        "--check-timeout", type=float, default=30.0, help="time limit per check phase in seconds (0: none)"
    )


@pytest.hookimpl(wrapper=True)
def pytest_make_collect_report(collector: pytest.Collector) -> Generator[None, Any, Any]:
    """A grader file is imported (while it is collected) with its rewritten bytecode kept in ``$RRBOT_WORKSHOP_GRADER_
    PYCACHE``, if that names a folder (module docstring)."""
    folder = os.environ.get(PYCACHE_ENV, "")
    if not folder or not isinstance(collector, pytest.Module):
        return (yield)
    saved = sys.pycache_prefix, sys.dont_write_bytecode
    sys.pycache_prefix, sys.dont_write_bytecode = folder, False
    try:
        return (yield)
    finally:
        sys.pycache_prefix, sys.dont_write_bytecode = saved


def library_not_local_to_hypothesis() -> None:
    """Hypothesis mixes constants found in the *local* modules' source (the code under test) into the examples it
    draws. For a grader that is the learner's code, not the library: installed from a folder (``pip install -e``, as
    the hub's installer does) the library would count as local, its ~200 modules would be parsed on every workspace's
    first grading (most of a CPU-second), and the examples would depend on how the course was installed and on which of
    its modules happen to be imported. Installed into site-packages it is never local; this makes it so everywhere.
    (Hypothesis's own list of site-packages folders; if a later Hypothesis has none, its default stays.)
    """
    try:
        from hypothesis.internal import scrutineer
        from hypothesis.internal.constants_ast import is_local_module_file
    except ImportError:
        return
    folders = getattr(scrutineer, "SITE_PACKAGES_DIRS", None)
    if isinstance(folders, set):
        folders.add(Path(__file__).resolve().parents[2])  # the rrbot_workshop package
        for cached in (getattr(scrutineer.ModuleLocation.from_path, "cache_clear", None),
                       getattr(is_local_module_file, "cache_clear", None)):
            if cached is not None:
                cached()


def pytest_configure(config: pytest.Config) -> None:
    gc.freeze()  # what the grading inherited lives until it ends: collections need not walk it (module docstring)
    library_not_local_to_hypothesis()
    path = config.getoption("--rubric-json")
    collector = RubricCollector(Path(path) if path else None, float(config.getoption("--check-timeout")))
    collector.start_logging()
    config.pluginmanager.register(collector, "rrbot_workshop_rubric")
