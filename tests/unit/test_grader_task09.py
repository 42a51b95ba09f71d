"""The task-9 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake.

Full marks on ``solutions/`` and less on the untouched ``exercises/`` are checked for every task in
``test_graders.py``; these show that each check catches the mistake it is about.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
YAML = "rrbot_bringup/config/rrbot_chained_controllers.yaml"


def _mutated(tmp_path: Path, file: str, old: str, new: str, count: int = 1) -> Path:
    source = tracks.task_dir(9, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    assert text.count(old) == count, f"mutation {old!r} applies {text.count(old)} times to {path}, not {count}"
    path.write_text(text.replace(old, new))
    return tmp_path


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


def test_original_workshop_velocity_references_fail(tmp_path: Path) -> None:
    """The original's mismatch: PIDs exporting only velocity references cannot take the JTC's position commands."""
    root = _mutated(tmp_path, YAML, "reference_and_state_interfaces: [position, velocity]",
                    "reference_and_state_interfaces: [velocity]", count=2)
    failed = _failed(grade(9, task_root=root))
    assert {"pids_command_effort_with_position_and_velocity_references", "activate_chain_connects"} <= failed


def test_jtc_commanding_the_hardware_is_not_a_chain(tmp_path: Path) -> None:
    """Without command_joints the trajectory controller claims joint positions the simulation does not offer."""
    root = _mutated(tmp_path, YAML,
                    "    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n", "")
    failed = _failed(grade(9, task_root=root))
    assert {"trajectory_controller_commands_the_pids", "activate_chain_connects"} <= failed


def test_activating_the_head_first_fails(tmp_path: Path) -> None:
    """A separate switch for the trajectory controller before its PIDs is rejected by the controller manager."""
    root = _mutated(
        tmp_path, "chain.py",
        "    if followers:\n        cm.switch_controllers(activate=followers, strictness=\"strict\")\n"
        "    if loaded[CHAIN[0]] != \"active\":\n        cm.switch_controllers(activate=[CHAIN[0]], strictness=\"strict\")\n",
        "    if loaded[CHAIN[0]] != \"active\":\n        cm.switch_controllers(activate=[CHAIN[0]], strictness=\"strict\")\n"
        "    if followers:\n        cm.switch_controllers(activate=followers, strictness=\"strict\")\n",
    )
    failed = _failed(grade(9, task_root=root))
    assert {"activate_chain_connects", "update_order_is_jazzy", "deactivate_chain",
            "trajectory_is_tracked_through_the_chain"} <= failed
    assert "gains_meet_the_step_specification" not in failed


def test_stopping_the_pids_first_fails(tmp_path: Path) -> None:
    """The PIDs cannot stop while the trajectory controller still claims their references."""
    root = _mutated(
        tmp_path, "chain.py",
        "    if CHAIN[0] in active:\n        cm.switch_controllers(deactivate=[CHAIN[0]], strictness=\"strict\")\n"
        "    followers = [name for name in CHAIN[1:] if name in active]\n",
        "    followers = [name for name in CHAIN[1:] if name in active]\n"
        "    if followers:\n        cm.switch_controllers(deactivate=followers, strictness=\"strict\")\n"
        "    if CHAIN[0] in active:\n        cm.switch_controllers(deactivate=[CHAIN[0]], strictness=\"strict\")\n",
    )
    assert _failed(grade(9, task_root=root)) == {"deactivate_chain"}


@pytest.mark.parametrize(("gains", "why"), [
    ("p: 100.0, i: 50.0, d: 10.0", "the exercise's starting gains settle too slowly"),
    ("p: 300.0, i: 1000.0, d: 10.0", "too much integral action overshoots"),
    ("p: 300.0, i: 0.0, d: 2.0", "too little damping rings"),
])
def test_untuned_gains_fail_the_specification(tmp_path: Path, gains: str, why: str) -> None:
    root = _mutated(tmp_path, YAML, "joint1: {p: 300.0, i: 100.0, d: 10.0", "joint1: {" + gains)
    assert "gains_meet_the_step_specification" in _failed(grade(9, task_root=root)), why
