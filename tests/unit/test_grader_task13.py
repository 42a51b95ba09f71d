"""The task-13 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed_with(tmp_path: Path, old: str, new: str) -> set[str]:
    source = tracks.task_dir(13, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / "jerk_limited.py"
    text = path.read_text()
    assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times"
    path.write_text(text.replace(old, new))
    return {c.name for c in grade(13, task_root=tmp_path).checks if not c.passed}


def test_positions_only(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "points.append(JointTrajectoryPoint(positions=list(position), velocities=list(velocity),\n"
                          "                                           accelerations=list(acceleration), time_from_start=t))",
                          "points.append(JointTrajectoryPoint(positions=list(position), time_from_start=t))")
    assert "limits_respected" in failed


def test_half_the_velocity_limit_is_not_time_optimal(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "inp.max_velocity = [limits[name][2] for name in joint_names]",
                          "inp.max_velocity = [0.5 * limits[name][2] for name in joint_names]")
    assert failed == {"time_optimal"}


def test_goal_not_checked(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "        if not low <= g <= high:\n", "        if False:\n")
    assert failed == {"goal_outside_limits_is_refused"}


def test_coarse_sampling(tmp_path: Path) -> None:
    """Points every 0.1 s: the JTC's interpolation between them no longer follows ruckig's jerk limit."""
    failed = _failed_with(tmp_path, "times = [k * sample_period for k in range(math.ceil(duration / sample_period))]",
                          "times = [k * 0.1 for k in range(math.ceil(duration / 0.1))]")
    assert "limits_respected" in failed


def test_calling_the_library_planner(tmp_path: Path) -> None:
    old = "    inp = InputParameter(n)\n"
    new = ("    import rrbot_workshop.motion as motion\n"
           "    return motion.jerk_limited_trajectory(joint_names, start, goal, [limits[j][2] for j in joint_names],\n"
           "                                          max_acceleration, max_jerk, sample_period)\n")
    failed = _failed_with(tmp_path, old, new)
    assert {"limits_respected", "time_optimal", "jtc_executes_it"} <= failed


def test_limits_in_the_wrong_order(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "out[name] = (lim.min_position, lim.max_position, lim.max_velocity)",
                          "out[name] = (lim.max_velocity, lim.min_position, lim.max_position)")
    assert "joint_limits" in failed
