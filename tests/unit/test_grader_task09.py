"""The task-9 grader: wrong solutions, written as learners would, lose points; correct ones written differently get
full marks. Each is a copy of ``solutions/`` with exact changes (see ``grader_variants``)."""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")
YAML = "rrbot_bringup/config/rrbot_chained_controllers.yaml"
CHAIN = "chain.py"
ACTIVATE = ('    if followers:\n        cm.switch_controllers(activate=followers, strictness="strict")\n'
            '    if loaded[CHAIN[0]] != "active":\n        cm.switch_controllers(activate=[CHAIN[0]], strictness="strict")\n')
DEACTIVATE = ('    if CHAIN[0] in active:\n        cm.switch_controllers(deactivate=[CHAIN[0]], strictness="strict")\n'
              '    followers = [name for name in CHAIN[1:] if name in active]\n'
              '    if followers:\n        cm.switch_controllers(deactivate=followers, strictness="strict")\n')
LOAD = ('    for name in CHAIN:\n        if name not in loaded:\n            cm.load_controller(name)\n'
        '            loaded[name] = "unconfigured"\n        if loaded[name] == "unconfigured":\n'
        '            cm.configure_controller(name)\n')
GAINS_1 = "joint1: {p: 300.0, i: 100.0, d: 10.0"
STEP = {"step_overshoot", "step_settling_time", "step_final_error"}
MANAGER_TYPES = ("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n\n"
                 "    pid_controller_joint1:\n      type: pid_controller/PidController\n\n"
                 "    pid_controller_joint2:\n      type: pid_controller/PidController\n\n"
                 "    joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n")
PID1_TYPE = "    pid_controller_joint1:\n      type: pid_controller/PidController\n\n"


def _section(name: str) -> str:
    return f"\n{name}:\n  ros__parameters:\n"


#: The checks the PIDs' wiring carries: the gains are measured on the learner's PIDs once they are wired.
ON_THE_PIDS = {"pids_command_effort_with_position_and_velocity_references", "trajectory_is_tracked_through_the_chain",
               *STEP}
#: The checks a chain.py that cannot connect the chain fails.
NOT_CONNECTED = {"activate_chain_connects", "activate_chain_from_any_state", "update_order_is_jazzy",
                 "deactivate_chain"}
TRACKING = "trajectory_is_tracked_through_the_chain"
CONFIGURED_ONCE = LOAD.replace(
    '        if loaded[name] == "unconfigured":\n            cm.configure_controller(name)\n',
    '        if loaded[name] == "unconfigured" and name not in _CONFIGURED:\n'
    '            cm.configure_controller(name)\n            _CONFIGURED.add(name)\n')

