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


def _wrong(name: str, fault: str, part: str, old: str, new: str, says: str = "not what happens") -> Variant:
    """One wrong part of one fault's prediction: that part's point alone is lost, and the reason names the file."""
    return Variant(name, {F: [_edit(fault, old, new)]}, fails={f"{fault}_{part}"}, names_file=F,
                   says={f"{fault}_{part}": says}, only=True)


FPC = '"forward_position_controller": '
JSB = '"joint_state_broadcaster": '
JTC = '"joint_trajectory_controller": '

WRONG = [
    _wrong("hardware_error_finalizes_the_component", "read_error", "states", '"unconfigured"', '"finalized"',
           says="hardware 'rrbot': predicted 'finalized'"),
    _wrong("broadcaster_survives_a_hardware_error", "read_error", "states", JSB + '"inactive"', JSB + '"active"',
           says="controller 'joint_state_broadcaster'"),
    _wrong("joints_reset_to_zero_after_a_hardware_error", "read_error", "joints", "[0.2, 0.2]", "[0.0, 0.0]"),
    _wrong("a_crash_takes_the_broadcaster_down", "update_exception", "states", JSB + '"active"', JSB + '"inactive"'),
    _wrong("a_crash_takes_the_hardware_down", "update_exception", "states", '"rrbot": "active"', '"rrbot": "inactive"'),
    _wrong("wrong_size_command_ignored", "wrong_size_command", "states", FPC + '"inactive"', FPC + '"active"'),
    _wrong("wrong_size_command_moves_joint1", "wrong_size_command", "joints", "[0.2, 0.2]", "[0.7, 0.2]",
           says="joint1: predicted 0.7 rad"),
    _wrong("urdf_limits_apply_without_enforcement", "beyond_limits", "joints", "[0.5, 10.0]", "[0.5, 4.19]"),
    _wrong("a_command_beyond_the_limits_is_an_error", "beyond_limits", "states", FPC + '"active"', FPC + '"inactive"'),
    _wrong("enforced_limits_still_reach_the_command", "beyond_limits_enforced", "joints", "[0.5, 4.19]",
           "[0.5, 10.0]"),
    _wrong("enforced_limit_off_by_more_than_two_decimals", "beyond_limits_enforced", "joints", "[0.5, 4.19]",
           "[0.5, 4.2]", says="(to 2 decimals)"),
    _wrong("nan_skipped_finite_numbers_written", "nan_command", "joints", "[0.2, 0.2]", "[0.2, 0.5]"),
    _wrong("nan_deactivates_the_controller", "nan_command", "states", FPC + '"active"', FPC + '"inactive"'),
    _wrong("inactive_hardware_deactivates_its_controllers", "hardware_inactive", "states", FPC + '"active"',
           FPC + '"inactive"'),
    _wrong("inactive_mock_hardware_stops_following", "hardware_inactive", "joints", "[0.6, 0.6]", "[0.2, 0.2]"),
    _wrong("strict_switch_behaves_as_best_effort", "double_claim", "states", JTC + '"inactive"', JTC + '"active"'),
    _wrong("a_state_that_is_no_lifecycle_state", "double_claim", "states", JTC + '"inactive"', JTC + '"stopped"',
           says="'stopped' is not a lifecycle state"),
    _wrong("one_position_left_out", "nan_command", "joints", "[0.2, 0.2]", "[0.2]", says="must list 2 positions"),
    _wrong("a_position_given_as_text", "hardware_inactive", "joints", "[0.6, 0.6]", '[0.6, "0.6"]',
           says="a finite number of rad"),
    Variant("running_the_faults_instead_of_predicting", {F: [
        ("__all__ = [\"PREDICTIONS\"]\n",
         "__all__ = [\"PREDICTIONS\"]\n\nfrom rrbot_workshop.course.fault_lab import FAULTS, run_fault\n"
         "_COPIED = {name: run_fault(name).prediction_view() for name in FAULTS}\n"),
        ("PREDICTIONS: dict[str, dict[str, Any]] = {", "PREDICTIONS: dict[str, dict[str, Any]] = _COPIED or {")]},
        fails={"read_error_states", "double_claim_joints", "predictions_file_loads"},
        says={"predictions_file_loads": "runs the faults"}),
    Variant("one_fault_left_out", {F: [(_block("double_claim"), "")]},
            fails={"double_claim_states", "double_claim_joints"}, says={"double_claim_states": "no entry 'double_claim'"},
            only=True),
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


def test_running_the_faults_loses_every_point(rubrics: dict) -> None:
    rubric = rubrics["running_the_faults_instead_of_predicting"]
    assert rubric.score == 0, rubric.format()
    assert {c.blocked_by for c in rubric.failed() if c.name != "predictions_file_loads"} == {"predictions_file_loads"}
    assert [c.name for c in rubric.checks if c.hint] == ["predictions_file_loads"], "one cause, one hint"


def test_a_failed_check_never_gives_the_answer(rubrics: dict) -> None:
    """The self-check names what is wrong, not what happens (notebook 14 reveals that once the learner predicted)."""
    reason = next(c.detail for c in rubrics["urdf_limits_apply_without_enforcement"].failed())
    assert "4.19" in reason and "10" not in reason, reason


def test_a_wrong_prediction_shows_one_hint_and_it_is_that_checks(rubrics: dict) -> None:
    rubric = rubrics["nan_deactivates_the_controller"]
    assert [c.name for c in rubric.checks if c.hint] == ["nan_command_states"], rubric.format()


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_prediction_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


# ------------------------------------------------------------------------------ the reveal (quotes an outcome)


def test_reveal_grades_the_prediction_then_explains(monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    import matplotlib

    from rrbot_workshop.course.grading import attempts

    monkeypatch.setenv(attempts.ENV, "0")  # the course's own test: nothing of the learner's is sealed

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
