"""Predictions are graded as they were before their outcomes were shown (tasks 6 and 14).

Showing an outcome (notebook 14's reveal cells, notebook 06's prediction cell) first seals the learner's prediction in
the attempt log; a prediction changed afterwards earns nothing, and the reason says so. No hint is shown for a
prediction not made yet. Nothing here states an outcome: the predictions used are guesses, graded as they come.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import fault_lab, tracks
from rrbot_workshop.course.grading import attempts, grade, sealed
from rrbot_workshop.course.grading.rubric import Rubric

REPO = Path(__file__).resolve().parents[2]
NOTEBOOK = REPO / "notebooks" / "14_fault_lab.ipynb"
CONTROLLERS = ("joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller")


def _guess(state: str, position: float) -> dict[str, object]:
    """A complete prediction of one fault: every state ``state``, both joints at ``position``."""
    return {"controllers": dict.fromkeys(CONTROLLERS, state), "hardware": {"rrbot": state},
            "joints": [position, position]}


def _predictions_file(guesses: dict[str, dict[str, object]]) -> str:
    return f'"""Task 14: guesses."""\n\nPREDICTIONS = {json.dumps(guesses, indent=4)}\n'


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A course folder with task 14's grader and an exercise whose every prediction is a guess (all 'active', 0.0)."""
    root = tmp_path / "course"
    (root / "tests" / "tasks").mkdir(parents=True)
    for name in ("conftest.py", "test_task14_fault_lab.py"):
        shutil.copy(REPO / "tests" / "tasks" / name, root / "tests" / "tasks" / name)
    task = root / "exercises" / "task14_fault_lab"
    task.mkdir(parents=True)
    (task / "predictions.py").write_text(_predictions_file({f: _guess("active", 0.0) for f in fault_lab.FAULTS}))
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    for env in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV, attempts.ENV):
        monkeypatch.delenv(env, raising=False)
    tracks.set_track(None)
    return root


def test_a_seal_keeps_the_first_prediction_and_compares_parts(course: Path) -> None:
    first = {"nan_command": _guess("inactive", 0.3)}
    assert sealed.seal(14, first, ["nan_command"], now=1000.0) == ["nan_command"]
    assert sealed.seal(14, {"nan_command": _guess("active", 0.1)}, ["nan_command"]) == [], "the first seal stays"
    kept = sealed.seals(14)["nan_command"]
    assert kept.time == 1000.0 and json.loads(kept.prediction) == first["nan_command"]
    assert sealed.changed_since_sealed(14, "nan_command", _guess("inactive", 0.3)) == ""
    assert sealed.changed_since_sealed(14, "nan_command", {**_guess("inactive", 0.3), "joints": (0.3, 0.3)}) == "", (
        "a tuple is the same prediction as a list")
    changed = {**_guess("inactive", 0.3), "joints": [0.4, 0.4]}
    assert sealed.changed_since_sealed(14, "nan_command", changed, keys=("controllers", "hardware")) == ""
    reason = sealed.changed_since_sealed(14, "nan_command", changed, keys=("joints",), notebook="notebook 14")
    assert "was changed after notebook 14 showed its outcome" in reason and "earns nothing" in reason


