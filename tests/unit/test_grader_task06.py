"""The task-6 grader against wrong solutions written as learners would, and against right ones written differently.

Each variant is a copy of ``solutions/task06_lifecycle/`` with exact changes to ``lifecycle.py`` (see
:mod:`grader_variants`); all are graded once, two at a time, in a module-scoped fixture.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

F = "lifecycle.py"
SOLUTION = (tracks.task_dir(6, "solutions") / F).read_text() if HAS_SOLUTIONS else ""
SWITCH = ('    cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"],\n'
          '                          strictness="strict")\n')
RECOVER = ('    cm.set_hardware_component_state(component, "active")\n'
           '    cm.switch_controllers(activate=controllers, strictness="strict")\n')
REMOVE = ('    state = next(c.state for c in cm.list_controllers() if c.name == name)\n'
          '    if state == "active":\n'
          '        cm.switch_controllers(deactivate=[name], strictness="strict")\n'
          '    if state in ("active", "inactive"):\n'
          '        cm.cleanup_controller(name)\n'
          '    cm.unload_controller(name)\n')


def _prediction(name: str, accepted: str) -> str:
    return f'    "{name}": {{\n        "accepted": {accepted},\n'


def _state(name: str, controller: str, old: str, new: str) -> tuple[str, str]:
    """In the prediction of ``name``, the state of ``controller`` (a key in the solution's block) from old to new."""
    block_start = SOLUTION.index(f'    "{name}": {{\n')
    block = SOLUTION[block_start:SOLUTION.index("    },\n", block_start) + len("    },\n")]
    assert block.count(f'"{controller}": "{old}"') == 1, (name, controller, old)
    return block, block.replace(f'"{controller}": "{old}"', f'"{controller}": {new}')


REMOVE_WAITS = {"remove_an_active_controller", "remove_an_inactive_controller", "remove_an_unconfigured_controller",
                "remove_controller_generated"}

WRONG = [
    Variant("two_switches_leave_a_cycle_without_a_controller", {F: [(SWITCH, (
        '    cm.switch_controllers(deactivate=["forward_position_controller"], strictness="strict")\n'
        '    cm.update(0.0, 0.01)\n'
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], strictness="strict")\n'))]},
            fails={"one_strict_switch", "no_cycle_without_a_robot_controller"}, names_file=F, only=True,
            says={"no_cycle_without_a_robot_controller": "neither robot controller active"}),
    Variant("forward_controller_unloaded_instead_of_deactivated", {F: [(SWITCH, SWITCH + (
        '    cm.cleanup_controller("forward_position_controller")\n'
        '    cm.unload_controller("forward_position_controller")\n'))]},
            fails={"switch_end_states"}, names_file=F, only=True,
            says={"switch_end_states": "forward_position_controller unloaded (should be inactive)"}),
    Variant("switch_made_best_effort", {F: [(SWITCH, SWITCH.replace('"strict"', '"best_effort"'))]},
            fails={"one_strict_switch"}, only=True, says={"one_strict_switch": "strictness 'best_effort'"}),
    Variant("switch_strictness_left_to_the_default", {F: [(SWITCH, SWITCH.replace(
        ',\n                          strictness="strict")', ")"))]},
            fails={"one_strict_switch"}, only=True, says={"one_strict_switch": "strictness 'best_effort'"}),
    Variant("controllers_reactivated_before_the_hardware", {F: [(RECOVER, (
        '    cm.switch_controllers(activate=controllers, strictness="best_effort")\n'
        '    cm.set_hardware_component_state(component, "active")\n'))]},
            fails={"recover_the_hardware", "recover_the_controllers", "recover_another_robot"}, names_file=F,
            says={"recover_the_hardware": "which is not available (hardware component 'rrbot' is 'unconfigured')"}),
    Variant("hardware_recovered_but_controllers_left_inactive", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n', "")]},
            fails={"recover_the_controllers"}, only=True, names_file=F),
    Variant("hardware_not_recovered", {F: [('    cm.set_hardware_component_state(component, "active")\n', "")]},
            fails={"recover_the_hardware", "recover_the_controllers", "recover_another_robot"},
            says={"recover_the_hardware": "hardware component 'rrbot' is 'unconfigured'"}),
    Variant("recover_names_the_rrbot_component", {F: [(
        '    cm.set_hardware_component_state(component, "active")\n',
        '    cm.set_hardware_component_state("rrbot", "active")\n')]},
            fails={"recover_another_robot"}, only=True,
            says={"recover_another_robot": "no hardware component named 'rrbot'"}),
    Variant("recover_reactivates_a_fixed_list", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n',
        '    cm.switch_controllers(activate=["joint_state_broadcaster", "forward_position_controller"], '
        'strictness="best_effort")\n')]},
            fails={"recover_the_controllers"}, only=True,
            says={"recover_the_controllers": "forward_position_controller active (should be inactive)"}),
    Variant("recover_reactivates_every_inactive_controller", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n',
        '    cm.switch_controllers(activate=[c.name for c in cm.list_controllers() if c.state == "inactive"], '
        'strictness="best_effort")\n')]},
            fails={"recover_the_controllers"}),
    Variant("recover_one_switch_per_controller", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n',
        '    for controller in controllers:\n'
        '        cm.switch_controllers(activate=[controller], strictness="strict")\n')]},
            fails={"recover_the_controllers"}, only=True, says={"recover_the_controllers": "in one switch"}),
    Variant("unload_without_deactivating", {F: [(
        '    if state == "active":\n        cm.switch_controllers(deactivate=[name], strictness="strict")\n', "")]},
            fails={"remove_an_active_controller", "remove_controller_generated"}, only=True, names_file=F),
    Variant("cleanup_of_an_unconfigured_controller", {F: [(
        '    if state in ("active", "inactive"):\n        cm.cleanup_controller(name)\n',
        "    cm.cleanup_controller(name)\n")]},
            fails={"remove_an_unconfigured_controller", "remove_controller_generated"}, only=True, names_file=F),
    Variant("state_of_a_fixed_controller_looked_up", {F: [(
        "    state = next(c.state for c in cm.list_controllers() if c.name == name)\n",
        '    state = next(c.state for c in cm.list_controllers() if c.name == "forward_position_controller")\n')]},
            fails={"remove_an_active_controller", "remove_controller_generated"}),
    Variant("every_active_controller_deactivated_on_the_way", {F: [(
        '        cm.switch_controllers(deactivate=[name], strictness="strict")\n',
        '        cm.switch_controllers(deactivate=[c.name for c in cm.list_controllers() if c.state == "active"], '
        'strictness="strict")\n')]},
            fails={"remove_an_active_controller"}, says={"remove_an_active_controller": "changed the others"}),
    Variant("typo_in_remove_controller_raises", {F: [(
        "    cm.unload_controller(name)\n", "    cm.unload_controller(name, force=True)\n")]},
            fails={"remove_an_active_controller", "remove_an_inactive_controller", "remove_an_unconfigured_controller"},
            names_file=F, says={"remove_an_active_controller": "TypeError"}),
    Variant("best_effort_believed_to_forgive_an_interface_conflict", {F: [(
        _prediction("activate_next_to_forward_best_effort", "False"),
        _prediction("activate_next_to_forward_best_effort", "True"))]},
            fails={"prediction_activate_next_to_forward_best_effort"}, only=True, names_file=F,
            says={"prediction_activate_next_to_forward_best_effort": "wrong in: whether it is accepted"}),
    Variant("hardware_deactivation_believed_to_stop_the_controllers", {F: [
        _state("deactivate_the_hardware", "forward_position_controller", "active", '"inactive"')]},
            fails={"prediction_deactivate_the_hardware"}, only=True,
            says={"prediction_deactivate_the_hardware": "the state of forward_position_controller"}),
    Variant("configuring_an_active_controller_believed_accepted", {F: [(
        _prediction("configure_an_active_controller", "False"), _prediction("configure_an_active_controller", "True"))]},
            fails={"prediction_configure_an_active_controller"}, only=True),
    Variant("cleanup_believed_to_unload", {F: [
        _state("cleanup_an_inactive_controller", "joint_trajectory_controller", "unconfigured", '"unloaded"')]},
            fails={"prediction_cleanup_an_inactive_controller"}, only=True,
            says={"prediction_cleanup_an_inactive_controller": "wrong in: the state of joint_trajectory_controller"}),
    Variant("cleanup_believed_to_finalize", {F: [
        _state("cleanup_an_inactive_controller", "joint_trajectory_controller", "unconfigured", '"finalized"')]},
            fails={"prediction_cleanup_an_inactive_controller"}, only=True),
    Variant("unload_believed_to_take_an_active_controller_out", {F: [
        _state("unload_an_active_controller", "forward_position_controller", "active", '"unloaded"')]},
            fails={"prediction_unload_an_active_controller"}, only=True,
            says={"prediction_unload_an_active_controller": "wrong in: the state of forward_position_controller"}),
    Variant("a_controller_left_out_of_a_prediction", {F: [
        _state("unload_an_active_controller", "forward_position_controller", "active", "None")]},
            fails={"prediction_unload_an_active_controller"}, only=True,
            says={"prediction_unload_an_active_controller": "not made yet: the state of forward_position_controller"}),
    Variant("a_state_that_is_no_state", {F: [
        _state("deactivate_the_hardware", "joint_state_broadcaster", "active", '"running"')]},
            fails={"prediction_deactivate_the_hardware"}, only=True,
            says={"prediction_deactivate_the_hardware": "'running', which is not a state"}),
    Variant("lifecycle_file_does_not_import", {F: [("from typing import Any\n", "from typing import Any\nimport nope\n")]},
            fails={"lifecycle_file_loads", "switch_end_states", "prediction_deactivate_the_hardware"}, names_file=F,
            says={"switch_end_states": "fails because lifecycle_file_loads fails"}),
]

