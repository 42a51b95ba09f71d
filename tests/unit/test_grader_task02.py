"""The task-2 grader: wrong switches, YAML files and bringups, written as learners get them wrong, lose points; right
ones written differently from solutions/ get full marks.

Full marks on solutions/ and 0 on the untouched exercise are checked for every grader in test_graders.py.
"""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

CONTROLLERS = "rrbot_bringup/config/rrbot_controllers.yaml"
TAG = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
MAIN = "rrbot_description/urdf/rrbot.urdf.xacro"
BRINGUP = "rrbot_bringup/bringup.py"

JTC_DECLARED = """
    # Interpolates trajectories received on ~/joint_trajectory (or the follow_joint_trajectory action).
    joint_trajectory_controller:
      type: joint_trajectory_controller/JointTrajectoryController
"""
JTC_SECTION_START = "\n\njoint_trajectory_controller:\n  ros__parameters:\n"
#: The trajectory controller's own section, as solutions/ writes it.
JTC_SECTION = (
    '\n'
    '\n'
    'joint_trajectory_controller:\n'
    '  ros__parameters:\n'
    '    joints:\n'
    '      - joint1\n'
    '      - joint2\n'
    '\n'
    '    command_interfaces:  # what it writes\n'
    '      - position\n'
    '\n'
    '    state_interfaces:    # what it reads back (feedback and the start of each new trajectory)\n'
    '      - position\n'
    '      - velocity\n'
    '\n'
    "    # The original workshop also set `state_publish_rate: 50.0`. Jazzy's controller has no such parameter\n"
    '    # any more (it publishes its state on every update), so it is left out.\n'
    '    action_monitor_rate: 20.0         # [Hz]: how often the action server checks a running goal\n'
    '    allow_partial_joints_goal: false  # every trajectory must name both joints\n'
    '\n'
    '    constraints:\n'
    '      stopped_velocity_tolerance: 0.01  # [rad/s]: slower than this counts as stopped at the goal\n'
    "      goal_time: 0.0                    # [s] allowed after the trajectory's end to reach the goal; 0: no limit\n"
)
BRINGUP_STEPS = """    try:
        cm.load_controller(robot_controller)
        cm.configure_controller(robot_controller)
        cm.switch_controllers(activate=[robot_controller], strictness="strict")

        # `spawner <other> --inactive`: ready to be switched to.
        other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller)
        cm.load_controller(other)
        cm.configure_controller(other)
    except Exception:
        system.shutdown()
        raise
    return system"""
XACRO_ARGS = 'xacro_args={"use_mock_hardware": use_mock_hardware, "mock_sensor_commands": mock_sensor_commands},'


HARDWARE = """        <xacro:if value="${use_mock_hardware}">
          <!-- Mock hardware: each command shows up on the state interface of the same name at the next read. -->
          <plugin>mock_components/GenericSystem</plugin>
          <!-- true: the mock also offers a command interface per sensor state (tcp_fts_sensor/fx, ...), so a
               test can set what the sensor "measures". -->
          <param name="mock_sensor_commands">${mock_sensor_commands}</param>
        </xacro:if>
        <xacro:unless value="${use_mock_hardware}">
          <!-- The real robot's driver (task 7 writes it). -->
          <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
        </xacro:unless>
"""
FPC_TYPE = "    forward_position_controller:\n      type: forward_command_controller/ForwardCommandController\n"
JTC_JOINTS = ("joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n")
TYPES_IN_OWN_SECTIONS = [
    ("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n", ""),
    (FPC_TYPE, ""),
    (JTC_DECLARED, "\n"),
    ("\n\nforward_position_controller:\n  ros__parameters:\n",
     "\n\njoint_state_broadcaster:\n  ros__parameters:\n    type: joint_state_broadcaster/JointStateBroadcaster\n"
     "\n\nforward_position_controller:\n  ros__parameters:\n"
     "    type: forward_command_controller/ForwardCommandController\n"),
    (JTC_SECTION_START, JTC_SECTION_START + "    type: joint_trajectory_controller/JointTrajectoryController\n"),
]

