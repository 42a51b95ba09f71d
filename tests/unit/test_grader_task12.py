"""Task 12's grader: wrong solutions written as learners would lose points; correct ones written differently do not."""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric, grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

YAML = "rrbot_bringup/config/rrbot_controllers.yaml"
BRINGUP = "rrbot_bringup/bringup.py"
CHECK = "    if robot_controller not in ROBOT_CONTROLLERS:\n"
RAISE = '        raise ValueError(f"robot_controller must be one of {ROBOT_CONTROLLERS}, got {robot_controller!r}")\n'
LOAD = 'controllers = load_with_substitutions(CONTROLLERS, {"prefix": prefix})'
RATE = '    if update_rate is not None:\n        controllers = override(controllers, "controller_manager", ' \
       '{"update_rate": update_rate})\n'
XACRO = 'xacro_args={"prefix": prefix, "use_mock_hardware": use_mock_hardware}'
SPAWN = 'spawn=["joint_state_broadcaster", robot_controller], inactive=other)'


def _yaml(joint_lines_fpc: str, joint_lines_jtc: str) -> str:
    """Task 2's controllers YAML with the given joint lines (block style)."""
    return f"""controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    forward_position_controller:
      type: forward_command_controller/ForwardCommandController
    joint_trajectory_controller:
      type: joint_trajectory_controller/JointTrajectoryController

forward_position_controller:
  ros__parameters:
    joints:
{joint_lines_fpc}
    interface_name: position

joint_trajectory_controller:
  ros__parameters:
    joints:
{joint_lines_jtc}
    command_interfaces: [position]
    state_interfaces: [position, velocity]
    allow_partial_joints_goal: false
    constraints:
      stopped_velocity_tolerance: 0.01
      goal_time: 0.0
"""


PREFIXED = "      - $(var prefix)joint1\n      - $(var prefix)joint2"
PLAIN = "      - joint1\n      - joint2"