#: remove_controller with a lookup table and a loop; inactive controllers unloaded directly (Jazzy cleans them up).
REMOVE_BY_TABLE = '''    states = {}
    for entry in cm.list_controllers():
        states[entry.name] = entry.state
    while states.get(name) == "active":
        cm.switch_controllers([], [name], "strict")
        states = {entry.name: entry.state for entry in cm.list_controllers()}
    cm.unload_controller(name)
'''

#: The predictions built from one fresh-system baseline, in flow style, with other orders of keys.
PREDICTIONS_BUILT = '''

_FRESH = {"joint_trajectory_controller": "inactive", "joint_state_broadcaster": "active",
          "forward_position_controller": "active"}


def _p(accepted, hardware="active", **changed):
    return {"hardware": {"rrbot": hardware}, "controllers": {**_FRESH, **changed}, "accepted": accepted}


PREDICTIONS = {
    "cleanup_an_inactive_controller": _p(True, joint_trajectory_controller="unconfigured"),
    "switch_on_unconfigured_hardware": _p(False, "unconfigured"),
    "deactivate_the_hardware": _p(True, "inactive"),
    "unload_an_active_controller": _p(False),
    "configure_an_active_controller": _p(False),
    "activate_next_to_forward_best_effort": _p(False),
    "activate_next_to_forward": _p(bool(0)),
}
'''

