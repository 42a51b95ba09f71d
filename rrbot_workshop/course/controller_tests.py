"""Controller tests: a learner's pytest tests of a controller, and how good they are.

ros2_controllers judges a controller by its tests; task 16 judges tests by the wrong controllers they fail on. A test
of the task-8 displacement controller takes the fixture :func:`controller_class` and builds the controller from it,
so the same test can be run on any controller:

* the learner runs ``pytest`` on their file: :func:`controller_class` is their own task-8 class (the library's
  reference while it is unfinished);
* :func:`run_tests` runs a test file in a fresh pytest process once per controller of a list (a correct one, one that
  does nothing, wrong ones) and returns :class:`TestRuns`: what each test did on each controller, and what that means
  (which tests fail on a correct controller, which check nothing, which wrong controllers each test catches);
* the ``%%pytest`` cell magic runs a notebook cell's tests the same way and prints the table.

Controllers are named by a *spec*: ``"task8"`` (the learner's task-8 class, see :func:`default_controller_class`),
``"nothing"`` (:class:`~rrbot_workshop.testing.NullController`), a plugin type name
(``"forward_command_controller/ForwardCommandController"``) or ``"module:Class"``.
"""

from __future__ import annotations

import importlib
import json
import logging
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.exceptions import CourseError, PluginNotFound, UnfinishedExercise

__all__ = ["TASK8", "NOTHING", "controller_class", "default_controller_class", "resolve_controller", "label",
           "Outcome", "TestRuns", "run_tests", "pytest_cell"]

logger = logging.getLogger(__name__)

#: Spec of the learner's task-8 DisplacementController (the library's reference while it is unfinished).
TASK8 = "task8"
#: Spec of the controller that does nothing (:class:`~rrbot_workshop.testing.NullController`).
NOTHING = "nothing"
_REFERENCE = "rrbot_workshop.controllers.displacement:DisplacementController"
_PLUGIN = "rrbot_workshop.course.controller_tests_plugin"
#: What is copied of a test file's folder: at most this many files, of at most this many bytes in all.
_MAX_FILES = 200
_MAX_BYTES = 20 * 1024 * 1024


# --------------------------------------------------------------------------------------------- which controller


def default_controller_class() -> type:
    """The class a learner's tests get when the learner runs them: their task-8 ``DisplacementController`` on the
    current track, or, while it is unfinished, the library's reference (a warning says so)."""
    plugin = next(p for p in tracks.TRACK_PLUGINS if p.task == 8)
    try:
        return tracks.load_track_class(plugin)
    except UnfinishedExercise as exc:
        warnings.warn(f"your task-8 DisplacementController is unfinished ({exc.problem}); the tests run on the "
                      "library's reference instead", stacklevel=2)
        module, _, name = _REFERENCE.partition(":")
        return getattr(importlib.import_module(module), name)  # type: ignore[no-any-return]


@pytest.fixture
def controller_class() -> type:
    """The controller class under test: build the controller with ``controller_class()``.

    Run by the learner, it is :func:`default_controller_class`; the task-16 grader gives each test other controllers
    in its place (a correct one, one that does nothing, wrong ones).
    """
    return default_controller_class()


def resolve_controller(spec: str) -> type:
    """The controller class a spec names (see the module's docstring).

    Raises:
        CourseError: If the spec names no controller class; the message lists the forms a spec takes.
    """
    from rrbot_workshop.middleware import plugins
    from rrbot_workshop.testing import NullController

    if spec == TASK8:
        return default_controller_class()
    if spec == NOTHING:
        return NullController
    try:
        if ":" in spec:
            module, _, name = spec.partition(":")
            found: Any = importlib.import_module(module)
            for part in name.split("."):
                found = getattr(found, part)
        elif "/" in spec:
            tracks.install()
            found = plugins.resolve("controller", spec)
        else:
            found = None
    except (ImportError, AttributeError, PluginNotFound) as exc:
        raise CourseError("controller", spec, f"'{spec}' cannot be loaded ({type(exc).__name__}: {exc})",
                          [TASK8, NOTHING, "<package>/<Class>", "<module>:<Class>"]) from None
    if not isinstance(found, type):
        raise CourseError("controller", spec, f"'{spec}' names no controller class",
                          [TASK8, NOTHING, "<package>/<Class>", "<module>:<Class>"])
    return found