# The kinds of miss of issue 29, as they apply to task 9:
# - orders as asked: head_activated_first, activated_in_sorted_order, pids_stopped_first (the grader's own trajectory
#   lists joint2 first; joints_listed_joint2_first is right);
# - rates where every controller is slower than the loop: every_controller_slower_than_the_loop, slower_pid (and
#   trajectory_controller_slower_than_the_loop is right: the specification only holds the PIDs to the loop's rate);
# - configure again after cleanup: configured_only_once_per_session (activate_chain is tried on a cleaned-up chain);
# - validation before anything starts, return values, NaN outputs, whole periods: the task states none (chain.py's
#   functions return None, and the learner writes no controller output or duration).
WRONG = [
    Variant("velocity_references_only", {YAML: [
        ("    command_interface: effort\n    reference_and_state_interfaces: [position, velocity]\n    gains:\n"
         "      # Tuned", "    command_interface: effort\n    reference_and_state_interfaces: [velocity]\n    gains:\n"
         "      # Tuned")]},
            fails=ON_THE_PIDS, only=True, names_file="rrbot_chained_controllers.yaml, line ",
            says={"pids_command_effort_with_position_and_velocity_references": "interfaces [velocity]"}),
    Variant("trajectory_controller_commands_the_hardware", {YAML: [
        ("    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n", "")]},
            fails={"trajectory_controller_commands_the_pids"}, only=True,
            says={"trajectory_controller_commands_the_pids": "command_joints not given"}),
    Variant("trajectory_controller_sends_positions_only", {YAML: [
        ("    command_interfaces: [position, velocity]", "    command_interfaces: [position]")]},
            fails={"trajectory_controller_commands_the_pids"}, only=True,
            names_file="rrbot_chained_controllers.yaml, line "),
    Variant("command_joints_name_the_interfaces", {YAML: [
        ("    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n",
         "    command_joints: [pid_controller_joint1/joint1/position, pid_controller_joint2/joint2/position]\n")]},
            fails={"trajectory_controller_commands_the_pids"}, only=True,
            says={"trajectory_controller_commands_the_pids": "pid_controller_joint1/joint1/position"}),
    Variant("command_joint_misspelt", {YAML: [
        ("    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n",
         "    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint_2]\n")]},
            fails={"trajectory_controller_commands_the_pids"}, only=True,
            says={"trajectory_controller_commands_the_pids": "joint_2"}),
    Variant("pids_command_position", {YAML: [
        ("    dof_names: [joint2]\n    command_interface: effort", "    dof_names: [joint2]\n    command_interface: position")]},
            fails=ON_THE_PIDS, only=True, says={"pids_command_effort_with_position_and_velocity_references": "command_interface position"}),
    Variant("command_interface_left_out", {YAML: [
        ("    dof_names: [joint2]\n    command_interface: effort\n", "    dof_names: [joint2]\n")]},
            fails=ON_THE_PIDS | {"yaml_is_valid_for_jazzy"}, only=True,
            says={"pids_command_effort_with_position_and_velocity_references": "not given"}),
    Variant("second_pid_copied_on_joint1", {YAML: [
        ("    dof_names: [joint2]\n", "    dof_names: [joint1]\n"),
        ("      joint2: {p: 300.0, i: 300.0", "      joint1: {p: 300.0, i: 300.0")]},
            fails=ON_THE_PIDS, only=True),
    Variant("update_rate_written_as_a_float", {YAML: [("update_rate: 100  # [Hz]", "update_rate: 100.0  # [Hz]")]},
            fails={"yaml_is_valid_for_jazzy"}, only=True, says={"yaml_is_valid_for_jazzy": "update_rate"}),
    Variant("head_activated_first", {CHAIN: [(ACTIVATE,
        '    if loaded[CHAIN[0]] != "active":\n        cm.switch_controllers(activate=[CHAIN[0]], strictness="strict")\n'
        '    if followers:\n        cm.switch_controllers(activate=followers, strictness="strict")\n')]},
            fails=NOT_CONNECTED, only=True, names_file="chain.py, line "),
    Variant("activated_in_sorted_order", {CHAIN: [(ACTIVATE,
        '    for name in sorted(CHAIN):\n        if loaded[name] != "active":\n'
        '            cm.switch_controllers(activate=[name], strictness="strict")\n')]},
            fails=NOT_CONNECTED, only=True, names_file="chain.py, line "),
    Variant("activation_without_strictness", {CHAIN: [(ACTIVATE, ACTIVATE.replace(', strictness="strict"', ""))]},
            fails={"activate_chain_connects", "activate_chain_from_any_state"}, only=True,
            says={"activate_chain_connects": "not strict"}),
    Variant("activation_best_effort", {CHAIN: [(ACTIVATE, ACTIVATE.replace('"strict"', '"best_effort"'))]},
            fails={"activate_chain_connects", "activate_chain_from_any_state"}, only=True),
    Variant("pids_stopped_first", {CHAIN: [(DEACTIVATE,
        '    followers = [name for name in CHAIN[1:] if name in active]\n'
        '    if followers:\n        cm.switch_controllers(deactivate=followers, strictness="strict")\n'
        '    if CHAIN[0] in active:\n        cm.switch_controllers(deactivate=[CHAIN[0]], strictness="strict")\n')]},
            fails={"deactivate_chain", "deactivate_chain_from_any_state"}, only=True, names_file="chain.py, line "),
    Variant("deactivation_without_strictness", {CHAIN: [(DEACTIVATE, DEACTIVATE.replace(', strictness="strict"', ""))]},
            fails={"deactivate_chain", "deactivate_chain_from_any_state"}, only=True),
    Variant("everything_assumed_configured", {CHAIN: [(LOAD, "")]},
            fails={"activate_chain_from_any_state"}, only=True, names_file="chain.py, line "),
    Variant("loaded_but_never_configured", {CHAIN: [(
        '        if loaded[name] == "unconfigured":\n            cm.configure_controller(name)\n', "")]},
            fails={"activate_chain_from_any_state"}, only=True, names_file="chain.py, line "),
    Variant("configured_only_once_per_session", {CHAIN: [
        ("CHAIN = [", "_CONFIGURED: set[str] = set()\nCHAIN = ["), (LOAD, CONFIGURED_ONCE)]},
            fails={"activate_chain_from_any_state"}, only=True, names_file="chain.py, line ",
            says={"activate_chain_from_any_state": "cleaned up"}),
    Variant("whole_chain_in_one_switch_whatever_its_state", {CHAIN: [(ACTIVATE,
        '    cm.switch_controllers(activate=list(CHAIN), strictness="strict")\n')]},
            fails={"activate_chain_from_any_state"}, only=True, names_file="chain.py, line "),
    Variant("whole_chain_stopped_whatever_its_state", {CHAIN: [(DEACTIVATE,
        '    cm.switch_controllers(deactivate=list(CHAIN), strictness="strict")\n')]},
            fails={"deactivate_chain_from_any_state"}, only=True, names_file="chain.py, line "),
    Variant("deactivation_unloads_the_chain", {CHAIN: [(DEACTIVATE, DEACTIVATE + (
        '    for name in CHAIN:\n        cm.unload_controller(name)\n'))]},
            fails={"deactivate_chain", "deactivate_chain_from_any_state"}, only=True),
    Variant("deactivation_cleans_the_chain_up", {CHAIN: [(DEACTIVATE, DEACTIVATE + (
        '    for name in CHAIN:\n        cm.cleanup_controller(name)\n'))]},
            fails={"deactivate_chain", "deactivate_chain_from_any_state"}, only=True),
    Variant("loop_at_1000_hz", {YAML: [("update_rate: 100  # [Hz]", "update_rate: 1000  # [Hz]")]},
            fails=STEP, only=True, says={"step_overshoot": "1000 Hz"}),
    Variant("slower_pid", {YAML: [("    pid_controller_joint1:\n      type: pid_controller/PidController\n",
                                   "    pid_controller_joint1:\n      type: pid_controller/PidController\n"
                                   "      update_rate: 50\n")]},
            fails=STEP, only=True, says={"step_overshoot": "50 Hz"}),
    Variant("slower_pid_in_its_own_section", {YAML: [
        (_section("pid_controller_joint1"), _section("pid_controller_joint1") + "    update_rate: 50\n")]},
            fails=STEP, only=True, names_file="rrbot_chained_controllers.yaml, line "),
    Variant("every_controller_slower_than_the_loop", {YAML: [(MANAGER_TYPES, MANAGER_TYPES.replace(
        "Controller\n", "Controller\n      update_rate: 50\n").replace(
        "Broadcaster\n", "Broadcaster\n      update_rate: 50\n"))]},
            fails=STEP, only=True, says={"step_overshoot": "50 Hz"}),
    Variant("pid_type_misspelt_in_its_own_section", {YAML: [
        (PID1_TYPE, ""), (_section("pid_controller_joint1"),
                          _section("pid_controller_joint1") + "    type: pid_controller/PIDController\n")]},
            fails={"yaml_is_valid_for_jazzy"}, only=True, says={"yaml_is_valid_for_jazzy": "pid_controller/PIDController"}),
    Variant("pid_type_left_out", {YAML: [(PID1_TYPE, "")]},
            fails={"yaml_is_valid_for_jazzy"}, only=True, says={"yaml_is_valid_for_jazzy": "has no type"}),
    Variant("exercise_starting_gains", {YAML: [(GAINS_1, "joint1: {p: 100.0, i: 50.0, d: 10.0")]},
            fails={"step_settling_time", "step_final_error"}, only=True),
    Variant("too_much_integral", {YAML: [(GAINS_1, "joint1: {p: 300.0, i: 1000.0, d: 10.0")]},
            fails={"step_overshoot", "step_settling_time"}, only=True),
    Variant("too_little_damping", {YAML: [(GAINS_1, "joint1: {p: 300.0, i: 0.0, d: 2.0")]},
            fails={"step_overshoot", "step_settling_time"}, only=True),
    Variant("no_integral_on_joint2", {YAML: [("joint2: {p: 300.0, i: 300.0", "joint2: {p: 300.0, i: 0.0")]},
            fails={TRACKING}, only=True, says={TRACKING: "joint2"}),
]