RIGHT = [
    Variant("positional_switch_and_set_controller_state", {F: [
        ('    cm.set_controller_state("joint_trajectory_controller", "inactive")\n',
         '    cm.configure_controller("joint_trajectory_controller")\n'),
        (SWITCH, '    cm.switch_controllers(["joint_trajectory_controller"], ["forward_position_controller"], 2)\n')]}),
    Variant("recover_through_inactive_with_the_service_constant", {F: [(RECOVER, (
        '    cm.set_hardware_component_state(component, "inactive")\n'
        '    cm.set_hardware_component_state(component, "active")\n'
        '    cm.switch_controllers(activate=list(controllers), deactivate=[], strictness="STRICT")\n'))]}),
    Variant("remove_by_table_without_cleanup", {F: [(REMOVE, REMOVE_BY_TABLE)]}),
    Variant("state_labels_in_capitals", {F: [
        _state("deactivate_the_hardware", "joint_state_broadcaster", "active", '"Active"'),
        _state("cleanup_an_inactive_controller", "joint_trajectory_controller", "unconfigured", '"UNCONFIGURED"')]}),
    Variant("predictions_built_from_a_baseline", {F: [("\n\n# -----------------------------------------------"
                                                       "---------------------------------------------- 6.1\n",
                                                       PREDICTIONS_BUILT + "\n\n# ---------------------------------"
                                                       "------------------------------------------------------------ "
                                                       "6.1\n")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(6, WRONG + RIGHT, Path(tmp_path_factory.mktemp("task06")), workers=2)


def test_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_a_file_that_does_not_import_is_one_cause_with_one_hint(rubrics: dict[str, Rubric]) -> None:
    rubric = rubrics["lifecycle_file_does_not_import"]
    assert [c.name for c in rubric.checks if c.hint] == ["lifecycle_file_loads"], rubric.format()
    assert all(c.blocked_by == "lifecycle_file_loads" for c in rubric.failed() if c.name != "lifecycle_file_loads")


def test_a_wrong_prediction_is_the_only_cause_and_shows_its_hint(rubrics: dict[str, Rubric]) -> None:
    rubric = rubrics["cleanup_believed_to_unload"]
    assert [c.name for c in rubric.checks if c.hint] == ["prediction_cleanup_an_inactive_controller"], rubric.format()


def test_the_hints_of_the_untouched_exercise_state_no_outcome() -> None:
    """Nothing is predicted yet: the predictions show no hint, and the checks of 6.3 (whose hints would say what unload
    and cleanup do) show none and say why."""
    rubric = grade(6, track="exercises", record=False)
    hinted = [c.name for c in rubric.checks if c.hint]
    assert hinted == ["switch_end_states"], rubric.format()
    remove = {c.name: c for c in rubric.checks}["remove_an_active_controller"]
    assert "its hints come once you have predicted unload_an_active_controller" in remove.detail, rubric.format()
