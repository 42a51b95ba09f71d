"""The task-6 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed_with(tmp_path: Path, *changes: tuple[str, str]) -> set[str]:
    source = tracks.task_dir(6, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / "lifecycle.py"
    text = path.read_text()
    for old, new in changes:
        assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times"
        text = text.replace(old, new)
    path.write_text(text)
    return {c.name for c in grade(6, task_root=tmp_path).checks if not c.passed}


def test_two_switches_leave_a_cycle_without_a_controller(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, (
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"],\n'
        '                          strictness="strict")\n',
        '    cm.switch_controllers(deactivate=["forward_position_controller"], strictness="strict")\n'
        '    cm.update(0.0, 0.01)\n'
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], strictness="strict")\n'))
    assert failed == {"switch_to_trajectory_controller"}


def test_forward_controller_unloaded_instead_of_deactivated(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, (
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"],\n'
        '                          strictness="strict")\n',
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"],\n'
        '                          strictness="strict")\n'
        '    cm.cleanup_controller("forward_position_controller")\n'
        '    cm.unload_controller("forward_position_controller")\n'))
    assert failed == {"switch_to_trajectory_controller"}


def test_controllers_reactivated_before_the_hardware(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, (
        '    cm.set_hardware_component_state(component, "active")\n    cm.switch_controllers(activate=controllers, '
        'strictness="strict")\n',
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n    cm.set_hardware_component_state('
        'component, "active")\n'))
    assert failed == {"recover_after_a_read_error"}


def test_hardware_recovered_but_controllers_left_inactive(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('    cm.switch_controllers(activate=controllers, strictness="strict")\n', ""))
    assert failed == {"recover_after_a_read_error"}


def test_unload_without_deactivating(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('    if state == "active":\n        cm.switch_controllers(deactivate=[name], '
                                     'strictness="strict")\n', ""))
    assert failed == {"remove_a_controller_from_any_state"}


def test_cleanup_of_an_unconfigured_controller(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('    if state in ("active", "inactive"):\n        cm.cleanup_controller(name)\n',
                                     "    cm.cleanup_controller(name) if state != 'unconfigured' or True else None\n"))
    assert failed == {"remove_a_controller_from_any_state"}


def test_best_effort_believed_to_forgive_an_interface_conflict(tmp_path: Path) -> None:
    old = ('    "activate_next_to_forward_best_effort": {\n        "accepted": False,\n')
    failed = _failed_with(tmp_path, (old, old.replace("False", "True")))
    assert failed == {"predictions"}


def test_hardware_deactivation_believed_to_stop_the_controllers(tmp_path: Path) -> None:
    old = ('    "deactivate_the_hardware": {\n        "accepted": True,\n        "controllers": {"joint_state_broadcaster": '
           '"active", "forward_position_controller": "active",\n')
    failed = _failed_with(tmp_path, (old, old.replace('"forward_position_controller": "active"',
                                                      '"forward_position_controller": "inactive"')))
    assert failed == {"predictions"}