def label(spec: str) -> str:
    """A short name for a spec in a table: the class name, ``task 8`` or ``does nothing``."""
    if spec == TASK8:
        return "task 8"
    if spec == NOTHING:
        return "does nothing"
    return spec.replace(":", "/").rsplit("/", 1)[-1].rsplit(".", 1)[-1]


# --------------------------------------------------------------------------------------------- outcomes


@dataclass(frozen=True)
class Outcome:
    """What one test did on one controller.

    Attributes:
        test: The test's name (with its own parameters, if any).
        controller: The controller's label ("" for a test that does not take ``controller_class``).
        outcome: ``"passed"``, ``"failed"`` or ``"skipped"``.
        kind: For a failure: ``"check"`` (an assert, ``pytest.raises`` or ``pytest.fail``), ``"exception"`` (the code
            raised) or ``"timeout"``.
        message: For a failure or skip: its first line.
        line: The test file's line where it failed (0 if unknown).
        source_line: That line's text.
        checks: Checks that ran and held: ``assert`` statements and ``pytest.raises`` blocks.
        explicit: The test's source calls ``pytest.fail`` or raises ``AssertionError`` itself.
        asserts: The test's source has an ``assert`` statement.
        uses_fixture: The test takes ``controller_class`` (itself or through its fixtures).
    """

    test: str
    controller: str
    outcome: str
    kind: str = ""
    message: str = ""
    line: int = 0
    source_line: str = ""
    checks: int = 0
    explicit: bool = False
    asserts: bool = False
    uses_fixture: bool = True

    @property
    def passed(self) -> bool:
        """True if the test passed."""
        return self.outcome == "passed"

    @property
    def failed(self) -> bool:
        """True if the test failed (in any phase)."""
        return self.outcome == "failed"

    def why(self) -> str:
        """The failure in a line: where in the test file, and what."""
        where = f"line {self.line} (`{self.source_line}`): " if self.line and self.source_line else ""
        return f"{where}{self.message}"


