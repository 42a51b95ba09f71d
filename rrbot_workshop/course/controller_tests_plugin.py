"""pytest plugin that runs each test of a file once per controller and records what happened: the inner side of
:func:`rrbot_workshop.course.controller_tests.run_tests`.

It is started as ``python -m pytest FILE -p rrbot_workshop.course.controller_tests_plugin --controllers-json IN
--outcomes-json OUT --test-timeout S -o enable_assertion_pass_hook=true``. ``IN`` maps controller ids to controller
specs (see :func:`~rrbot_workshop.course.controller_tests.resolve_controller`); every test that takes the fixture
``controller_class`` (itself, or through a fixture of its own) is parametrized over them, which overrides the fixture.
For each test and controller ``OUT`` gets the outcome, whether a failure was a failed check (``assert``,
``pytest.raises`` that saw nothing raised, ``pytest.fail``) or something the code raised, where in the test file it
failed, and how many checks the test passed (``assert`` statements that held, ``pytest.raises`` blocks entered).

Each phase of a test gets ``S`` seconds of CPU time (ten times that of waiting): a learner's test may loop forever.
A test that runs out of time on the first controller (a grader's correct one) is skipped on the others.
"""

from __future__ import annotations

import contextlib
import inspect
import json
import linecache
import os
import re
import signal
import threading
import time
from collections import Counter
from collections.abc import Generator, Iterator
from pathlib import Path
from typing import Any

import pytest

__all__ = ["FIXTURE", "TestTimeout", "Recorder", "split_nodeid"]

#: The fixture a test takes to be given the controller under test.
FIXTURE = "controller_class"
#: How the plugin's parameter shows in a test's id: ``test_x[cut=c3]``.
_TOKEN = re.compile(r"(?:^|-)cut=(\w+)(?=-|$)")
#: A test whose own source says so checks something even if no check pytest counts ran on a correct controller:
#: ``pytest.fail``, ``raise AssertionError``, ``pytest.raises``, ``numpy.testing.assert_allclose``, ``self.assertEqual``.
_EXPLICIT = re.compile(r"\bfail\s*\(|raise\s+AssertionError|\braises\s*\(|\bassert_\w+\s*\(|\.assert[A-Z]\w*\s*\(")
_ASSERT = re.compile(r"^\s*assert\b", re.MULTILINE)
#: Seconds between two writes of the outcomes while tests run.
_DUMP_EVERY = 2.0


class TestTimeout(BaseException):  # noqa: N818 - reads as an event, like KeyboardInterrupt
    """Raised inside a test phase that ran longer than its time limit."""

    __test__ = False  # not a test class for pytest


def split_nodeid(nodeid: str) -> tuple[str, str]:
    """``(test, controller id)`` of a pytest node id: ``"t.py::test_x[a-cut=c2]"`` -> ``("test_x[a]", "c2")``.

    The test keeps its own parameters; the controller id is ``""`` for a test that was not given one.
    """
    name = nodeid.split("::", 1)[1] if "::" in nodeid else nodeid
    base, bracket, rest = name.partition("[")
    if not bracket:
        return base, ""
    params = rest[:-1] if rest.endswith("]") else rest
    found = _TOKEN.search(params)
    if found is None:
        return name, ""
    left = (params[: found.start()] + params[found.end():]).strip("-")
    return (f"{base}[{left}]" if left else base), found.group(1)