RIGHT_CHAIN_ONE_SWITCH = '''"""Task 9.2, written with set operations and one switch each way."""

from rrbot_workshop.controller_manager.manager import ControllerManager

CHAIN = ["joint_trajectory_controller", "pid_controller_joint1", "pid_controller_joint2"]


def _states(cm):
    result = {}
    for entry in cm.list_controllers():
        result[entry.name] = entry.state
    return result


def activate_chain(cm: ControllerManager) -> None:
    states = _states(cm)
    for name in CHAIN:
        if states.get(name) is None:
            cm.load_controller(name)
            cm.configure_controller(name)
        elif states[name] == "unconfigured":
            cm.configure_controller(name)
    missing = [name for name in reversed(CHAIN) if _states(cm)[name] != "active"]
    if missing:
        # followers and head together: the manager activates the exporters first
        cm.switch_controllers(activate=missing, strictness=2)


def deactivate_chain(cm: ControllerManager) -> None:
    running = [name for name in CHAIN if _states(cm).get(name) == "active"]
    if running:
        cm.switch_controllers(deactivate=running, strictness=2)
'''

RIGHT_CHAIN_SET_STATE = '''"""Task 9.2 with a helper per controller."""

CHAIN = ["joint_trajectory_controller", "pid_controller_joint1", "pid_controller_joint2"]


def state_of(cm, name):
    for c in cm.list_controllers():
        if c.name == name:
            return c.state
    return "unloaded"


def activate_chain(cm):
    head, *pids = CHAIN
    for name in pids + [head]:
        if state_of(cm, name) == "unloaded":
            cm.load_controller(name)
        if state_of(cm, name) == "unconfigured":
            cm.configure_controller(name)
    for name in pids:
        if state_of(cm, name) != "active":
            cm.switch_controllers(activate=[name], strictness="STRICT")
    if state_of(cm, head) != "active":
        cm.switch_controllers(activate=[head], strictness="STRICT")


def deactivate_chain(cm):
    for name in CHAIN:  # head first
        if state_of(cm, name) == "active":
            cm.switch_controllers(deactivate=[name], strictness="strict")
'''