WRONG = [
    Variant("prefix_only_in_the_description", {BRINGUP: [(LOAD, LOAD.replace('{"prefix": prefix}', '{"prefix": ""}'))]},
            fails={"prefix_reaches_the_running_system", "robot_controller_choice", "any_arguments_match_the_launch_file"}),
    Variant("prefix_only_in_the_controllers", {BRINGUP: [(XACRO, XACRO.replace('"prefix": prefix', '"prefix": ""'))]},
            fails={"prefix_reaches_the_running_system", "any_arguments_match_the_launch_file"}),
    Variant("yaml_left_unprefixed", {YAML: _yaml(PLAIN, PLAIN)},
            fails={"yaml_follows_the_prefix"}, only=True, says={"yaml_follows_the_prefix": "rrbot_controllers.yaml, line"}),
    Variant("yaml_hard_coded_for_left", {YAML: _yaml("      - left_joint1\n      - left_joint2",
                                                     "      - left_joint1\n      - left_joint2")},
            fails={"yaml_follows_the_prefix"}, only=True),
    Variant("only_the_forward_controller_prefixed", {YAML: _yaml(PREFIXED, PLAIN)},
            fails={"yaml_follows_the_prefix"}, only=True,
            says={"yaml_follows_the_prefix": "joint_trajectory_controller's joints"}),
    Variant("only_joint1_prefixed", {YAML: _yaml("      - $(var prefix)joint1\n      - joint2",
                                                 "      - $(var prefix)joint1\n      - joint2")},
            fails={"yaml_follows_the_prefix"}, only=True),
    Variant("prefix_glued_with_an_extra_underscore", {YAML: _yaml(PREFIXED.replace(")joint", ")_joint"),
                                                                  PREFIXED.replace(")joint", ")_joint"))},
            fails={"yaml_follows_the_prefix"}, only=True,
            says={"yaml_follows_the_prefix": "rrbot_controllers.yaml, line"}),
    Variant("update_rate_ignored", {BRINGUP: [(RATE, "")]},
            fails={"update_rate_is_injected", "any_arguments_match_the_launch_file"}),
    Variant("update_rate_written_into_the_file", {BRINGUP: [(RATE, (
        "    if update_rate is not None:\n"
        "        CONTROLLERS.write_text(CONTROLLERS.read_text().replace('update_rate: 100', "
        "f'update_rate: {update_rate}'))\n"
        "        controllers = load_with_substitutions(CONTROLLERS, {'prefix': prefix})\n"))]},
            fails={"update_rate_is_injected"}),
    Variant("unknown_robot_controller_accepted", {BRINGUP: [(CHECK + RAISE, "")]},
            fails={"unknown_robot_controller_refused", "refusal_names_the_valid_controllers"}),
    Variant("refusal_without_the_valid_names", {BRINGUP: [(RAISE, '        raise ValueError("unknown robot '
                                                                   'controller")\n')]},
            fails={"refusal_names_the_valid_controllers"}),
    Variant("refused_with_another_exception", {BRINGUP: [(RAISE, RAISE.replace("ValueError", "KeyError"))]},
            fails={"unknown_robot_controller_refused", "refusal_names_the_valid_controllers"}, names_file="bringup.py"),
    Variant("refused_after_starting_the_robot", {BRINGUP: [
        (CHECK + RAISE, ""),
        ("    return rw.bringup(", "    system = rw.bringup("),
        (SPAWN, 'spawn=["joint_state_broadcaster"], inactive=[])\n'
                "    if robot_controller not in ROBOT_CONTROLLERS:\n" + RAISE +
                "    system.controller_manager.load_controller(robot_controller)\n"
                "    for name in other:\n        system.controller_manager.load_controller(name)\n"
                "        system.controller_manager.configure_controller(name)\n"
                "    system.controller_manager.configure_controller(robot_controller)\n"
                "    system.controller_manager.switch_controllers(activate=[robot_controller], strictness='strict')\n"
                "    return system"),
    ]}, fails={"unknown_robot_controller_refused"}),
    Variant("refused_after_a_trial_start", {BRINGUP: [(CHECK, CHECK + (
        '        rw.bringup("rrbot", load_with_substitutions(CONTROLLERS, {"prefix": prefix}), '
        'xacro_args={"prefix": prefix}, spawn=["joint_state_broadcaster"]).shutdown()\n'))]},
            fails={"unknown_robot_controller_refused"}, only=True,
            says={"unknown_robot_controller_refused": "only after bringing up"}),
    Variant("mock_hardware_always", {BRINGUP: [(XACRO, XACRO.replace('"use_mock_hardware": use_mock_hardware',
                                                                     '"use_mock_hardware": True'))]},
            fails={"use_mock_hardware_is_injected", "any_arguments_match_the_launch_file"}),
    Variant("mock_hardware_not_passed_on", {BRINGUP: [(XACRO, 'xacro_args={"prefix": prefix}')]},
            fails={"use_mock_hardware_is_injected"}),
    Variant("robot_controller_ignored", {BRINGUP: [
        ('    other = [name for name in ROBOT_CONTROLLERS if name != robot_controller]\n',
         '    other = ["joint_trajectory_controller"]\n'),
        (SPAWN, 'spawn=["joint_state_broadcaster", "forward_position_controller"], inactive=other)')]},
            fails={"robot_controller_choice", "any_arguments_match_the_launch_file"}),
    Variant("other_controller_not_loaded", {BRINGUP: [(SPAWN, SPAWN.replace("inactive=other", "inactive=[]"))]},
            fails={"defaults", "robot_controller_choice", "any_arguments_match_the_launch_file"}),
    Variant("other_controller_left_unconfigured", {BRINGUP: [
        ("    return rw.bringup(", "    system = rw.bringup("),
        (SPAWN, SPAWN.replace("inactive=other)", "inactive=[])\n    for name in other:\n"
                              "        system.controller_manager.load_controller(name)\n    return system"))]},
            fails={"defaults", "robot_controller_choice"}),
]

#: An alternative bringup: the text substituted by hand, a merged override, the lists built in a loop.
BRINGUP_BY_HAND = '''"""Task 12, written another way."""

import copy
from pathlib import Path

import yaml

from rrbot_workshop.bringup import bringup
from rrbot_workshop.middleware import param_substitution as injection

HERE = Path(__file__).resolve().parent
VALID = {"forward_position_controller": "joint_trajectory_controller",
         "joint_trajectory_controller": "forward_position_controller"}


def start_rrbot(prefix="", robot_controller="forward_position_controller", update_rate=None,
                use_mock_hardware=True):
    """Start the RRBot with its parameters injected."""
    try:
        other = VALID[robot_controller]
    except KeyError:
        raise ValueError(f"unknown robot_controller {robot_controller!r}; valid: {', '.join(sorted(VALID))}") from None
    text = (HERE / "config" / "rrbot_controllers.yaml").read_text()
    params = yaml.safe_load(injection.substitute(text, {"prefix": prefix}))
    if update_rate is not None:
        params = injection.merge(params, {"controller_manager": {"ros__parameters": {"update_rate": update_rate}}})
    args = {}
    args["prefix"] = prefix
    args["use_mock_hardware"] = use_mock_hardware
    spawn = []
    for name in ("joint_state_broadcaster", robot_controller):
        spawn.append(name)
    return bringup(description="rrbot", controllers=copy.deepcopy(params), xacro_args=args, spawn=spawn,
                   inactive=[other])
'''

