"""The task-14 grader: wrong predictions, as learners would make them, lose the point of the part they are about;
right predictions written differently (other forms, rounding the course allows) get full marks. Each variant is a
copy of solutions/task14_fault_lab with changes (see grader_variants.py)."""

from __future__ import annotations

import pytest
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

F = "predictions.py"
SOLUTION = (tracks.task_dir(14, "solutions") / F).read_text() if HAS_SOLUTIONS else ""


def _block(fault: str) -> str:
    """The text of the prediction of ``fault`` in the solution, from its key to its closing brace."""
    if not SOLUTION:
        return ""
    start = SOLUTION.index(f'    "{fault}": {{\n')
    return SOLUTION[start:SOLUTION.index("    },\n", start) + len("    },\n")]


def _edit(fault: str, old: str, new: str) -> tuple[str, str]:
    """A replacement of ``old`` by ``new`` inside the prediction of ``fault`` only (the blocks look alike)."""
    block = _block(fault)
    if not block:
        return ("", "")
    assert block.count(old) == 1, f"{old!r} occurs {block.count(old)} times in the prediction of {fault}"
    return block, block.replace(old, new)


def _wrong(name: str, fault: str, part: str, old: str, new: str) -> Variant:
    return Variant(name, {F: [_edit(fault, old, new)]}, fails={f"{fault}_{part}"})


FPC = '"forward_position_controller": '
JSB = '"joint_state_broadcaster": '
JTC = '"joint_trajectory_controller": '

WRONG = [
    _wrong("hardware_error_finalizes_the_component", "read_error", "states", '"unconfigured"', '"finalized"'),
    _wrong("broadcaster_survives_a_hardware_error", "read_error", "states", JSB + '"inactive"', JSB + '"active"'),
    _wrong("joints_reset_to_zero_after_a_hardware_error", "read_error", "joints", "[0.2, 0.2]", "[0.0, 0.0]"),
    _wrong("a_crash_takes_the_broadcaster_down", "update_exception", "states", JSB + '"active"', JSB + '"inactive"'),
    _wrong("a_crash_takes_the_hardware_down", "update_exception", "states", '"rrbot": "active"', '"rrbot": "inactive"'),
    _wrong("wrong_size_command_ignored", "wrong_size_command", "states", FPC + '"inactive"', FPC + '"active"'),
    _wrong("wrong_size_command_moves_joint1", "wrong_size_command", "joints", "[0.2, 0.2]", "[0.7, 0.2]"),
    _wrong("urdf_limits_apply_without_enforcement", "beyond_limits", "joints", "[0.5, 10.0]", "[0.5, 4.19]"),
    _wrong("a_command_beyond_the_limits_is_an_error", "beyond_limits", "states", FPC + '"active"', FPC + '"inactive"'),
    _wrong("enforced_limits_still_reach_the_command", "beyond_limits_enforced", "joints", "[0.5, 4.19]",
           "[0.5, 10.0]"),
    _wrong("enforced_limit_off_by_more_than_two_decimals", "beyond_limits_enforced", "joints", "[0.5, 4.19]",
           "[0.5, 4.2]"),
    _wrong("nan_skipped_finite_numbers_written", "nan_command", "joints", "[0.2, 0.2]", "[0.2, 0.5]"),
    _wrong("nan_deactivates_the_controller", "nan_command", "states", FPC + '"active"', FPC + '"inactive"'),
    _wrong("inactive_hardware_deactivates_its_controllers", "hardware_inactive", "states", FPC + '"active"',
           FPC + '"inactive"'),
    _wrong("inactive_mock_hardware_stops_following", "hardware_inactive", "joints", "[0.6, 0.6]", "[0.2, 0.2]"),
    _wrong("strict_switch_behaves_as_best_effort", "double_claim", "states", JTC + '"inactive"', JTC + '"active"'),
    Variant("running_the_faults_instead_of_predicting", {F: [
        ("__all__ = [\"PREDICTIONS\"]\n",
         "__all__ = [\"PREDICTIONS\"]\n\nfrom rrbot_workshop.course.fault_lab import FAULTS, run_fault\n"
         "_COPIED = {name: run_fault(name).prediction_view() for name in FAULTS}\n"),
        ("PREDICTIONS: dict[str, dict[str, Any]] = {", "PREDICTIONS: dict[str, dict[str, Any]] = _COPIED or {")]},
        fails={"read_error_states", "double_claim_joints"}),
    Variant("one_fault_left_out", {F: [(_block("double_claim"), "")]},
            fails={"double_claim_states", "double_claim_joints"}),
]