@dataclass
class TestRuns:
    """Every test of a file, run on every controller of a list.

    Attributes:
        labels: The controllers' labels, in the order given.
        outcomes: Every outcome.
        errors: Why the test file (or pytest) could not run, if it could not.
        load_errors: Label -> why that controller could not be loaded.
    """

    __test__ = False  # not a test class for pytest

    labels: list[str]
    outcomes: list[Outcome]
    errors: list[str]
    load_errors: dict[str, str]

    @property
    def tests(self) -> list[str]:
        """The tests, in the file's order."""
        return list(dict.fromkeys(o.test for o in self.outcomes))

    def outcome(self, test: str, controller: str) -> Outcome | None:
        """What ``test`` did on ``controller`` (for a test without the fixture: what it did at all)."""
        for o in self.outcomes:
            if o.test == test and o.controller in (controller, ""):
                return o
        return None

    def without_fixture(self) -> list[str]:
        """Tests that do not take ``controller_class``: they always test the same controller."""
        return [t for t in self.tests if not any(o.uses_fixture for o in self.outcomes if o.test == t)]

    def failing_on(self, correct: str) -> list[Outcome]:
        """Tests that do not pass on the correct controller ``correct`` (failed or skipped)."""
        found = [self.outcome(t, correct) for t in self.tests if t not in self.without_fixture()]
        return [o for o in found if o is not None and not o.passed]

    def checks_nothing(self, correct: str) -> list[Outcome]:
        """Tests that pass on ``correct`` without running a single check (no assert held, no ``pytest.raises``)."""
        found = [self.outcome(t, correct) for t in self.tests if t not in self.without_fixture()]
        return [o for o in found if o is not None and o.passed and o.checks == 0 and not o.explicit]

    def catches(self, test: str, wrong: str, correct: str, nothing: str) -> bool:
        """Whether ``test`` catches the wrong controller ``wrong``: it passes on ``correct`` and checks something there,
        and fails on ``wrong``; a test that also passes on ``nothing`` (a controller that does nothing) must fail on
        ``wrong`` by a failed check, not by an exception (that would show only that the code raised)."""
        good, bad, idle = self.outcome(test, correct), self.outcome(test, wrong), self.outcome(test, nothing)
        if good is None or bad is None or not good.uses_fixture or not good.passed or not bad.failed:
            return False
        if good.checks == 0 and not good.explicit:
            return False
        return bad.kind == "check" or idle is None or not idle.passed

    def catchers(self, wrong: str, correct: str, nothing: str) -> list[str]:
        """The tests that catch ``wrong`` (see :meth:`catches`)."""
        return [t for t in self.tests if self.catches(t, wrong, correct, nothing)]

    def raised_only(self, wrong: str, correct: str, nothing: str) -> list[Outcome]:
        """Failures on ``wrong`` that do not count: an exception in a test that passes on ``nothing`` as well."""
        out = []
        for test in self.tests:
            good, bad, idle = self.outcome(test, correct), self.outcome(test, wrong), self.outcome(test, nothing)
            if (good is not None and good.passed and bad is not None and bad.failed and bad.kind != "check"
                    and idle is not None and idle.passed and not self.catches(test, wrong, correct, nothing)):
                out.append(bad)
        return out

    def table(self) -> str:
        """Every test against every controller, ``pass`` or ``FAIL``, then each failure's line and reason."""
        if self.errors:
            return "the tests could not run: " + "; ".join(self.errors)
        tests = self.tests
        if not tests:
            return "no tests (pytest collects functions whose names start with test_)"
        width = max(len(t) for t in tests) + 2
        columns = [max(len(lb), 4) + 2 for lb in self.labels]
        lines = [(" " * width + "".join(lb.ljust(c) for lb, c in zip(self.labels, columns, strict=True))).rstrip()]
        failures = []
        for test in tests:
            cells = []
            for lb, c in zip(self.labels, columns, strict=True):
                o = self.outcome(test, lb)
                mark = "-" if o is None else {"passed": "pass", "failed": "FAIL"}.get(o.outcome, "skip")
                cells.append(mark.ljust(c))
                if o is not None and not o.passed and (o.controller or lb == self.labels[0]):
                    failures.append(f"{test} on {o.controller or 'its own controller'}: {o.why()}")
            lines.append(test.ljust(width) + "".join(cells).rstrip())
        for lb, why in self.load_errors.items():
            lines.append(f"{lb} could not be loaded: {why}")
        return "\n".join(lines + ([""] + failures if failures else []))

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        printer.text(self.table())


# --------------------------------------------------------------------------------------------- running


def _copy_folder(source: Path, dest: Path) -> None:
    """Copy the regular files of ``source`` (recursively; no links, hidden files or ``__pycache__``; at most
    :data:`_MAX_FILES` files and :data:`_MAX_BYTES` bytes) to ``dest``: the test file's helpers and data come along."""
    count = size = 0
    for path in sorted(source.rglob("*")):
        rel = path.relative_to(source)
        if any(part.startswith(".") or part == "__pycache__" for part in rel.parts) or path.is_symlink() \
                or not path.is_file():
            continue
        count, size = count + 1, size + path.stat().st_size
        if count > _MAX_FILES or size > _MAX_BYTES:
            break
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)