RIGHT_YAML_FLOW = """controller_manager:
  ros__parameters:
    update_rate: 100
    joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    pid_controller_joint2: {type: pid_controller/PidController}
    pid_controller_joint1: {type: pid_controller/PidController}
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}

joint_trajectory_controller:
  ros__parameters:
    state_interfaces: [position, velocity]
    command_interfaces: [position, velocity]
    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]
    joints: [joint1, joint2]

pid_controller_joint2:
  ros__parameters:
    reference_and_state_interfaces: [position, velocity]
    command_interface: effort
    dof_names: [joint2]
    gains: {joint2: {p: 400.0, i: 400.0, d: 12.0, i_clamp_max: 20.0, i_clamp_min: -20.0}}

pid_controller_joint1:
  ros__parameters:
    reference_and_state_interfaces: [position, velocity]
    command_interface: effort
    dof_names: [joint1]
    gains: {joint1: {p: 400.0, i: 120.0, d: 12.0, i_clamp_max: 20.0, i_clamp_min: -20.0}}
"""

RIGHT_YAML_OWN_SECTIONS_FLOW = """controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster}}
pid_controller_joint1: {ros__parameters: {type: pid_controller/PidController, dof_names: [joint1],
  command_interface: effort, reference_and_state_interfaces: [position, velocity],
  gains: {joint1: {p: 300.0, i: 100.0, d: 10.0, i_clamp_max: 20.0, i_clamp_min: -20.0}}}}
pid_controller_joint2: {ros__parameters: {type: pid_controller/PidController, dof_names: [joint2],
  command_interface: effort, reference_and_state_interfaces: [position, velocity],
  gains: {joint2: {p: 300.0, i: 300.0, d: 10.0, i_clamp_max: 20.0, i_clamp_min: -20.0}}}}
joint_trajectory_controller: {ros__parameters: {type: joint_trajectory_controller/JointTrajectoryController,
  joints: [joint1, joint2], command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2],
  command_interfaces: [position, velocity], state_interfaces: [position, velocity]}}
"""

