"""The task-5 grader against wrong solutions written as learners would, and against right ones written differently.

Each variant is a copy of ``solutions/task05_simulation/`` with exact changes (see :mod:`grader_variants`); all are
graded once, two at a time, in a module-scoped fixture.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import Rubric

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

MACRO = "rrbot_description/urdf/rrbot/rrbot_macro.xacro"
CONTROL = "rrbot_description/urdf/rrbot/rrbot_macro.ros2_control.xacro"
TOP = "rrbot_description/urdf/rrbot.urdf.xacro"
BRINGUP = "rrbot_bringup/bringup.py"

J1_LIMIT = 'upper="${radians(380)}" effort="1000.0"'
J2_LIMIT = 'upper="${radians(240)}" effort="1000.0"'
SIM_IF, SIM_UNLESS = '<xacro:if value="${sim_mujoco}">', '<xacro:unless value="${sim_mujoco}">'
PARAMS = 'params="name prefix use_mock_hardware:=false mock_sensor_commands:=false sim_mujoco:=false"'
SOLUTION_HARDWARE = """      <hardware>
        <!-- Task 5: the simulator takes the place of the robot; it wins over the mock. -->
        <xacro:if value="${sim_mujoco}">
          <!-- MuJoCo physics, stepped by the controller manager's read(): 1 ms steps, position servos. -->
          <plugin>rrbot_workshop/MujocoSystem</plugin>
        </xacro:if>
        <xacro:unless value="${sim_mujoco}">
          <xacro:if value="${use_mock_hardware}">
            <!-- Mock hardware: each command shows up on the state interface of the same name at the next read. -->
            <plugin>mock_components/GenericSystem</plugin>
            <param name="mock_sensor_commands">${mock_sensor_commands}</param>
          </xacro:if>
          <xacro:unless value="${use_mock_hardware}">
            <!-- The real robot's driver (task 7 writes it). -->
            <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
          </xacro:unless>
        </xacro:unless>
      </hardware>
"""

#: The solution's <hardware> block, rewritten as three independent blocks (an alternative written differently).
THREE_BLOCKS = """      <hardware>
        <xacro:if value="${sim_mujoco}">
          <plugin>rrbot_workshop/MujocoSystem</plugin>
        </xacro:if>
        <xacro:if value="${not sim_mujoco and use_mock_hardware}">
          <plugin>mock_components/GenericSystem</plugin>
          <param name="mock_sensor_commands">${mock_sensor_commands}</param>
        </xacro:if>
        <xacro:if value="${not sim_mujoco and not use_mock_hardware}">
          <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
        </xacro:if>
      </hardware>
"""

#: The simulator added in front of task 2's choice, which is left unconditional: two plugins with sim_mujoco:=true.
TWO_PLUGINS = """      <hardware>
        <xacro:if value="${sim_mujoco}">
          <plugin>rrbot_workshop/MujocoSystem</plugin>
        </xacro:if>
        <xacro:if value="${use_mock_hardware}">
          <plugin>mock_components/GenericSystem</plugin>
          <param name="mock_sensor_commands">${mock_sensor_commands}</param>
        </xacro:if>
        <xacro:unless value="${use_mock_hardware}">
          <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
        </xacro:unless>
      </hardware>