#: One cause, several checks (each names the cause in graded(after=...)), or several slips at once.
MANY_RULES = {"yaml_without_the_trajectory_controller", "yaml_without_the_trajectory_controller_section"}

WRONG = [
    # --- the YAML: each stated value, in either layout; one slip costs the rule it breaks
    Variant("yaml_without_the_trajectory_controller", {CONTROLLERS: [(JTC_DECLARED, "\n"), (JTC_SECTION, "\n")]},
            fails={"controller_types", "joint_trajectory_controller_interfaces", "joint_trajectory_controller_constraints",
                   "parameters_valid_in_jazzy"}, only=True),
    Variant("yaml_without_the_trajectory_controller_section", {CONTROLLERS: [(JTC_SECTION, "\n")]},
            fails={"joint_trajectory_controller_interfaces", "joint_trajectory_controller_constraints"}, only=True,
            says={"joint_trajectory_controller_interfaces": "own section"}),
    Variant("state_publish_rate_of_humble", {CONTROLLERS: [
        ("    action_monitor_rate: 20.0", "    state_publish_rate: 50.0\n    action_monitor_rate: 20.0")]},
            fails={"parameters_valid_in_jazzy"}, only=True, says={"parameters_valid_in_jazzy": "state_publish_rate"}),
    Variant("forward_controller_on_velocity", {CONTROLLERS: [("interface_name: position", "interface_name: velocity")]},
            fails={"forward_position_controller_parameters"}, only=True,
            says={"forward_position_controller_parameters": "interface_name is 'velocity'"}),
    Variant("forward_interface_name_as_a_list", {CONTROLLERS: [("interface_name: position", "interface_name: [position]")]},
            fails={"forward_position_controller_parameters"}, only=True),
    Variant("update_rate_of_10_hz", {CONTROLLERS: [("update_rate: 100", "update_rate: 10")]}, fails={"update_rate"},
            only=True, says={"update_rate": "100"}),
    Variant("update_rate_as_a_float", {CONTROLLERS: [("update_rate: 100", "update_rate: 100.0")]}, fails={"update_rate"},
            only=True, says={"update_rate": "integer"}),
    Variant("update_rate_as_a_string", {CONTROLLERS: [("update_rate: 100", 'update_rate: "100"')]}, fails={"update_rate"},
            only=True),
    Variant("trajectory_controller_writing_velocity_too", {CONTROLLERS: [
        ("command_interfaces:  # what it writes\n      - position",
         "command_interfaces:  # what it writes\n      - position\n      - velocity")]},
            fails={"joint_trajectory_controller_interfaces"}, only=True),
    Variant("trajectory_controller_reading_position_only", {CONTROLLERS: [
        ("state_interfaces:    # what it reads back (feedback and the start of each new trajectory)\n      - position\n"
         "      - velocity", "state_interfaces:\n      - position")]},
            fails={"joint_trajectory_controller_interfaces"}, only=True),
    Variant("trajectory_joints_not_in_the_stated_order", {CONTROLLERS: [
        (JTC_JOINTS, JTC_JOINTS.replace("- joint1\n      - joint2", "- joint2\n      - joint1"))]},
            fails={"joint_trajectory_controller_interfaces"}, only=True, says={"joint_trajectory_controller_interfaces": "joints"}),
    Variant("forward_joints_reversed", {CONTROLLERS: [
        ("forward_position_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2",
         "forward_position_controller:\n  ros__parameters:\n    joints:\n      - joint2\n      - joint1")]},
            fails={"forward_position_controller_parameters"}, only=True,
            says={"forward_position_controller_parameters": "in that order"}),
    Variant("partial_goals_allowed", {CONTROLLERS: [("allow_partial_joints_goal: false", "allow_partial_joints_goal: true")]},
            fails={"joint_trajectory_controller_constraints"}, only=True),
    Variant("goal_time_of_half_a_second", {CONTROLLERS: [("goal_time: 0.0 ", "goal_time: 0.5 ")]},
            fails={"joint_trajectory_controller_constraints"}, only=True, says={"joint_trajectory_controller_constraints": "goal_time"}),
    Variant("stopped_velocity_tolerance_left_out", {CONTROLLERS: [
        ("      stopped_velocity_tolerance: 0.01  # [rad/s]: slower than this counts as stopped at the goal\n", "")]},
            fails={"joint_trajectory_controller_constraints"}, only=True),
    Variant("own_sections_with_a_misspelled_type", {CONTROLLERS: TYPES_IN_OWN_SECTIONS + [
        ("    type: forward_command_controller/ForwardCommandController\n",
         "    type: forward_command_controller/ForwardCommandControler\n")]},
            fails={"controller_types"}, only=True, says={"controller_types": "ForwardCommandControler"}),
    # --- the description: the switch, both ways, really passed through
    Variant("hard_coded_mock_sensor_commands", {TAG: [
        ('<param name="mock_sensor_commands">${mock_sensor_commands}</param>',
         '<param name="mock_sensor_commands">false</param>')]},
            fails={"mock_sensor_commands_reaches_the_mock", "description_defaults_to_the_driver",
                   "macro_takes_the_switch_as_parameters"}, only=True),
    Variant("mock_in_both_branches", {TAG: [
        ("<plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>",
         "<plugin>mock_components/GenericSystem</plugin>")]}, fails={"use_mock_hardware_switch"}, only=True,
            says={"use_mock_hardware_switch": "use_mock_hardware:=false"}),
    Variant("if_without_unless", {TAG: [
        ("        <xacro:unless value=\"${use_mock_hardware}\">\n          <!-- The real robot's driver (task 7 writes it). -->\n"
         "          <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>\n        </xacro:unless>",
         "        <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>")]},
            fails={"use_mock_hardware_switch"}, only=True, says={"use_mock_hardware_switch": "2 <plugin> tags"}),
    Variant("description_defaults_to_the_mock", {MAIN: [
        ('<xacro:arg name="use_mock_hardware" default="false" />', '<xacro:arg name="use_mock_hardware" default="true" />')]},
            fails={"description_defaults_to_the_driver"}, only=True, says={"description_defaults_to_the_driver": "defaults to false"}),
    Variant("sensor_commands_default_true", {MAIN: [
        ('<xacro:arg name="mock_sensor_commands" default="false" />', '<xacro:arg name="mock_sensor_commands" default="true" />')]},
            fails={"description_defaults_to_the_driver"}, only=True, says={"description_defaults_to_the_driver": "mock_sensor_commands"}),
    Variant("sensor_commands_not_handed_to_the_macro", {MAIN: [
        ('    mock_sensor_commands="$(arg mock_sensor_commands)" />', "    />")]},
            fails={"mock_sensor_commands_reaches_the_mock", "description_defaults_to_the_driver"}, only=True,
            says={"mock_sensor_commands_reaches_the_mock": "mock_sensor_commands:=true"}),
    Variant("macro_reads_the_argument_itself", {TAG: [
        ('<xacro:if value="${use_mock_hardware}">', '<xacro:if value="$(arg use_mock_hardware)">'),
        ('<xacro:unless value="${use_mock_hardware}">', '<xacro:unless value="$(arg use_mock_hardware)">')]},
            fails={"macro_takes_the_switch_as_parameters"}, only=True,
            says={"macro_takes_the_switch_as_parameters": "reads $(arg ...) itself"}),
    Variant("macro_parameters_without_defaults", {TAG: [
        ("params=\"name prefix use_mock_hardware:=false mock_sensor_commands:=false\"",
         "params=\"name prefix use_mock_hardware mock_sensor_commands\"")]},
            fails={"macro_takes_the_switch_as_parameters"}, only=True, says={"macro_takes_the_switch_as_parameters": "defaults"}),
    Variant("macro_defaults_to_the_mock", {TAG: [
        ("params=\"name prefix use_mock_hardware:=false", "params=\"name prefix use_mock_hardware:=true")]},
            fails={"macro_takes_the_switch_as_parameters"}, only=True, says={"macro_takes_the_switch_as_parameters": "defaults to false"}),
    # --- the bringup: each rule on its own (a broken YAML or description of the learner's is stood in for)
    Variant("bringup_without_the_inactive_controller", {BRINGUP: [
        ("        cm.load_controller(other)\n        cm.configure_controller(other)\n", "")]},
            fails={"other_controller_loaded_inactive"}, only=True, says={"other_controller_loaded_inactive": "not loaded"}),
    Variant("other_controller_loaded_not_configured", {BRINGUP: [
        ("        cm.load_controller(other)\n        cm.configure_controller(other)\n", "        cm.load_controller(other)\n")]},
            fails={"other_controller_loaded_inactive"}, only=True, says={"other_controller_loaded_inactive": "unconfigured"}),
    Variant("bringup_ignoring_robot_controller", {BRINGUP: [
        ("        cm.load_controller(robot_controller)\n        cm.configure_controller(robot_controller)\n"
         "        cm.switch_controllers(activate=[robot_controller]",
         "        cm.load_controller(ROBOT_CONTROLLERS[0])\n        cm.configure_controller(ROBOT_CONTROLLERS[0])\n"
         "        cm.switch_controllers(activate=[ROBOT_CONTROLLERS[0]]")]},
            fails={"other_controller_loaded_inactive"}, only=True),
    Variant("bringup_always_on_the_mock", {BRINGUP: [
        (XACRO_ARGS, 'xacro_args={"use_mock_hardware": True, "mock_sensor_commands": mock_sensor_commands},')]},
            fails={"start_rrbot_passes_use_mock_hardware"}, only=True),
    Variant("bringup_always_with_sensor_commands", {BRINGUP: [
        (XACRO_ARGS, 'xacro_args={"use_mock_hardware": use_mock_hardware, "mock_sensor_commands": True},')]},
            fails={"start_rrbot_passes_mock_sensor_commands"}, only=True),
    Variant("bringup_without_xacro_arguments", {BRINGUP: [(XACRO_ARGS, "")]},
            fails={"start_rrbot_activates_controllers", "start_rrbot_returns_at_time_zero",
                   "other_controller_loaded_inactive", "start_rrbot_passes_mock_sensor_commands",
                   "failure_half_way_leaves_nothing_running", "forward_command_reaches_the_joints",
                   "forward_commands_in_joint_order", "joint_trajectory_controller_reaches_the_goals"},
            says={"start_rrbot_activates_controllers": "RRBotHardwareInterface"}),
    Variant("bringup_waits_like_the_launch_file", {BRINGUP: [
        ("    cm = system.controller_manager\n", "    system.spin(1.0)  # the launch file's delay\n    cm = system.controller_manager\n")]},
            fails={"start_rrbot_returns_at_time_zero"}, only=True, says={"start_rrbot_returns_at_time_zero": "t = 1 s"}),
    Variant("bringup_without_cleanup", {BRINGUP: [(BRINGUP_STEPS, """    cm.load_controller(robot_controller)
    cm.configure_controller(robot_controller)
    cm.switch_controllers(activate=[robot_controller], strictness="strict")
    other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller)
    cm.load_controller(other)
    cm.configure_controller(other)
    return system""")]}, fails={"failure_half_way_leaves_nothing_running"}, only=True,
            says={"failure_half_way_leaves_nothing_running": "left the system"}),
    Variant("bringup_swallowing_the_error", {BRINGUP: [("    except Exception:\n        system.shutdown()\n        raise\n",
                                                        "    except Exception as exc:\n        print('spawner failed:', exc)\n")]},
            fails={"failure_half_way_leaves_nothing_running"}, only=True,
            says={"failure_half_way_leaves_nothing_running": "instead of raising"}),
    Variant("bringup_shuts_down_always", {BRINGUP: [("    except Exception:\n        system.shutdown()\n        raise\n",
                                                     "    finally:\n        system.shutdown()\n")]},
            fails={"start_rrbot_activates_controllers", "start_rrbot_returns_at_time_zero",
                   "other_controller_loaded_inactive", "start_rrbot_passes_use_mock_hardware",
                   "start_rrbot_passes_mock_sensor_commands", "failure_half_way_leaves_nothing_running",
                   "forward_command_reaches_the_joints", "forward_commands_in_joint_order",
                   "joint_trajectory_controller_reaches_the_goals"},
            says={"start_rrbot_activates_controllers": "shut down"}),
    Variant("bringup_returns_nothing", {BRINGUP: [("        raise\n    return system", "        raise")]},
            fails={"start_rrbot_activates_controllers", "start_rrbot_returns_at_time_zero",
                   "other_controller_loaded_inactive", "start_rrbot_passes_use_mock_hardware",
                   "start_rrbot_passes_mock_sensor_commands", "failure_half_way_leaves_nothing_running",
                   "forward_command_reaches_the_joints", "forward_commands_in_joint_order",
                   "joint_trajectory_controller_reaches_the_goals"}, names_file="bringup.py",
            says={"start_rrbot_activates_controllers": "NoneType"}),
]