RIGHT = [
    Variant("types_in_the_controllers_own_sections", {YAML: [(MANAGER_TYPES, "")] + [
        (_section(name), _section(name) + f"    type: {kind}\n") for name, kind in (
            ("pid_controller_joint1", "pid_controller/PidController"),
            ("pid_controller_joint2", "pid_controller/PidController"),
            ("joint_trajectory_controller", "joint_trajectory_controller/JointTrajectoryController"))] + [
        ("\n\n\npid_controller_joint1:", "\n\njoint_state_broadcaster:\n  ros__parameters:\n"
         "    type: joint_state_broadcaster/JointStateBroadcaster\n\npid_controller_joint1:")]}),
    Variant("types_in_own_sections_flow_style", {YAML: RIGHT_YAML_OWN_SECTIONS_FLOW}),
    Variant("one_switch_each_way_integer_strictness", {CHAIN: RIGHT_CHAIN_ONE_SWITCH}),
    Variant("one_controller_per_switch", {CHAIN: RIGHT_CHAIN_SET_STATE}),
    Variant("flow_yaml_other_order_stiffer_gains", {YAML: RIGHT_YAML_FLOW}),
    Variant("node_keys_with_wildcard_and_slash", {YAML: (
        RIGHT_YAML_OWN_SECTIONS_FLOW.replace("controller_manager:", "/**/controller_manager:")
        .replace("\npid_controller_joint1:", "\n/**/pid_controller_joint1:")
        .replace("\njoint_trajectory_controller:", "\n/joint_trajectory_controller:"))}),
    Variant("update_rate_left_out_jazzy_default_100_hz", {YAML: [("    update_rate: 100  # [Hz]\n", "")]}),
    Variant("trajectory_controller_slower_than_the_loop", {YAML: [(
        "      type: joint_trajectory_controller/JointTrajectoryController\n",
        "      type: joint_trajectory_controller/JointTrajectoryController\n      update_rate: 50\n")]}),
    Variant("joints_listed_joint2_first", {YAML: [
        ("    joints: [joint1, joint2]\n    command_joints: [pid_controller_joint1/joint1, pid_controller_joint2/joint2]\n",
         "    joints: [joint2, joint1]\n    command_joints: [pid_controller_joint2/joint2, pid_controller_joint1/joint1]\n")]}),
    Variant("block_lists_and_pid_at_loop_rate", {YAML: [
        ("    dof_names: [joint1]\n", "    dof_names:\n      - joint1\n"),
        ("    pid_controller_joint2:\n      type: pid_controller/PidController\n",
         "    pid_controller_joint2:\n      type: pid_controller/PidController\n      update_rate: 100\n")]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(9, WRONG + RIGHT, tmp_path_factory.mktemp("task09"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_one_slip_shows_hints_at_one_check(rubrics: dict, variant: Variant) -> None:
    """The checks a single slip fails build on one of them (graded(after=...)): only that one is a cause."""
    assert_one_cause(rubrics[variant.name], check_specs(9), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(9))


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])