"""

#: A bringup written in one switch, as notebook 05, the README and rw.bringup's docstring do.
ONE_SWITCH_BRINGUP = '''"""Simulated RRBot, brought up in one call."""

from pathlib import Path

from rrbot_workshop.bringup import bringup
from rrbot_workshop.exceptions import ParameterError

ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")
HERE = Path(__file__).resolve().parent
DESCRIPTION_FILE = HERE.parent / "rrbot_description" / "urdf" / "rrbot.urdf.xacro"
CONTROLLERS_FILE = HERE / "config" / "rrbot_sim_controllers.yaml"


def start_rrbot_sim(robot_controller="joint_trajectory_controller"):
    if robot_controller not in ROBOT_CONTROLLERS:
        raise ParameterError("start_rrbot_sim", "robot_controller", f"must be one of {ROBOT_CONTROLLERS}")
    others = [c for c in ROBOT_CONTROLLERS if c != robot_controller]
    return bringup(str(DESCRIPTION_FILE), str(CONTROLLERS_FILE), xacro_args={"sim_mujoco": "true"},
                   spawn=["joint_state_broadcaster", robot_controller], inactive=others)
'''

#: Step by step, with set_controller_state and a loop, refusing through a dict lookup.
STEPWISE_BRINGUP = '''"""Simulated RRBot, one spawner at a time."""

from pathlib import Path

import rrbot_workshop as rw
from rrbot_workshop.exceptions import ParameterError

ROBOT_CONTROLLERS = ("forward_position_controller", "joint_trajectory_controller")
DESCRIPTION_FILE = Path(__file__).resolve().parents[1] / "rrbot_description/urdf/rrbot.urdf.xacro"
CONTROLLERS_FILE = Path(__file__).resolve().parent / "config/rrbot_sim_controllers.yaml"
_OTHER = {"forward_position_controller": "joint_trajectory_controller",
          "joint_trajectory_controller": "forward_position_controller"}


def start_rrbot_sim(robot_controller: str = "joint_trajectory_controller"):
    other = _OTHER.get(robot_controller)
    if other is None:
        raise ParameterError(owner="start_rrbot_sim", parameter="robot_controller",
                             message=f"unknown controller {robot_controller!r}")
    system = rw.bringup(DESCRIPTION_FILE, CONTROLLERS_FILE, xacro_args=dict(sim_mujoco=True, use_mock_hardware=False))
    try:
        cm = system.controller_manager
        for name in ("joint_state_broadcaster", robot_controller, other):
            cm.load_controller(name)
            cm.set_controller_state(name, "inactive")
            if name != other:
                cm.switch_controllers(activate=[name], strictness="strict")
    except BaseException:
        system.shutdown()
        raise
    return system
'''

WRONG = [
    Variant("motors_too_weak_to_hold_the_arm",
            {MACRO: [(J1_LIMIT, J1_LIMIT.replace("1000.0", "1.0")), (J2_LIMIT, J2_LIMIT.replace("1000.0", "1.0"))]},
            fails={"goals_reached_in_physics"}, only=True),
    Variant("only_joint1_raised_joint2_still_1_nm", {MACRO: [(J2_LIMIT, J2_LIMIT.replace("1000.0", "1.0"))]},
            fails={"goals_reached_in_physics"}, only=True),
    Variant("mock_wins_over_the_simulator",
            {CONTROL: [(SIM_IF, '<xacro:if value="${sim_mujoco and not use_mock_hardware}">'),
                       (SIM_UNLESS, '<xacro:unless value="${sim_mujoco and not use_mock_hardware}">')]},
            fails={"simulator_selected", "hardware_choice_generated"}),
    Variant("two_plugins_in_one_hardware",
            {CONTROL: [(SOLUTION_HARDWARE, TWO_PLUGINS)]},
            fails={"simulator_selected", "macro_parameter", "hardware_choice_generated"},
            says={"macro_parameter": "2 <plugin> tags"}),
    Variant("argument_not_passed_to_the_macro", {TOP: [('    sim_mujoco="$(arg sim_mujoco)"\n', "")]},
            fails={"simulator_selected", "hardware_choice_generated"}, says={"simulator_selected": "sim_mujoco:=True"}),
    Variant("xacro_arg_read_inside_the_macro",
            {CONTROL: [(SIM_IF, '<xacro:if value="$(arg sim_mujoco)">'),
                       (SIM_UNLESS, '<xacro:unless value="$(arg sim_mujoco)">'),
                       (PARAMS, PARAMS.replace(" sim_mujoco:=false", ""))],
             TOP: [('    sim_mujoco="$(arg sim_mujoco)"\n', "")]},
            fails={"macro_parameter"}, only=True),
    Variant("mock_sensor_commands_dropped",
            {CONTROL: [('            <param name="mock_sensor_commands">${mock_sensor_commands}</param>\n', "")]},
            fails={"task2_choice_without_the_simulator", "hardware_choice_generated"}),
    Variant("simulator_always_on_by_default", {CONTROL: [(PARAMS, PARAMS.replace("sim_mujoco:=false", "sim_mujoco:=true"))],
                                               TOP: [('<xacro:arg name="sim_mujoco" default="false" />',
                                                      '<xacro:arg name="sim_mujoco" default="true" />')]},
            fails={"task2_choice_without_the_simulator", "macro_parameter", "hardware_choice_generated"}),
    Variant("bringup_on_the_mock", {BRINGUP: [('xacro_args={"sim_mujoco": True}', 'xacro_args={"use_mock_hardware": True}')]},
            fails={"bringup_default", "bringup_robot_controller_argument"}),
    Variant("robot_controller_argument_ignored",
            {BRINGUP: [("        cm.load_controller(robot_controller)\n        cm.configure_controller(robot_controller)\n"
                        "        cm.switch_controllers(activate=[robot_controller]",
                        '        cm.load_controller("joint_trajectory_controller")\n'
                        '        cm.configure_controller("joint_trajectory_controller")\n'
                        '        cm.switch_controllers(activate=["joint_trajectory_controller"]'),
                       ("other = next(name for name in ROBOT_CONTROLLERS if name != robot_controller)",
                        'other = "forward_position_controller"')]},
            fails={"bringup_robot_controller_argument"}, only=True),
    Variant("robot_controller_before_the_broadcaster",
            {BRINGUP: [('spawn=["joint_state_broadcaster"])', "spawn=[])"),
                       ("        other = next(", '        cm.load_controller("joint_state_broadcaster")\n'
                        '        cm.configure_controller("joint_state_broadcaster")\n'
                        '        cm.switch_controllers(activate=["joint_state_broadcaster"], strictness="strict")\n'
                        "        other = next(")]},
            fails={"broadcaster_not_after_the_robot_controller"}, only=True),
    Variant("other_controller_not_loaded",
            {BRINGUP: [("        cm.load_controller(other)\n        cm.configure_controller(other)\n", "")]},
            fails={"bringup_default", "bringup_robot_controller_argument"}, says={"bringup_default": "not loaded"}),
    Variant("refused_with_a_value_error",
            {BRINGUP: [('raise ParameterError("start_rrbot_sim", "robot_controller",',
                        'raise ValueError("start_rrbot_sim", "robot_controller",')]},
            fails={"bringup_refuses_an_unknown_controller"}, only=True),
    Variant("refused_after_the_system_is_up",
            {BRINGUP: [("    if robot_controller not in ROBOT_CONTROLLERS:\n", "    if False:\n"),
                       ("    cm = system.controller_manager\n",
                        "    cm = system.controller_manager\n    if robot_controller not in ROBOT_CONTROLLERS:\n"
                        '        raise ParameterError("start_rrbot_sim", "robot_controller", "unknown")\n')]},
            fails={"bringup_refuses_an_unknown_controller"}, only=True),
    Variant("system_left_running_after_a_failure",
            {BRINGUP: [("    except Exception:\n        system.shutdown()\n        raise\n",
                        "    except Exception:\n        raise\n")]},
            fails={"bringup_failure_leaves_nothing_running"}, only=True),
    Variant("failure_swallowed", {BRINGUP: [("    except Exception:\n        system.shutdown()\n        raise\n",
                                             "    except Exception:\n        pass\n")]},
            fails={"bringup_failure_leaves_nothing_running"}, only=True),
    Variant("spun_before_returning", {BRINGUP: [("        raise\n    return system\n",
                                                 "        raise\n    system.spin(0.5)\n    return system\n")]},
            fails={"bringup_default", "bringup_robot_controller_argument"}),
]

WRONG += [
    Variant("refused_after_a_system_came_up_and_went_down",
            {BRINGUP: [("    if robot_controller not in ROBOT_CONTROLLERS:\n", "    if False:\n"),
                       ("    cm = system.controller_manager\n",
                        "    cm = system.controller_manager\n    if robot_controller not in ROBOT_CONTROLLERS:\n"
                        "        system.shutdown()\n"
                        '        raise ParameterError("start_rrbot_sim", "robot_controller", "unknown")\n')]},
            fails={"bringup_refuses_an_unknown_controller"}, only=True,
            says={"bringup_refuses_an_unknown_controller": "only after bringing a system up"}),
    Variant("simulator_only_without_the_mock",
            {CONTROL: [(SIM_IF, '<xacro:if value="${sim_mujoco and not use_mock_hardware}">'),
                       (SIM_UNLESS, '<xacro:unless value="${sim_mujoco and not use_mock_hardware}">')]},
            fails={"simulator_selected", "macro_parameter", "hardware_choice_generated"},
            says={"simulator_selected": "use_mock_hardware:=True"}),
]

#: The <hardware> block chosen in a helper macro of a file of its own (the TODO leaves the form open).
HARDWARE_MACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="rrbot_hardware" params="sim mock sensor_commands">
    <hardware>
      <xacro:if value="${sim}"><plugin>rrbot_workshop/MujocoSystem</plugin></xacro:if>
      <xacro:if value="${not sim and mock}">
        <plugin>mock_components/GenericSystem</plugin>
        <param name="mock_sensor_commands">${sensor_commands}</param>
      </xacro:if>
      <xacro:if value="${not sim and not mock}">
        <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
      </xacro:if>
    </hardware>
  </xacro:macro>
</robot>
"""