class Recorder:
    """Parametrizes the tests over the controllers, limits each phase's time, and writes the outcomes.

    Args:
        specs: Controller id -> spec.
        out: The JSON file written after each test.
        timeout: CPU seconds per test phase (0: no limit).
    """

    def __init__(self, specs: dict[str, str], out: Path, timeout: float) -> None:
        from rrbot_workshop.course.controller_tests import resolve_controller

        self.out = out
        self.timeout = timeout
        self.classes: dict[str, type] = {}
        self.load_errors: dict[str, str] = {}
        for cid, spec in specs.items():
            try:
                self.classes[cid] = resolve_controller(spec)
            except Exception as exc:  # noqa: BLE001 - reported with the outcomes
                self.load_errors[cid] = _one_line(f"{type(exc).__name__}: {exc}")
        self.records: dict[str, dict[str, Any]] = {}
        self.errors: list[str] = []
        self.checks: Counter[str] = Counter()
        #: Test -> why it is not run again: it ran out of time on the first controller (the correct one, for a grader).
        self.timed_out: dict[str, str] = {}
        self.current = ""
        self._raises = pytest.raises
        self._dumped = time.monotonic()

    # ------------------------------------------------------------------ checks that ran
    def count_raises(self, *args: Any, **kwargs: Any) -> Any:
        """``pytest.raises``, counted as a check of the running test."""
        self.checks[self.current] += 1
        return self._raises(*args, **kwargs)

    def pytest_assertion_pass(self, item: pytest.Item, lineno: int, orig: str, expl: str) -> None:
        self.checks[item.nodeid] += 1

    # ------------------------------------------------------------------ collection
    def pytest_generate_tests(self, metafunc: pytest.Metafunc) -> None:
        if FIXTURE in metafunc.fixturenames and self.classes:
            metafunc.parametrize(FIXTURE, list(self.classes.values()), ids=[f"cut={c}" for c in self.classes])

    def pytest_collectreport(self, report: pytest.CollectReport) -> None:
        if report.failed:
            text = str(report.longrepr)
            said = [line[1:].strip() for line in text.splitlines() if line.startswith("E ")]
            self.errors.append(_one_line(" ".join(said) or text.strip().splitlines()[-1] if text.strip() else "error"))

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        sources: dict[Any, str] = {}
        for item in session.items:
            test, cid = split_nodeid(item.nodeid)
            function = getattr(item, "function", None)
            if function not in sources:
                sources[function] = ""
                with contextlib.suppress(OSError, TypeError):
                    sources[function] = inspect.getsource(function) if function is not None else ""
            source = sources[function]
            self.records[item.nodeid] = {
                "test": test, "controller": cid, "outcome": "pending", "kind": "", "message": "", "line": 0,
                "source_line": "", "checks": 0, "explicit": bool(_EXPLICIT.search(source)),
                "asserts": bool(_ASSERT.search(source)), "uses_fixture": FIXTURE in getattr(item, "fixturenames", ()),
            }
        self.dump()

    # ------------------------------------------------------------------ running
    @contextlib.contextmanager
    def time_limit(self, phase: str) -> Iterator[None]:
        """Raise :class:`TestTimeout` in the block after :attr:`timeout` s of CPU (ten times that of waiting)."""
        if self.timeout <= 0 or not hasattr(signal, "SIGPROF") or threading.current_thread() is not threading.main_thread():
            yield
            return

        def on_cpu(signum: int, frame: Any) -> None:
            raise TestTimeout(f"the test's {phase} used more than {self.timeout:g} s of CPU time (an endless loop?)")

        def on_wall(signum: int, frame: Any) -> None:
            raise TestTimeout(f"the test's {phase} waited more than {self.timeout * 10:g} s without finishing")

        previous = signal.signal(signal.SIGPROF, on_cpu), signal.signal(signal.SIGALRM, on_wall)
        signal.setitimer(signal.ITIMER_PROF, self.timeout)
        signal.setitimer(signal.ITIMER_REAL, self.timeout * 10)
        try:
            yield
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0)
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGPROF, previous[0])
            signal.signal(signal.SIGALRM, previous[1])

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_setup(self, item: pytest.Item) -> Generator[None, Any, Any]:
        self.current = item.nodeid
        test = split_nodeid(item.nodeid)[0]
        if test in self.timed_out:  # once is enough: a test that loops would cost its time limit on every controller
            pytest.skip(f"not run: it ran out of time on {self.timed_out[test]}")
        with self.time_limit("set-up"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_call(self, item: pytest.Item) -> Generator[None, Any, Any]:
        with self.time_limit("run"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_teardown(self, item: pytest.Item, nextitem: pytest.Item | None) -> Generator[None, Any, Any]:
        with self.time_limit("tear-down"):
            return (yield)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_makereport(self, item: pytest.Item, call: pytest.CallInfo[None]) -> Generator[
            None, pytest.TestReport, pytest.TestReport]:
        report = yield
        record = self.records.get(item.nodeid)
        if record is None:
            return report
        if report.failed and record["outcome"] != "failed":
            record["outcome"] = "failed"
            exc = call.excinfo.value if call.excinfo is not None else None
            record["kind"] = _kind(exc)
            record["message"] = ("in " + call.when + ": " if call.when != "call" else "") + _message(exc)
            record["line"], record["source_line"] = _where(call, Path(str(item.path)))
            if record["kind"] == "timeout" and record["controller"] == next(iter(self.classes), ""):
                self.timed_out.setdefault(record["test"], "the first controller")
        elif report.skipped and record["outcome"] == "pending":
            record["outcome"] = "skipped"
            longrepr = report.longrepr
            record["message"] = _one_line(longrepr[2] if isinstance(longrepr, tuple) else str(longrepr))
        elif call.when == "call" and report.passed and record["outcome"] == "pending":
            record["outcome"] = "passed"
        if call.when == "teardown":
            record["checks"] = self.checks[item.nodeid]
            if record["outcome"] == "pending":
                record["outcome"] = "skipped"
            if time.monotonic() - self._dumped > _DUMP_EVERY:  # a run killed from outside still says what it did
                self.dump()
        return report

    def pytest_sessionfinish(self, session: pytest.Session, exitstatus: int) -> None:
        self.dump()

    def dump(self) -> None:
        """Write the outcomes so far (atomically)."""
        self._dumped = time.monotonic()
        data = {"errors": self.errors, "load_errors": self.load_errors, "tests": list(self.records.values())}
        tmp = self.out.with_name(self.out.name + ".tmp")
        tmp.write_text(json.dumps(data), encoding="utf-8")
        os.replace(tmp, self.out)


def _one_line(text: str, limit: int = 400) -> str:
    line = " ".join(part.strip() for part in str(text).strip().splitlines() if part.strip())
    return line if len(line) <= limit else line[: limit - 3].rstrip() + "..."


def _kind(exc: BaseException | None) -> str:
    if isinstance(exc, TestTimeout):
        return "timeout"
    if isinstance(exc, AssertionError | pytest.fail.Exception):
        return "check"
    return "exception"


def _message(exc: BaseException | None) -> str:
    if exc is None:
        return "failed"
    if isinstance(exc, AssertionError):
        first = str(exc).strip().splitlines()
        return _one_line(first[0]) if first else "assert failed"
    if isinstance(exc, pytest.fail.Exception | TestTimeout):
        return _one_line(str(exc))
    return _one_line(f"{type(exc).__name__}: {exc}")


def _where(call: pytest.CallInfo[None], path: Path) -> tuple[int, str]:
    """Line number and text of the last line of the test file in the failure's traceback."""
    if call.excinfo is None:
        return 0, ""
    for entry in reversed(call.excinfo.traceback):
        if Path(str(entry.path)) == path:
            lineno = entry.lineno + 1
            return lineno, linecache.getline(str(path), lineno).strip()
    return 0, ""


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("controller_tests", "run tests once per controller")
    group.addoption("--controllers-json", default=None, help="controller id -> spec (JSON file)")
    group.addoption("--outcomes-json", default=None, help="write each test's outcome per controller to this file")
    group.addoption("--test-timeout", type=float, default=5.0, help="CPU seconds per test phase (0: none)")


def pytest_configure(config: pytest.Config) -> None:
    specs_file = config.getoption("--controllers-json")
    out = config.getoption("--outcomes-json")
    if not specs_file or not out:
        return
    specs = json.loads(Path(specs_file).read_text(encoding="utf-8"))
    recorder = Recorder({str(k): str(v) for k, v in specs.items()}, Path(out), float(config.getoption("--test-timeout")))
    config.pluginmanager.register(recorder, "controller_tests_recorder")
    pytest.raises = recorder.count_raises  # type: ignore[assignment]  # a pytest.raises block is a check too