#: An alternative bringup: the validation as a set, the rate set in a deep copy of the loaded mapping.
BRINGUP_SET_AND_COPY = '''"""Task 12, written a third way."""
from __future__ import annotations

import copy
import os

import rrbot_workshop as rw
from rrbot_workshop.middleware.param_substitution import load_with_substitutions

ARMS = {"joint_trajectory_controller", "forward_position_controller"}


def start_rrbot(prefix: str = "", robot_controller: str = "forward_position_controller",
                update_rate: int | None = None, use_mock_hardware: bool = True) -> rw.System:
    if robot_controller not in ARMS:
        raise ValueError("robot_controller %r is not a robot controller; choose joint_trajectory_controller or "
                         "forward_position_controller" % robot_controller)
    path = os.path.join(os.path.dirname(__file__), "config", "rrbot_controllers.yaml")
    cfg = copy.deepcopy(load_with_substitutions(path, dict(prefix=prefix)))
    if update_rate:
        cfg["controller_manager"]["ros__parameters"]["update_rate"] = int(update_rate)
    return rw.bringup("rrbot", cfg, xacro_args=dict(use_mock_hardware=use_mock_hardware, prefix=prefix),
                      inactive=sorted(ARMS - {robot_controller}), spawn=["joint_state_broadcaster", robot_controller])
'''

#: An alternative YAML: flow lists, quoted values, sections in another order.
YAML_FLOW = """# prefix-aware controllers
joint_trajectory_controller:
  ros__parameters:
    joints: ["$(var prefix)joint1", "$(var prefix)joint2"]
    command_interfaces: ["position"]
    state_interfaces: ["position", "velocity"]
    allow_partial_joints_goal: false
    constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}

forward_position_controller:
  ros__parameters: {joints: ["$(var prefix)joint1", "$(var prefix)joint2"], interface_name: position}

controller_manager:
  ros__parameters:
    joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    forward_position_controller: {type: forward_command_controller/ForwardCommandController}
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    update_rate: 100
"""

#: An alternative YAML: each controller's type in its own section (a layout Jazzy's spawner reads), block style.
YAML_TYPES_IN_OWN_SECTIONS = """controller_manager:
  ros__parameters:
    update_rate: 100

joint_state_broadcaster:
  ros__parameters:
    type: joint_state_broadcaster/JointStateBroadcaster

forward_position_controller:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    joints:
      - $(var prefix)joint1
      - $(var prefix)joint2
    interface_name: position

joint_trajectory_controller:
  ros__parameters:
    type: joint_trajectory_controller/JointTrajectoryController
    joints: [$(var prefix)joint1, $(var prefix)joint2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
    allow_partial_joints_goal: false
    constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}
"""

#: The same in flow style, the manager's section written as ``/**/controller_manager``.
YAML_TYPES_IN_OWN_SECTIONS_FLOW = """/**/controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster}}
forward_position_controller: {ros__parameters: {type: forward_command_controller/ForwardCommandController,
  joints: ["$(var prefix)joint1", "$(var prefix)joint2"], interface_name: position}}
joint_trajectory_controller: {ros__parameters: {type: joint_trajectory_controller/JointTrajectoryController,
  joints: ["$(var prefix)joint1", "$(var prefix)joint2"], command_interfaces: [position],
  state_interfaces: [position, velocity], allow_partial_joints_goal: false,
  constraints: {stopped_velocity_tolerance: 0.01, goal_time: 0.0}}}
"""

RIGHT = [
    Variant("types_in_the_controllers_own_sections", {YAML: YAML_TYPES_IN_OWN_SECTIONS}),
    Variant("types_in_own_sections_flow_style", {YAML: YAML_TYPES_IN_OWN_SECTIONS_FLOW}),
    Variant("substituted_by_hand_and_merged", {BRINGUP: BRINGUP_BY_HAND}),
    Variant("set_validation_and_a_deep_copy", {BRINGUP: BRINGUP_SET_AND_COPY}),
    Variant("flow_yaml_in_another_order", {YAML: YAML_FLOW}),
    Variant("keyword_xacro_args_and_quoted_joints", {
        BRINGUP: [(XACRO, 'xacro_args=dict(use_mock_hardware=bool(use_mock_hardware), prefix=str(prefix))')],
        YAML: _yaml("      - $(var prefix)joint1\n      - $(var prefix)joint2",
                    "      - \"$(var prefix)joint1\"\n      - \"$(var prefix)joint2\""),
    }),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(12, WRONG + RIGHT, Path(tmp_path_factory.mktemp("task12")))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(12), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(12))


def test_enough_variants() -> None:
    """The issue asks for at least 12 wrong and 3 alternative solutions per task."""
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


def test_exercise_as_handed_out_gets_a_clear_reason() -> None:
    """The untouched exercise scores 0, and its first causes' reasons say where to start: the learner's file and line,
    and the TODO still to write."""
    rubric = grade(12, track="exercises", record=False)
    assert rubric.score == 0, rubric.format()
    reasons = " ".join(check.detail for check in rubric.failed() if not check.blocked_by)
    for phrase in ("rrbot_controllers.yaml, line", "bringup.py, line", "TODO(task 12.2)"):
        assert phrase in reasons, rubric.format()