RIGHT = [
    Variant("hardware_in_a_helper_macro_file", {
        "rrbot_description/urdf/rrbot/rrbot_hardware.xacro": HARDWARE_MACRO,
        CONTROL: [('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n',
                   '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n  <xacro:include filename="rrbot_hardware.xacro" />\n'),
                  (SOLUTION_HARDWARE, '      <xacro:rrbot_hardware sim="${sim_mujoco}" mock="${use_mock_hardware}" '
                                      'sensor_commands="${mock_sensor_commands}" />\n')]}),
    Variant("one_switch_bringup", {BRINGUP: ONE_SWITCH_BRINGUP}),
    Variant("stepwise_bringup_with_set_controller_state", {BRINGUP: STEPWISE_BRINGUP}),
    Variant("three_independent_blocks_and_string_defaults",
            {CONTROL: [(SOLUTION_HARDWARE, THREE_BLOCKS),
                       (PARAMS, 'params="name prefix sim_mujoco:=false use_mock_hardware:=false '
                                'mock_sensor_commands:=false"')],
             TOP: [('<xacro:arg name="sim_mujoco" default="false" />', ""),
                   ('<xacro:arg name="prefix" default="" />',
                    '<xacro:arg name="sim_mujoco" default="False" />\n  <xacro:arg name="prefix" default="" />')]}),
    Variant("effort_from_a_property_and_joint2_only_raised",
            {MACRO: [('<xacro:property name="link2_mass" value="0.5" />',
                      '<xacro:property name="link2_mass" value="0.5" />\n  <xacro:property name="sim_effort" value="${25}" />'),
                     (J2_LIMIT, 'upper="${radians(240)}" effort="${sim_effort}"'),
                     (J1_LIMIT, J1_LIMIT.replace("1000.0", "1.0"))]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Rubric]:
    return grade_variants(5, WRONG + RIGHT, Path(tmp_path_factory.mktemp("task05")), workers=2)


def test_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


#: Variants with two slips at once (each shows its own hints).
MANY_SLIPS = {"simulator_always_on_by_default"}


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name not in MANY_SLIPS], ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict[str, Rubric], variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(5), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(5))
