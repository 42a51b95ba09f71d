"""Controller tests run once per controller: what each test did on each, and what that says about the test.

One crafted test file of the forward command controller is run (in its own pytest process, as a grader runs a
learner's file) on the library's ``ForwardCommandController`` and on a controller that does nothing; each test below
reads one behaviour off the outcomes.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import pytest

from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.controllers.forward_command import ForwardCommandController
from rrbot_workshop.course import tracks
from rrbot_workshop.course.controller_tests import (
    NOTHING,
    TASK8,
    TestRuns,
    default_controller_class,
    label,
    pytest_cell,
    resolve_controller,
    run_tests,
)
from rrbot_workshop.course.controller_tests_plugin import split_nodeid
from rrbot_workshop.exceptions import CourseError
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.testing import ControllerHarness, NullController

FORWARD = "forward_command_controller/ForwardCommandController"
CORRECT, IDLE = label(FORWARD), label(NOTHING)

TESTS = '''
import pytest

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.lifecycle import ReturnType, State
from rrbot_workshop.msgs import Float64MultiArray
from rrbot_workshop.testing import ControllerHarness

JOINTS = ["j1/position", "j2/position"]


@pytest.fixture
def harness(controller_class):
    h = ControllerHarness(controller_class(), "fwd", {"joints": ["j1", "j2"], "interface_name": "position"},
                          command_values={"j1/position": 1.5, "j2/position": 2.5})
    h.configure()
    h.activate()
    return h


def test_a_command_is_written(harness):
    harness.publish("~/commands", Float64MultiArray(data=[10.0, 20.0]))
    harness.update()
    assert harness.values(JOINTS) == [10.0, 20.0]


def test_empty_joints_refused(controller_class):
    with pytest.raises(ParameterError):
        ControllerHarness(controller_class(), "fwd", {"joints": [], "interface_name": "position"})


def test_update_runs(harness):
    harness.update()


def test_asserts_in_a_branch_that_does_not_run(harness):
    if harness.update() is ReturnType.ERROR:
        assert False


def test_fails_when_it_must(harness):
    if harness.values(JOINTS) != [1.5, 2.5]:
        pytest.fail("moved")


def test_wrong_expectation(harness):
    harness.publish("~/commands", Float64MultiArray(data=[10.0, 20.0]))
    harness.update()
    assert harness.values(JOINTS) == [11.5, 22.5]


def test_raises_on_the_idle_controller(controller_class):
    h = ControllerHarness(controller_class(), "fwd", {"joints": ["j1"], "interface_name": "position"},
                          command_values={"j1/position": 0.0})
    h.configure()
    assert h.controller.command_interface_configuration().names[0] == "j1/position"


def test_without_the_fixture():
    assert True


@pytest.mark.parametrize("value", [1.0, 2.0])
def test_with_its_own_parameter(harness, value):
    harness.publish("~/commands", Float64MultiArray(data=[value, value]))
    harness.update()
    assert harness.values(JOINTS) == [value, value]


def test_loops_forever(controller_class):
    while True:
        pass
'''


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("learner")
    (path / "test_forward.py").write_text(TESTS)
    return path


def _digest(folder: Path) -> str:
    return hashlib.sha256(b"".join(p.name.encode() + p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()))\
        .hexdigest()


@pytest.fixture(scope="module")
def runs(folder: Path) -> TestRuns:
    return run_tests(folder / "test_forward.py", [FORWARD, NOTHING], timeout=0.5)


def test_every_test_runs_on_every_controller(runs: TestRuns) -> None:
    assert runs.labels == [CORRECT, IDLE] and not runs.errors and not runs.load_errors
    assert runs.tests[:3] == ["test_a_command_is_written", "test_empty_joints_refused", "test_update_runs"]
    assert {"test_with_its_own_parameter[1.0]", "test_with_its_own_parameter[2.0]"} <= set(runs.tests)
    for test in ("test_a_command_is_written", "test_empty_joints_refused"):
        assert runs.outcome(test, CORRECT).passed and runs.outcome(test, IDLE).failed  # type: ignore[union-attr]


def test_the_learners_folder_is_only_read(folder: Path) -> None:
    before = _digest(folder)
    run_tests(folder / "test_forward.py", [NOTHING], timeout=0.5)
    assert _digest(folder) == before and not (folder / "__pycache__").exists()


def test_checks_that_ran_are_counted(runs: TestRuns) -> None:
    assert runs.outcome("test_a_command_is_written", CORRECT).checks == 1  # type: ignore[union-attr]
    assert runs.outcome("test_empty_joints_refused", CORRECT).checks == 1  # type: ignore[union-attr]
    assert runs.outcome("test_with_its_own_parameter[2.0]", CORRECT).checks == 1  # type: ignore[union-attr]


def test_a_test_that_checks_nothing_is_found(runs: TestRuns) -> None:
    nothing = {o.test: o for o in runs.checks_nothing(CORRECT)}
    assert set(nothing) == {"test_update_runs", "test_asserts_in_a_branch_that_does_not_run"}
    assert nothing["test_asserts_in_a_branch_that_does_not_run"].asserts
    assert not nothing["test_update_runs"].asserts


def test_a_test_that_fails_explicitly_is_not_said_to_check_nothing(runs: TestRuns) -> None:
    outcome = runs.outcome("test_fails_when_it_must", CORRECT)
    assert outcome is not None and outcome.passed and outcome.checks == 0 and outcome.explicit


def test_a_failed_check_is_told_from_an_exception(runs: TestRuns) -> None:
    check = runs.outcome("test_a_command_is_written", IDLE)
    raised = runs.outcome("test_raises_on_the_idle_controller", IDLE)
    assert check is not None and check.kind == "check" and "assert [1.5, 2.5] == [10.0, 20.0]" in check.message
    assert raised is not None and raised.kind == "exception" and raised.message.startswith("IndexError")
    assert raised.source_line.startswith("assert h.controller.command_interface_configuration()")


def test_a_test_that_fails_on_the_correct_controller_is_reported_with_its_line(runs: TestRuns) -> None:
    failing = {o.test: o for o in runs.failing_on(CORRECT)}
    assert "test_wrong_expectation" in failing
    assert failing["test_wrong_expectation"].source_line == "assert harness.values(JOINTS) == [11.5, 22.5]"
    assert "line " in failing["test_wrong_expectation"].why()


def test_a_test_without_the_fixture_runs_once_and_is_named(runs: TestRuns) -> None:
    assert runs.without_fixture() == ["test_without_the_fixture"]
    assert [o.controller for o in runs.outcomes if o.test == "test_without_the_fixture"] == [""]


def test_a_test_that_loops_is_stopped_and_not_run_again(runs: TestRuns) -> None:
    first, second = runs.outcome("test_loops_forever", CORRECT), runs.outcome("test_loops_forever", IDLE)
    assert first is not None and first.kind == "timeout" and "CPU time" in first.message
    assert second is not None and second.outcome == "skipped"


def test_catching_needs_a_check_on_the_correct_controller_and_a_failure_on_the_wrong_one(runs: TestRuns) -> None:
    """Here the do-nothing controller plays a wrong one: the test that writes commands catches it, the test that
    checks nothing does not, and a test that raised on it counts because it does not pass on it by doing nothing."""
    assert runs.catches("test_a_command_is_written", IDLE, CORRECT, IDLE)
    assert not runs.catches("test_update_runs", IDLE, CORRECT, IDLE)
    assert not runs.catches("test_wrong_expectation", IDLE, CORRECT, IDLE)
    assert runs.catches("test_raises_on_the_idle_controller", IDLE, CORRECT, IDLE)


def test_a_failure_by_exception_of_a_test_that_passes_on_the_idle_controller_does_not_catch() -> None:
    from rrbot_workshop.course.controller_tests import Outcome

    runs = TestRuns(["ok", "idle", "bad"], [
        Outcome("test_x", "ok", "passed", checks=1), Outcome("test_x", "idle", "passed", checks=1),
        Outcome("test_x", "bad", "failed", kind="exception", message="KeyError: 'j1'"),
    ], [], {})
    assert not runs.catches("test_x", "bad", "ok", "idle")
    assert [o.message for o in runs.raised_only("bad", "ok", "idle")] == ["KeyError: 'j1'"]


def test_the_table_shows_each_test_on_each_controller_and_why_it_failed(runs: TestRuns) -> None:
    text = runs.table()
    header, first = text.splitlines()[:2]
    assert header.split() == ["ForwardCommandController", "does", "nothing"]
    assert first.split() == ["test_a_command_is_written", "pass", "FAIL"]
    assert "test_wrong_expectation on ForwardCommandController: line" in text


def test_a_file_that_does_not_parse_is_one_error(tmp_path: Path) -> None:
    (tmp_path / "test_broken.py").write_text("def test_x(:\n    pass\n")
    runs = run_tests(tmp_path / "test_broken.py", [NOTHING])
    assert runs.errors and "SyntaxError" in " ".join(runs.errors) and runs.outcomes == []
    assert runs.table().startswith("the tests could not run")


def test_a_missing_test_file_is_refused(tmp_path: Path) -> None:
    with pytest.raises(CourseError, match="no test file"):
        run_tests(tmp_path / "test_missing.py", [NOTHING])


def test_two_controllers_with_one_label_are_refused(folder: Path) -> None:
    with pytest.raises(CourseError, match="same label"):
        run_tests(folder / "test_forward.py", [NOTHING, NOTHING])


def test_split_nodeid_keeps_the_tests_own_parameters() -> None:
    assert split_nodeid("t.py::test_x[cut=c2]") == ("test_x", "c2")
    assert split_nodeid("t.py::test_x[a-b-cut=c10]") == ("test_x[a-b]", "c10")
    assert split_nodeid("t.py::test_x[cut=c0-1.0]") == ("test_x[1.0]", "c0")
    assert split_nodeid("t.py::test_y") == ("test_y", "")
    assert split_nodeid("t.py::TestA::test_y[p]") == ("TestA::test_y[p]", "")


def test_specs_name_controllers() -> None:
    assert resolve_controller(NOTHING) is NullController
    assert resolve_controller(FORWARD) is ForwardCommandController
    assert resolve_controller("rrbot_workshop.controllers.displacement:DisplacementController") is DisplacementController
    assert label("task16_public_mutants:StateNotAdded") == "StateNotAdded" and label(TASK8) == "task 8"


@pytest.mark.parametrize("spec", ["rrbot_workshop.controllers:NoSuchController", "no_such_module:X", "plain", "no/Such",
                                  "rrbot_workshop.controllers.displacement:forbidden_interface_name_prefix"])
def test_a_spec_that_names_no_controller_class_is_refused(spec: str) -> None:
    with pytest.raises(CourseError, match="valid: .*nothing.*task8"):
        resolve_controller(spec)


def test_the_learners_class_stands_in_while_finished_else_the_reference(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(tracks.TRACK_ENV, "exercises")
    tracks.set_track(None)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        assert default_controller_class() is DisplacementController  # the handed-out exercise is unfinished
    assert "unfinished" in str(said[0].message) and "library's reference" in str(said[0].message)
    if (tracks.course_root() / "solutions").is_dir():
        monkeypatch.setenv(tracks.TRACK_ENV, "solutions")
        cls = default_controller_class()
        assert cls is not DisplacementController and cls.__name__ == "DisplacementController"


def test_the_null_controller_succeeds_and_does_nothing() -> None:
    h = ControllerHarness(NullController(), "idle", {"anything": 1}, command_values={"j/position": 0.5})
    assert h.configure() is State.INACTIVE and h.activate() is State.ACTIVE
    assert h.update() is ReturnType.OK and h.value("j/position") == 0.5
    assert h.deactivate() is State.INACTIVE and h.bus.topic_names_and_types() == []


def test_the_cell_magic_prints_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    pytest_cell(f"--against {FORWARD} {NOTHING}", "def test_x(controller_class):\n    assert controller_class()\n")
    out = capsys.readouterr().out
    assert out.splitlines()[1].split() == ["test_x", "pass", "pass"]


def test_the_cell_magic_says_what_is_valid(capsys: pytest.CaptureFixture[str]) -> None:
    pytest_cell("--controllers nothing", "def test_x():\n    pass\n")
    assert "usage: %%pytest --against SPEC" in capsys.readouterr().out
    pytest_cell("--against no_such_module:X", "def test_x(controller_class):\n    pass\n")
    assert "no_such_module:X" in capsys.readouterr().out


def test_the_test_files_folder_comes_along(tmp_path: Path) -> None:
    (tmp_path / "expected.txt").write_text("0.5\n")
    (tmp_path / "helpers.py").write_text("JOINTS = ['j1']\n")
    (tmp_path / "test_reads.py").write_text(
        "from pathlib import Path\n\nfrom helpers import JOINTS\n\n\n"
        "def test_reads_its_data(controller_class):\n"
        "    assert float((Path(__file__).parent / 'expected.txt').read_text()) == 0.5 and JOINTS == ['j1']\n")
    runs = run_tests(tmp_path / "test_reads.py", [NOTHING])
    assert [o.outcome for o in runs.outcomes] == ["passed"], runs.table()