#: The whole file in flow style, the controllers' own sections first, no comments.
FLOW_YAML = """\
forward_position_controller: {ros__parameters: {interface_name: position, joints: [joint1, joint2]}}
joint_trajectory_controller:
  ros__parameters: {joints: [joint1, joint2], command_interfaces: [position], state_interfaces: [position, velocity],
    allow_partial_joints_goal: false, constraints: {goal_time: 0, stopped_velocity_tolerance: 1.0e-2}}
controller_manager:
  ros__parameters:
    joint_trajectory_controller: {type: joint_trajectory_controller/JointTrajectoryController}
    forward_position_controller: {type: forward_command_controller/ForwardCommandController}
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    update_rate: 100
"""

#: One rw.bringup call spawning both, the other controller inactive (bringup shuts down what fails itself).
ONE_CALL_BRINGUP = '''"""start_rrbot in one bringup call."""

from pathlib import Path

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ParameterError

HERE = Path(__file__).parent
CHOICES = ["forward_position_controller", "joint_trajectory_controller"]


def start_rrbot(robot_controller="forward_position_controller", use_mock_hardware=True, mock_sensor_commands=False):
    if robot_controller not in CHOICES:
        raise ParameterError("start_rrbot", "robot_controller", f"must be one of {CHOICES}")
    (other,) = [c for c in CHOICES if c != robot_controller]
    return rw.bringup(
        HERE.parent / "rrbot_description/urdf/rrbot.urdf.xacro",
        HERE / "config" / "rrbot_controllers.yaml",
        xacro_args=dict(use_mock_hardware=use_mock_hardware, mock_sensor_commands=mock_sensor_commands),
        spawn=["joint_state_broadcaster", robot_controller],
        inactive=[other],
    )
'''

