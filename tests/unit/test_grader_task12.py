"""The task-12 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
YAML = "rrbot_bringup/config/rrbot_controllers.yaml"
BRINGUP = "rrbot_bringup/bringup.py"


def _failed_with(tmp_path: Path, file: str, old: str, new: str, count: int = 1) -> set[str]:
    source = tracks.task_dir(12, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    assert text.count(old) == count, f"mutation {old!r} applies {text.count(old)} times"
    path.write_text(text.replace(old, new))
    return {c.name for c in grade(12, task_root=tmp_path).checks if not c.passed}


def test_prefix_only_in_the_description(tmp_path: Path) -> None:
    """The xacro gets the prefix, the controllers keep joint1/joint2: they do not configure."""
    failed = _failed_with(tmp_path, BRINGUP, '{"prefix": prefix})', '{"prefix": ""})')
    assert {"prefix_reaches_the_running_system", "robot_controller_choice"} <= failed


def test_prefix_only_in_the_controllers(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, 'xacro_args={"prefix": prefix,', 'xacro_args={"prefix": "",')
    assert "prefix_reaches_the_running_system" in failed


def test_hard_coded_prefix_in_the_yaml(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, YAML, "$(var prefix)joint", "joint", count=4)
    assert {"yaml_follows_the_prefix", "prefix_reaches_the_running_system"} <= failed


def test_update_rate_ignored(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, "    if update_rate is not None:\n", "    if False:\n")
    assert failed == {"update_rate_is_injected"}


def test_unknown_robot_controller_accepted(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, BRINGUP, "    if robot_controller not in ROBOT_CONTROLLERS:\n", "    if False:\n")
    assert failed == {"robot_controller_choice"}
