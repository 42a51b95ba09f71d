"""The task-6 grader against wrong solutions written as learners would, and against right ones written differently.

Each variant is a copy of ``solutions/task06_lifecycle/`` with exact changes to ``lifecycle.py`` (see
:mod:`grader_variants`); all are graded once, two at a time, in a module-scoped fixture.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

F = "lifecycle.py"
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


WRONG = [
    Variant("two_switches_leave_a_cycle_without_a_controller", {F: [(SWITCH, (
        '    cm.switch_controllers(deactivate=["forward_position_controller"], strictness="strict")\n'
        '    cm.update(0.0, 0.01)\n'
        '    cm.switch_controllers(activate=["joint_trajectory_controller"], strictness="strict")\n'))]},
            fails={"one_strict_switch", "no_cycle_without_a_robot_controller"}),
    Variant("forward_controller_unloaded_instead_of_deactivated", {F: [(SWITCH, SWITCH + (
        '    cm.cleanup_controller("forward_position_controller")\n'
        '    cm.unload_controller("forward_position_controller")\n'))]},
            fails={"switch_end_states"}),
    Variant("switch_made_best_effort", {F: [(SWITCH, SWITCH.replace('"strict"', '"best_effort"'))]},
            fails={"one_strict_switch"}),
    Variant("switch_strictness_left_to_the_default", {F: [(SWITCH, SWITCH.replace(
        ',\n                          strictness="strict")', ")"))]},
            fails={"one_strict_switch"}),
    Variant("controllers_reactivated_before_the_hardware", {F: [(RECOVER, (
        '    cm.switch_controllers(activate=controllers, strictness="best_effort")\n'
        '    cm.set_hardware_component_state(component, "active")\n'))]},
            fails={"recover_the_controllers", "recover_another_robot"}),
    Variant("hardware_recovered_but_controllers_left_inactive", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n', "")]},
            fails={"recover_the_controllers", "recover_another_robot"}),
    Variant("recover_names_the_rrbot_component", {F: [(
        '    cm.set_hardware_component_state(component, "active")\n',
        '    cm.set_hardware_component_state("rrbot", "active")\n')]},
            fails={"recover_another_robot"}),
    Variant("recover_reactivates_a_fixed_list", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n',
        '    cm.switch_controllers(activate=["joint_state_broadcaster", "forward_position_controller"], '
        'strictness="best_effort")\n')]},
            fails={"recover_the_controllers", "recover_another_robot"}),
    Variant("recover_one_switch_per_controller", {F: [(
        '    cm.switch_controllers(activate=controllers, strictness="strict")\n',
        '    for controller in controllers:\n'
        '        cm.switch_controllers(activate=[controller], strictness="strict")\n')]},
            fails={"recover_the_controllers"}),
    Variant("unload_without_deactivating", {F: [(
        '    if state == "active":\n        cm.switch_controllers(deactivate=[name], strictness="strict")\n', "")]},
            fails={"remove_an_active_controller", "remove_controller_generated"}),
    Variant("cleanup_of_an_unconfigured_controller", {F: [(
        '    if state in ("active", "inactive"):\n        cm.cleanup_controller(name)\n',
        "    cm.cleanup_controller(name)\n")]},
            fails={"remove_an_unconfigured_controller"}),
    Variant("state_of_a_fixed_controller_looked_up", {F: [(
        "    state = next(c.state for c in cm.list_controllers() if c.name == name)\n",
        '    state = next(c.state for c in cm.list_controllers() if c.name == "forward_position_controller")\n')]},
            fails={"remove_an_active_controller", "remove_controller_generated"}),
    Variant("every_active_controller_deactivated_on_the_way", {F: [(
        '        cm.switch_controllers(deactivate=[name], strictness="strict")\n',
        '        cm.switch_controllers(deactivate=[c.name for c in cm.list_controllers() if c.state == "active"], '
        'strictness="strict")\n')]},
            fails={"remove_an_active_controller"}),
    Variant("typo_in_remove_controller_raises", {F: [(
        "    cm.unload_controller(name)\n", "    cm.unload_controller(name, force=True)\n")]},
            fails={"remove_an_active_controller", "remove_an_inactive_controller", "remove_an_unconfigured_controller"},
            names_file=F),
    Variant("best_effort_believed_to_forgive_an_interface_conflict", {F: [(
        _prediction("activate_next_to_forward_best_effort", "False"),
        _prediction("activate_next_to_forward_best_effort", "True"))]},
            fails={"prediction_activate_next_to_forward_best_effort"}),
    Variant("hardware_deactivation_believed_to_stop_the_controllers", {F: [(
        '    "deactivate_the_hardware": {\n        "accepted": True,\n        "controllers": {"joint_state_broadcaster": '
        '"active", "forward_position_controller": "active",\n',
        '    "deactivate_the_hardware": {\n        "accepted": True,\n        "controllers": {"joint_state_broadcaster": '
        '"active", "forward_position_controller": "inactive",\n')]},
            fails={"prediction_deactivate_the_hardware"}),
    Variant("configuring_an_active_controller_believed_accepted", {F: [(
        _prediction("configure_an_active_controller", "False"), _prediction("configure_an_active_controller", "True"))]},
            fails={"prediction_configure_an_active_controller"}),
    Variant("cleanup_believed_to_unload", {F: [(
        '"joint_state_broadcaster": "active", "forward_position_controller": "active",\n'
        '                        "joint_trajectory_controller": "unconfigured"},',
        '"joint_state_broadcaster": "active", "forward_position_controller": "active",\n'
        '                        "joint_trajectory_controller": "finalized"},')]},
            fails={"prediction_cleanup_an_inactive_controller"}),
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
