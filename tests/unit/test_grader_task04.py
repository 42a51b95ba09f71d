"""The task-4 grader fails wrong answers: each test grades a copy of the solution with one deliberate mistake.

Full marks on ``solutions/`` and less on the untouched ``exercises/`` are checked for every task in
``test_graders.py``; these mutations show that each check catches the mistake it is about.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _mutated(tmp_path: Path, old: str, new: str) -> Path:
    """A copy of the task-4 solution with ``old`` replaced by ``new`` once; returns the folder to grade."""
    source = tracks.task_dir(4, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / "introspection.py"
    text = path.read_text()
    assert text.count(old) == 1, f"mutation {old!r} does not apply exactly once to {path}"
    path.write_text(text.replace(old, new))
    return tmp_path


def _failed(rubric: Rubric) -> set[str]:
    return {c.name for c in rubric.checks if not c.passed}


def test_controllers_in_the_wrong_state_fail_the_state_check(tmp_path: Path) -> None:
    """An answer that reports inactive controllers as active loses the controller_states points."""
    root = _mutated(
        tmp_path,
        "return {entry.name: entry.state for entry in cm.list_controllers()}",
        'return {entry.name: "active" if entry.state == "inactive" else entry.state for entry in cm.list_controllers()}',
    )
    rubric = grade(4, task_root=root)
    # switch_between returns the states and activate_all_at_once looks for the inactive ones: both go wrong too
    assert _failed(rubric) == {
        "controller_states", "switch_between", "conflict_names", "conflict_leaves_system_unchanged"
    }, rubric.format()


def test_hardware_state_object_instead_of_label_fails_only_the_hardware_check(tmp_path: Path) -> None:
    root = _mutated(
        tmp_path,
        "{component.name: component.state.label for",
        "{component.name: component.state for",
    )
    rubric = grade(4, task_root=root)
    assert _failed(rubric) == {"hardware_component_states"}, rubric.format()


def test_two_step_switch_fails_only_the_one_step_check(tmp_path: Path) -> None:
    """Deactivating first and activating in a second call reaches the right states but is not one switch."""
    root = _mutated(
        tmp_path,
        'cm.switch_controllers(activate=[activate], deactivate=[deactivate], strictness="strict")',
        'cm.switch_controllers(deactivate=[deactivate], strictness="strict")\n'
        '    cm.switch_controllers(activate=[activate], strictness="strict")',
    )
    rubric = grade(4, task_root=root)
    assert _failed(rubric) == {"switch_is_one_step"}, rubric.format()


def test_activating_one_by_one_fails_the_unchanged_check(tmp_path: Path) -> None:
    """Trying each inactive controller in its own switch activates the first one: the names are right but the
    system changed."""
    root = _mutated(
        tmp_path,
        '    try:\n        cm.switch_controllers(activate=inactive, strictness="strict")\n'
        "    except SwitchError as error:\n",
        "    interfaces: list[str] = []\n    controllers: list[str] = []\n    for name in inactive:\n        try:\n"
        "            cm.switch_controllers(activate=[name])\n"
        "        except SwitchError as error:\n            interfaces += error.interfaces\n"
        "            controllers += error.controllers\n"
        "    if interfaces:\n        error = SwitchError([], interfaces=interfaces, controllers=controllers)\n",
    )
    rubric = grade(4, task_root=root)
    assert _failed(rubric) == {"conflict_leaves_system_unchanged"}, rubric.format()


def test_required_instead_of_claimed_interfaces_fails_the_usage_check(tmp_path: Path) -> None:
    """An inactive controller's required interfaces are not in use: listing them fails interfaces_in_use."""
    root = _mutated(tmp_path, '"command": sorted(entry.claimed_interfaces)', '"command": sorted(entry.required_command_interfaces)')
    rubric = grade(4, task_root=root)
    assert _failed(rubric) == {"interfaces_in_use"}, rubric.format()


def test_hard_coded_workshop_answers_fail(tmp_path: Path) -> None:
    """Answers typed in for the workshop's RRBot fail on the other systems the grader brings up."""
    root = _mutated(
        tmp_path,
        "    cm = controller_manager_of(target)\n    return [entry.name for entry in cm.list_controllers()]\n",
        '    return ["joint_state_broadcaster", "forward_position_controller", "joint_trajectory_controller"]\n',
    )
    rubric = grade(4, task_root=root)
    assert "loaded_controllers" in _failed(rubric), rubric.format()


def _appended(tmp_path: Path, code: str) -> Path:
    """A copy of the solution with a wrong definition appended (the later ``def`` wins)."""
    import textwrap

    source = tracks.task_dir(4, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / "introspection.py"
    path.write_text(path.read_text() + "\n" + textwrap.dedent(code))
    return tmp_path


def test_only_active_controllers_counted_as_loaded(tmp_path: Path) -> None:
    root = _appended(tmp_path, """
        def loaded_controllers(target):
            return [c.name for c in controller_manager_of(target).list_controllers() if c.state == "active"]
        """)
    assert "loaded_controllers" in _failed(grade(4, task_root=root))


def test_available_interfaces_including_unavailable_ones(tmp_path: Path) -> None:
    root = _appended(tmp_path, """
        def available_interfaces(target):
            listing = controller_manager_of(target).list_hardware_interfaces()
            return {"command": sorted(i.name for i in listing.command_interfaces),
                    "state": sorted(i.name for i in listing.state_interfaces),
                    "claimed": sorted(i.name for i in listing.command_interfaces if i.is_claimed)}
        """)
    assert "available_interfaces" in _failed(grade(4, task_root=root))


def test_switch_without_loading_the_new_controller(tmp_path: Path) -> None:
    """Asking the switch for a controller that is declared but not loaded: the task says to load it first."""
    root = _appended(tmp_path, """
        def switch_between(target, deactivate, activate):
            cm = controller_manager_of(target)
            cm.switch_controllers(activate=[activate], deactivate=[deactivate], strictness="strict")
            return controller_states(cm)
        """)
    assert "switch_between" in _failed(grade(4, task_root=root))


def test_conflict_answer_with_every_loaded_controller(tmp_path: Path) -> None:
    """Naming every controller instead of the two the rejection is about."""
    root = _appended(tmp_path, """
        def activate_all_at_once(target):
            cm = controller_manager_of(target)
            inactive = [n for n, s in controller_states(cm).items() if s == "inactive"]
            try:
                cm.switch_controllers(activate=inactive, strictness="strict")
            except SwitchError as error:
                return {"interfaces": sorted(error.interfaces), "controllers": sorted(loaded_controllers(cm))}
            return {"interfaces": [], "controllers": []}
        """)
    assert "conflict_names" in _failed(grade(4, task_root=root))