def test_nothing_is_sealed_for_the_solutions_track_or_with_the_log_switched_off(
        course: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(attempts.ENV, "0")
    assert sealed.seal(14, {"nan_command": _guess("active", 0.0)}, ["nan_command"]) == []
    monkeypatch.delenv(attempts.ENV)
    monkeypatch.setenv(tracks.TRACK_ENV, "solutions")  # the predictions read are the solution's, not the learner's
    assert sealed.seal(14, {"nan_command": _guess("active", 0.0)}, ["nan_command"]) == []
    monkeypatch.delenv(tracks.TRACK_ENV)
    monkeypatch.setenv(tracks.EXERCISES_ENV, str(course / "elsewhere"))  # the course's test command
    assert sealed.seal(14, {"nan_command": _guess("active", 0.0)}, ["nan_command"]) == []
    assert not (course / "exercises" / ".progress").exists()


def test_reveal_seals_the_files_prediction_before_it_shows_the_outcome(
        course: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.setattr("matplotlib.pyplot.show", lambda *a, **k: None)
    order: list[str] = []

    def fake_run(name: str) -> fault_lab.Outcome:
        order.append("sealed" if "nan_command" in sealed.seals(14) else "not sealed")
        return fault_lab.Outcome(dict.fromkeys(CONTROLLERS, "active"), {"rrbot": "active"}, [0.0, 0.0])

    monkeypatch.setattr(fault_lab, "run_fault", fake_run)
    fault_lab.reveal("nan_command")
    assert order == ["sealed"], "the outcome ran before the prediction was sealed"
    assert "is sealed as it is now" in capsys.readouterr().out
    assert json.loads(sealed.seals(14)["nan_command"].prediction) == _guess("active", 0.0)
    file = course / "exercises" / "task14_fault_lab" / "predictions.py"
    guesses = {f: _guess("active", 0.0) for f in fault_lab.FAULTS}
    file.write_text(_predictions_file({**guesses, "nan_command": _guess("inactive", 0.0)}))
    fault_lab.reveal("nan_command")
    assert "was changed after this notebook showed its outcome" in capsys.readouterr().out


@pytest.fixture(scope="module")
def graded_with_seals(tmp_path_factory: pytest.TempPathFactory) -> tuple[Rubric, Rubric]:
    """Task 14 graded twice on a copy whose log seals two faults: 'nan_command' as the file holds it, and
    'double_claim' as another guess (the file was changed after the reveal)."""
    folder = tmp_path_factory.mktemp("task14_sealed")
    task = folder / "task14_fault_lab"
    task.mkdir()
    guesses = {f: _guess("active", 0.0) for f in fault_lab.FAULTS}
    (task / "predictions.py").write_text(_predictions_file(guesses))
    log = {"attempts": [], "sealed": {
        "nan_command": {"time": 1.0, "prediction": sealed.canonical(guesses["nan_command"])},
        "double_claim": {"time": 1.0, "prediction": sealed.canonical(_guess("inactive", 0.0))}}}
    (folder / ".progress").mkdir()
    (folder / ".progress" / "task14.json").write_text(json.dumps(log))
    changed = grade(14, task_root=folder, record=False)
    (task / "predictions.py").write_text(_predictions_file({**guesses, "double_claim": _guess("inactive", 0.0)}))
    restored = grade(14, task_root=folder, record=False)
    return changed, restored


def test_a_prediction_changed_after_its_reveal_earns_nothing_and_the_reason_says_so(
        graded_with_seals: tuple[Rubric, Rubric]) -> None:
    changed, _ = graded_with_seals
    by = {c.name: c for c in changed.checks}
    check = by["double_claim_states"]
    assert not check.passed and "was changed after notebook 14 showed its outcome" in check.detail
    assert check.detail.startswith("your predictions.py, line "), check.detail
    assert check.hint == "", "nothing left to hint at: the outcome was shown"
    assert "changed after" not in by["double_claim_joints"].detail, "its positions were not changed: graded as usual"
    for part in ("states", "joints"):
        assert "changed after" not in by[f"nan_command_{part}"].detail, "an unchanged prediction is graded as usual"


def test_the_sealed_prediction_put_back_is_graded_again(graded_with_seals: tuple[Rubric, Rubric]) -> None:
    _, restored = graded_with_seals
    assert all("changed after" not in c.detail for c in restored.checks), restored.format()


def test_no_hint_for_a_prediction_not_made_yet() -> None:
    """The untouched exercise predicts nothing: the self-check shows no hint at all (each would state an outcome)."""
    rubric = grade(14, track="exercises", record=False)
    assert rubric.score == 0 and not [c.name for c in rubric.checks if c.hint], rubric.format()
    assert all("not predicted yet" in c.detail for c in rubric.failed()), rubric.format()


def test_the_stored_notebook_shows_no_outcome() -> None:
    """The learner's copy of notebook 14 opens with no fault's outcome, timeline or explanation in its outputs."""
    cells = json.loads(NOTEBOOK.read_text())["cells"]
    text = json.dumps([c.get("outputs", []) for c in cells if c["cell_type"] == "code"])
    sources = "".join("".join(c["source"]) for c in cells)
    for fault in fault_lab.FAULTS:
        assert f'fault_lab.reveal("{fault}")' in sources, f"notebook 14 does not reveal {fault} through fault_lab"
        assert fault_lab.EXPLANATIONS[fault][:60] not in text + sources, f"the explanation of {fault} is in sight"
    for outcome_words in ("but it is", "it ends at", "image/png", "image/svg+xml", "Why:"):
        assert outcome_words not in text, f"a stored output of notebook 14 holds {outcome_words!r}"


def test_reveal_runs_nothing_before_the_prediction_is_complete(monkeypatch: pytest.MonkeyPatch,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    def must_not_run(name: str) -> None:
        raise AssertionError(f"the fault {name} ran before it was predicted")

    monkeypatch.setenv(attempts.ENV, "0")
    monkeypatch.setattr(fault_lab, "run_fault", must_not_run)
    half = {"controllers": {"joint_state_broadcaster": "active"}, "hardware": {"rrbot": None}, "joints": [0.2, 0.2]}
    assert fault_lab.reveal("nan_command", {"nan_command": half}) is None
    said = capsys.readouterr().out
    assert "Predict 'nan_command' first" in said and "hardware['rrbot']" in said and "Why:" not in said


def test_no_hint_of_task_14_states_what_happens() -> None:
    """The hints of a wrong prediction point at the rule; none holds a position the check grades or says that the
    states stay as they were."""
    import importlib.util
    import re
    import sys

    path = REPO / "tests" / "tasks" / "test_task14_fault_lab.py"
    spec = importlib.util.spec_from_file_location("task14_grader_hints", path)
    assert spec is not None and spec.loader is not None
    grader = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = grader
    try:
        spec.loader.exec_module(grader)
    finally:
        sys.modules.pop(spec.name, None)
    for fault in fault_lab.FAULTS:
        positions = fault_lab.run_fault(fault).joints
        numbers = {f"{round(p, 2):g}" for p in positions} | {f"{p:.2f}" for p in positions}
        for part in ("states", "joints"):
            for level in grader.HINTS[fault][part]:
                said = set(re.findall(r"(?<![\d.])-?\d+(?:\.\d+)?(?![\d.])", level))
                assert not numbers & said, f"a hint of {fault} ({part}) gives a position: {level}"
                for answer in ("nobody changes", "nothing changes", "everything stays", "stay as", "as before",
                               "stays active", "stays inactive", "keeps its last command"):
                    assert answer not in level.lower(), f"a hint of {fault} ({part}) says what happens: {level}"


# ------------------------------------------------------------------------------------------------------ task 6

_T6_GUESS = '''

PREDICTIONS = {name: {"accepted": True, "hardware": {"rrbot": "active"},
                      "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                                      "joint_trajectory_controller": "active"}}
               for name in PREDICTIONS}
'''


def _task6_grader() -> object:
    import importlib.util
    import sys

    path = REPO / "tests" / "tasks" / "test_task06_lifecycle.py"
    spec = importlib.util.spec_from_file_location("task06_grader_sealed", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(spec.name, None)
    return module


@pytest.fixture
def course6(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A course folder with task 6's grader and its exercise as handed out (nothing predicted)."""
    root = tmp_path / "course6"
    (root / "tests" / "tasks").mkdir(parents=True)
    for name in ("conftest.py", "test_task06_lifecycle.py"):
        shutil.copy(REPO / "tests" / "tasks" / name, root / "tests" / "tasks" / name)
    shutil.copytree(REPO / "exercises" / "task06_lifecycle", root / "exercises" / "task06_lifecycle")
    monkeypatch.setenv(tracks.ROOT_ENV, str(root))
    for env in (tracks.TRACK_ENV, tracks.TASK_ROOT_ENV, tracks.EXERCISES_ENV, attempts.ENV):
        monkeypatch.delenv(env, raising=False)
    tracks.set_track(None)
    return root


def test_notebook_06_shows_no_outcome_before_every_prediction_is_made_then_seals_them_first(
        course6: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    grader = _task6_grader()
    ran: list[bool] = []

    def fake_request(name: str) -> dict[str, object]:
        ran.append(name in sealed.seals(6))
        return {"accepted": False, "controllers": dict.fromkeys(CONTROLLERS, "active"), "hardware": {"rrbot": "active"}}

    monkeypatch.setattr(grader, "run_request", fake_request)
    assert grader.outcomes_may_show() is False and "runs once you have predicted them all" in capsys.readouterr().out
    grader.show_predictions()
    assert ran == [] and "Predict every request first (0 of 7 made)" in capsys.readouterr().out
    assert sealed.seals(6) == {}
    file = course6 / "exercises" / "task06_lifecycle" / "lifecycle.py"
    file.write_text(file.read_text() + _T6_GUESS)
    grader.show_predictions()
    assert ran and all(ran), "an outcome ran before the predictions were sealed"
    assert "Your predictions are sealed as they are now" in capsys.readouterr().out
    assert set(sealed.seals(6)) == set(grader.REQUESTS)
    assert grader.outcomes_may_show() is True


def test_a_task_6_prediction_changed_after_the_reveal_earns_nothing(course6: Path) -> None:
    file = course6 / "exercises" / "task06_lifecycle" / "lifecycle.py"
    file.write_text(file.read_text() + _T6_GUESS)
    grader = _task6_grader()
    sealed.seal(6, grader._file_predictions(), grader.REQUESTS, now=1.0)
    file.write_text(file.read_text() + '\nPREDICTIONS["deactivate_the_hardware"]["accepted"] = False\n')
    rubric = grade(6, check_timeout=60.0)
    by = {c.name: c for c in rubric.checks}
    changed = by["prediction_deactivate_the_hardware"]
    assert "was changed after notebook 06 showed its outcome" in changed.detail and changed.hint == ""
    assert all("changed after" not in c.detail for n, c in by.items() if n != "prediction_deactivate_the_hardware")