def run_tests(
    test_file: str | os.PathLike[str],
    against: Sequence[str] | Mapping[str, str],
    *,
    paths: Sequence[str | os.PathLike[str]] | None = None,
    timeout: float = 2.0,
    total_timeout: float = 120.0,
) -> TestRuns:
    """Run the pytest tests of ``test_file`` once per controller, in a fresh Python process.

    The test file's folder is copied first (a ``conftest.py``, helpers and data files come along), so the learner's
    folder is only read, and every run sees the files as they are now.

    Args:
        test_file: The test file.
        against: Controller specs (labels made by :func:`label`), or label -> spec.
        paths: Folders to put on the test process's ``sys.path`` (where ``module:Class`` specs live); default the
            course's ``tests/tasks/`` (the graders' public wrong controllers, ``task16_public_mutants:...``).
        timeout: CPU seconds each phase of a test may use.
        total_timeout: Seconds the whole run may take.

    Raises:
        CourseError: If ``test_file`` is not a file, or two controllers get the same label.
    """
    source = Path(test_file).expanduser().resolve()
    if not source.is_file():
        raise CourseError("test file", str(source), f"there is no test file {source}")
    named = dict(against) if isinstance(against, Mapping) else {label(s): s for s in against}
    if not isinstance(against, Mapping) and len(named) != len(against):
        raise CourseError("controllers", list(against), "two controllers get the same label; give label -> spec")
    ids = {f"c{i}": lb for i, lb in enumerate(named)}
    with tempfile.TemporaryDirectory(prefix="rrbot_controller_tests_") as tmp:
        folder = Path(tmp) / "tests"
        folder.mkdir()
        _copy_folder(source.parent, folder)
        (folder / source.name).write_bytes(source.read_bytes())
        (Path(tmp) / "pytest.ini").write_text("[pytest]\n", encoding="utf-8")
        specs, out = Path(tmp) / "controllers.json", Path(tmp) / "outcomes.json"
        specs.write_text(json.dumps({cid: named[lb] for cid, lb in ids.items()}), encoding="utf-8")
        env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}
        env[tracks.ROOT_ENV] = str(tracks.course_root())
        env[tracks.TRACK_ENV] = tracks.current_track()
        if paths is None:
            graders = tracks.course_root() / "tests" / "tasks"
            paths = [graders] if graders.is_dir() else []
        extra = [str(Path(p).resolve()) for p in paths]
        env["PYTHONPATH"] = os.pathsep.join([*extra, *([env["PYTHONPATH"]] if env.get("PYTHONPATH") else [])])
        cmd = [sys.executable, "-m", "pytest", str(folder / source.name), "-p", _PLUGIN, "-p", "no:cacheprovider",
               "-c", str(Path(tmp) / "pytest.ini"), "--rootdir", tmp, "-o", "enable_assertion_pass_hook=true",
               "-q", "--no-header", "-rN", "--tb=no", "--color=no", "--controllers-json", str(specs), "--outcomes-json", str(out),
               "--test-timeout", f"{timeout:g}"]
        errors: list[str] = []
        try:
            proc = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True, timeout=total_timeout,
                                  check=False)
            output = proc.stdout + proc.stderr
        except subprocess.TimeoutExpired:
            output = ""
            errors.append(f"the tests did not finish within {total_timeout:g} s")
        data: dict[str, Any] = {}
        if out.is_file():
            data = json.loads(out.read_text(encoding="utf-8"))
        elif not errors:
            tail = [line for line in output.strip().splitlines() if line.strip()][-3:]
            errors.append("pytest did not start: " + " ".join(tail))
    errors.extend(str(e) for e in data.get("errors", []))
    outcomes = [Outcome(test=str(r["test"]), controller=ids.get(str(r["controller"]), ""), outcome=str(r["outcome"]),
                        kind=str(r["kind"]), message=str(r["message"]), line=int(r["line"]),
                        source_line=str(r["source_line"]), checks=int(r["checks"]), explicit=bool(r["explicit"]),
                        asserts=bool(r["asserts"]), uses_fixture=bool(r["uses_fixture"]))
                for r in data.get("tests", [])]
    load_errors = {ids[c]: str(why) for c, why in data.get("load_errors", {}).items() if c in ids}
    return TestRuns(list(named), outcomes, errors, load_errors)


def pytest_cell(line: str, cell: str) -> None:
    """``%%pytest --against SPEC [SPEC ...]``: run the cell's tests once per controller and print the table.

    The cell is a test module of its own (its imports included); each test that takes ``controller_class`` runs on
    every controller named (default: ``task8``). Bad arguments print a line saying what is valid.
    """
    args = shlex.split(line)
    if args and args[0] == "--against":
        args = args[1:]
    elif args:
        print(f"%%pytest: unknown argument {args[0]!r}; usage: %%pytest --against SPEC [SPEC ...] with SPEC one of "
              f"{TASK8}, {NOTHING}, <package>/<Class>, <module>:<Class>")
        return
    specs = args or [TASK8]
    if TASK8 in specs:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            default_controller_class()
        if said:
            print(f"'{label(TASK8)}': {said[0].message}.")
    with tempfile.TemporaryDirectory(prefix="rrbot_cell_tests_") as tmp:
        path = Path(tmp) / "test_cell.py"
        path.write_text(cell, encoding="utf-8")
        try:
            runs = run_tests(path, specs)
        except CourseError as exc:
            print(f"%%pytest: {exc}")
            return
    print(runs.table())