#: Steps in a loop, the other controller first, cleanup in a helper.
LOOP_BRINGUP = '''"""start_rrbot with its spawner steps in a loop."""

from pathlib import Path

from rrbot_workshop.bringup import bringup

ROOT = Path(__file__).resolve().parents[1]


def _spawn(cm, name, activate):
    cm.load_controller(name)
    cm.configure_controller(name)
    if activate:
        cm.switch_controllers(activate=[name], strictness="strict")


def start_rrbot(robot_controller="forward_position_controller", use_mock_hardware=True, mock_sensor_commands=False):
    args = {"use_mock_hardware": "true" if use_mock_hardware else "false",
            "mock_sensor_commands": "true" if mock_sensor_commands else "false"}
    system = bringup(ROOT / "rrbot_description" / "urdf" / "rrbot.urdf.xacro",
                     ROOT / "rrbot_bringup" / "config" / "rrbot_controllers.yaml",
                     xacro_args=args, spawn=["joint_state_broadcaster"])
    plan = [(name, name == robot_controller)
            for name in ("joint_trajectory_controller", "forward_position_controller")]
    try:
        for name, activate in sorted(plan, key=lambda step: step[1], reverse=True):
            _spawn(system.controller_manager, name, activate)
    except BaseException:
        system.shutdown()
        raise
    return system
'''