ALT_BUILT_WITH_A_HELPER = '''"""Task 14: my predictions, built with a helper; positions rounded to 2 decimals, as the task allows."""

import math

ACTIVE, INACTIVE, UNCONFIGURED = "active", "inactive", "unconfigured"


def outcome(broadcaster, forward, trajectory, hardware, joint1, joint2):
    return {
        "controllers": {
            "forward_position_controller": forward,
            "joint_trajectory_controller": trajectory,
            "joint_state_broadcaster": broadcaster,
        },
        "hardware": {"rrbot": hardware},
        "joints": (joint1, joint2),
    }


PREDICTIONS = {}
PREDICTIONS["double_claim"] = outcome(ACTIVE, ACTIVE, INACTIVE, ACTIVE, 0.2, 0.2)
PREDICTIONS["hardware_inactive"] = outcome(ACTIVE, ACTIVE, INACTIVE, INACTIVE, 0.6, 0.6)
PREDICTIONS["nan_command"] = outcome(ACTIVE, ACTIVE, INACTIVE, ACTIVE, 0.2, 0.2)
PREDICTIONS["beyond_limits_enforced"] = outcome(ACTIVE, ACTIVE, INACTIVE, ACTIVE, 0.5, round(math.radians(240), 2))
PREDICTIONS["beyond_limits"] = outcome(ACTIVE, ACTIVE, INACTIVE, ACTIVE, 0.5, 10)
for fault in ("update_exception", "wrong_size_command"):
    PREDICTIONS[fault] = outcome(ACTIVE, INACTIVE, INACTIVE, ACTIVE, 0.2, 0.2)
PREDICTIONS["read_error"] = outcome(INACTIVE, INACTIVE, INACTIVE, UNCONFIGURED, 0.2, 0.2)
'''

ALT_UPPER_CASE_AND_EXACT = '''"""Task 14: lifecycle labels as ros2 control list_controllers prints them in capitals; exact radians."""

import math

_BASE = {"joint_state_broadcaster": "ACTIVE", "forward_position_controller": "ACTIVE",
         "joint_trajectory_controller": "INACTIVE"}


def _with(**changes):
    states = dict(_BASE)
    states.update(changes)
    return states


PREDICTIONS = {
    "read_error": {"controllers": _with(joint_state_broadcaster="Inactive", forward_position_controller="Inactive"),
                   "hardware": {"rrbot": "Unconfigured"}, "joints": [0.20, 0.20]},
    "update_exception": {"controllers": _with(forward_position_controller="INACTIVE"), "hardware": {"rrbot": "ACTIVE"},
                         "joints": [0.2, 0.2]},
    "wrong_size_command": {"controllers": _with(forward_position_controller="INACTIVE"),
                           "hardware": {"rrbot": "ACTIVE"}, "joints": [0.2, 0.2]},
    "beyond_limits": {"controllers": _with(), "hardware": {"rrbot": "ACTIVE"}, "joints": [0.5, 10.0]},
    "beyond_limits_enforced": {"controllers": _with(), "hardware": {"rrbot": "ACTIVE"},
                               "joints": [0.5, 240 * math.pi / 180]},
    "nan_command": {"controllers": _with(), "hardware": {"rrbot": "ACTIVE"}, "joints": [0.2, 0.2]},
    "hardware_inactive": {"controllers": _with(), "hardware": {"rrbot": "INACTIVE"}, "joints": [0.6, 0.6]},
    "double_claim": {"controllers": _with(), "hardware": {"rrbot": "ACTIVE"}, "joints": [0.2, 0.2]},
}
'''

