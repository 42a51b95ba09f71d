"""The task-14 grader fails plausible wrong predictions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed_with(tmp_path: Path, replacements: list[tuple[str, str]]) -> set[str]:
    source = tracks.task_dir(14, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / "predictions.py"
    text = path.read_text()
    for old, new in replacements:
        assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times"
        text = text.replace(old, new)
    path.write_text(text)
    return {c.name for c in grade(14, task_root=tmp_path).checks if not c.passed}


def test_wrong_predictions_each_lose_their_point(tmp_path: Path) -> None:
    """Five beliefs a learner may carry over (Humble's FINALIZED on error, a crash taking everyone down, a limit that
    applies without enforcement, hardware that stops its controllers, a best-effort-like strict switch): each costs
    exactly the fault it is about."""
    failed = _failed_with(tmp_path, [
        ('"hardware": {"rrbot": "unconfigured"}', '"hardware": {"rrbot": "finalized"}'),
        ('    "update_exception": {\n        "controllers": {"joint_state_broadcaster": "active"',
         '    "update_exception": {\n        "controllers": {"joint_state_broadcaster": "inactive"'),
        ('    "beyond_limits": {\n        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": '
         '"active",\n                        "joint_trajectory_controller": "inactive"},\n        "hardware": {"rrbot": '
         '"active"},\n        "joints": [0.5, 10.0],',
         '    "beyond_limits": {\n        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": '
         '"active",\n                        "joint_trajectory_controller": "inactive"},\n        "hardware": {"rrbot": '
         '"active"},\n        "joints": [0.5, 4.1888],'),
        ('    "hardware_inactive": {\n        "controllers": {"joint_state_broadcaster": "active", '
         '"forward_position_controller": "active",',
         '    "hardware_inactive": {\n        "controllers": {"joint_state_broadcaster": "active", '
         '"forward_position_controller": "inactive",'),
        ('    "double_claim": {\n        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": '
         '"active",\n                        "joint_trajectory_controller": "inactive"},',
         '    "double_claim": {\n        "controllers": {"joint_state_broadcaster": "active", "forward_position_controller": '
         '"inactive",\n                        "joint_trajectory_controller": "active"},'),
    ])
    assert failed == {"read_error", "update_exception", "beyond_limits", "hardware_inactive", "double_claim"}


def test_running_the_faults_instead_of_predicting_fails_everything(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, [(
        "__all__ = [\"PREDICTIONS\"]\n",
        "__all__ = [\"PREDICTIONS\"]\n\nfrom rrbot_workshop.course.fault_lab import FAULTS, run_fault\n"
        "_COPIED = {name: run_fault(name).prediction_view() for name in FAULTS}\n",
    ), ("PREDICTIONS: dict[str, dict[str, Any]] = {", "PREDICTIONS: dict[str, dict[str, Any]] = _COPIED or {")])
    assert len(failed) == 8