#: The plugin chosen by a Python expression; the mock's param under its own xacro:if; properties for the names.
EXPRESSION_SWITCH = [
    ("""        <xacro:if value="${use_mock_hardware}">
          <!-- Mock hardware: each command shows up on the state interface of the same name at the next read. -->
          <plugin>mock_components/GenericSystem</plugin>""",
     """        <xacro:property name="mock_plugin" value="mock_components/GenericSystem" />
        <xacro:property name="robot_plugin" value="controlko_hardware_interface/RRBotHardwareInterface" />
        <plugin>${mock_plugin if use_mock_hardware else robot_plugin}</plugin>
        <xacro:if value="${use_mock_hardware}">"""),
    ("""        <xacro:unless value="${use_mock_hardware}">
          <!-- The real robot's driver (task 7 writes it). -->
          <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
        </xacro:unless>
""", ""),
]

#: Flow style, each controller's type in its own section (Jazzy's spawner reads it there), the manager as '/**/'.
FLOW_OWN_SECTIONS_YAML = """\
/**/controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster}}
forward_position_controller: {ros__parameters: {type: forward_command_controller/ForwardCommandController,
  joints: [joint1, joint2], interface_name: position}}
joint_trajectory_controller:
  ros__parameters:
    type: joint_trajectory_controller/JointTrajectoryController
    joints: [joint1, joint2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
    allow_partial_joints_goal: False
    constraints: {stopped_velocity_tolerance: .01, goal_time: 0.}
"""