RIGHT = [
    Variant("built_with_a_helper_and_rounded", {F: ALT_BUILT_WITH_A_HELPER}),
    Variant("capital_labels_and_exact_radians", {F: ALT_UPPER_CASE_AND_EXACT}),
    Variant("within_half_a_hundredth", {F: [
        _edit("beyond_limits_enforced", "[0.5, 4.19]", "[0.498, 4.186]"),
        _edit("hardware_inactive", "[0.6, 0.6]", "[0.6049, 0.5951]")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(14, WRONG + RIGHT, tmp_path_factory.mktemp("task14"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_prediction_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", WRONG[:-2], ids=str)
def test_a_wrong_part_costs_only_its_own_point(rubrics: dict, variant: Variant) -> None:
    """Points per prediction: one wrong part loses one point, the others are kept."""
    rubric = rubrics[variant.name]
    assert {c.name for c in rubric.failed()} == set(variant.fails), rubric.format()
    assert rubric.score == rubric.max_score - 1, rubric.format()


def test_running_the_faults_loses_every_point(rubrics: dict) -> None:
    rubric = rubrics["running_the_faults_instead_of_predicting"]
    assert rubric.score == 0, rubric.format()


def test_a_failed_check_never_gives_the_answer(rubrics: dict) -> None:
    """The self-check names what is wrong, not what happens (notebook 14 reveals that once the learner predicted)."""
    reason = next(c.detail for c in rubrics["urdf_limits_apply_without_enforcement"].failed())
    assert "4.19" in reason and "10" not in reason, reason


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_prediction_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


# ------------------------------------------------------------------------------ predictions before outcomes
NOTEBOOK = tracks.course_root() / "notebooks" / "14_fault_lab.ipynb"


def test_the_stored_notebook_shows_no_outcome() -> None:
    """The learner's copy of notebook 14 opens with no fault's outcome, timeline or explanation in its outputs."""
    import json

    from rrbot_workshop.course import fault_lab

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
    from rrbot_workshop.course import fault_lab

    def must_not_run(name: str) -> None:
        raise AssertionError(f"the fault {name} ran before it was predicted")

    monkeypatch.setattr(fault_lab, "run_fault", must_not_run)
    half = {"controllers": {"joint_state_broadcaster": "active"}, "hardware": {"rrbot": None}, "joints": [0.2, 0.2]}
    assert fault_lab.reveal("nan_command", {"nan_command": half}) is None
    said = capsys.readouterr().out
    assert "Predict 'nan_command' first" in said and "hardware['rrbot']" in said and "Why:" not in said


def test_reveal_grades_the_prediction_then_explains(monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from rrbot_workshop.course import fault_lab

    monkeypatch.setattr("matplotlib.pyplot.show", lambda *a, **k: None)
    guess = {"controllers": {"joint_state_broadcaster": "active", "forward_position_controller": "active",
                             "joint_trajectory_controller": "inactive"},
             "hardware": {"rrbot": "active"}, "joints": [0.5, 4.19]}
    assert fault_lab.reveal("beyond_limits", {"beyond_limits": guess}) is not None
    said = capsys.readouterr().out
    assert said.index("Your states: right.") < said.index("joint2: predicted 4.19 rad, it ends at 10.00 rad")
    assert said.index("it ends at 10.00 rad") < said.index("Why: " + fault_lab.EXPLANATIONS["beyond_limits"][:40])


def test_positions_are_compared_to_two_decimals() -> None:
    from rrbot_workshop.course import fault_lab

    outcome = fault_lab.Outcome({}, {}, [0.5, 4.18879])
    for right in (4.19, 4.1888, 4.185, 4.193):
        assert not fault_lab.compare({"controllers": {}, "hardware": {}, "joints": [0.5, right]}, outcome), right
    for wrong in (4.18, 4.2, 4.19 + 0.0062):
        assert fault_lab.compare({"controllers": {}, "hardware": {}, "joints": [0.5, wrong]}, outcome), wrong