#: The <hardware> block in a helper macro of a file of its own, included by the <ros2_control> macro.
HARDWARE_MACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="rrbot_hardware" params="mock sensor_commands">
    <hardware>
      <xacro:if value="${mock}">
        <plugin>mock_components/GenericSystem</plugin>
        <param name="mock_sensor_commands">${sensor_commands}</param>
      </xacro:if>
      <xacro:unless value="${mock}">
        <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
      </xacro:unless>
    </hardware>
  </xacro:macro>
</robot>
"""
HELPER_MACRO = {
    "rrbot_description/urdf/rrbot/rrbot_hardware.xacro": HARDWARE_MACRO,
    TAG: [("<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n",
           "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:include filename=\"rrbot_hardware.xacro\" />\n"),
          ("      <hardware>\n" + HARDWARE + "      </hardware>\n",
           "      <xacro:rrbot_hardware mock=\"${use_mock_hardware}\" sensor_commands=\"${mock_sensor_commands}\" />\n")],
}

#: Jazzy's launch files hand the spawner the controllers file (--param-file): system.spawn(..., param_file=...).
SPAWNER_BRINGUP = '''"""start_rrbot with the spawner's --param-file."""

from pathlib import Path

import rrbot_workshop as rw

CONFIG = Path(__file__).resolve().parent / "config" / "rrbot_controllers.yaml"
ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")


def start_rrbot(robot_controller="forward_position_controller", use_mock_hardware=True, mock_sensor_commands=False):
    description = Path(__file__).resolve().parents[1] / "rrbot_description" / "urdf" / "rrbot.urdf.xacro"
    system = rw.bringup(description, CONFIG, xacro_args={"use_mock_hardware": str(use_mock_hardware).lower(),
                                                         "mock_sensor_commands": str(mock_sensor_commands).lower()})
    try:
        system.spawn(["joint_state_broadcaster"], param_file=CONFIG)
        system.spawn([robot_controller], param_file=CONFIG)
        system.spawn([c for c in ROBOT_CONTROLLERS if c != robot_controller], inactive=True, param_file=CONFIG)
    except Exception:
        system.shutdown()
        raise
    return system
'''

RIGHT = [
    Variant("flow_yaml_other_order", {CONTROLLERS: FLOW_YAML}),
    Variant("types_in_their_own_sections", {CONTROLLERS: TYPES_IN_OWN_SECTIONS}),
    Variant("flow_yaml_types_in_their_own_sections", {CONTROLLERS: FLOW_OWN_SECTIONS_YAML}),
    Variant("hardware_in_a_helper_macro_file", HELPER_MACRO),
    Variant("spawner_with_the_param_file", {BRINGUP: SPAWNER_BRINGUP, CONTROLLERS: TYPES_IN_OWN_SECTIONS}),
    Variant("one_bringup_call", {BRINGUP: ONE_CALL_BRINGUP}),
    Variant("spawner_steps_in_a_loop", {BRINGUP: LOOP_BRINGUP}),
    Variant("plugin_chosen_by_an_expression", {TAG: EXPRESSION_SWITCH}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(2, WRONG + RIGHT, tmp_path_factory.mktemp("task02"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name not in MANY_RULES], ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(2), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(2))


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3
