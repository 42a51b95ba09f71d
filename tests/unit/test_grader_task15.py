"""The task-15 grader against wrong and alternative solutions of MyRobot's hardware component and controllers YAML,
written as learners would (among them the habits a ROS 1 user brings).

Each wrong solution is the solution with one mistake and must lose points, failing the checks named; each
alternative is written differently and must get full marks.
"""

from __future__ import annotations

import json
import re

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

PY = "my_robot_hardware.py"
YAML = "my_robot_controllers.yaml"


def wrong(name: str, fails: set[str], *changes: tuple[str, str], file: str = PY, names_file: str = "") -> Variant:
    return Variant(name, {file: list(changes)}, fails=fails, names_file=names_file)


SOFT_CHECKS = {"soft_limits_slow_the_effort_joint", "soft_limits_on_the_position_joint"}

WRONG = [
    # 15.1
    wrong("only_the_first_joint_checked", {"init_refuses_wrong_interfaces"},
          ("        for joint in info.joints:\n            commands", "        for joint in info.joints[:1]:\n            commands")),
    wrong("two_command_interfaces_accepted", {"init_refuses_wrong_interfaces"},
          ("            if len(commands) != 1 or commands[0] not in MODES:\n",
           "            if commands[0] not in MODES:\n")),
    wrong("velocity_state_not_checked", {"init_refuses_wrong_interfaces"},
          ('            if "position" not in states or "velocity" not in states:\n',
           '            if "position" not in states:\n')),
    wrong("printed_instead_of_logged", {"init_logs_why"},
          ('                self.logger.error("joint \'%s\' has command interfaces %s; a motor of MyRobot takes exactly '
           'one, effort "\n                                  "or position", joint.name, commands)\n',
           '                print("wrong command interfaces")\n'),
          ('                self.logger.error("joint \'%s\' has state interfaces %s; the device reports position and '
           'velocity",\n                                  joint.name, states)\n', '                print("wrong states")\n')),
    wrong("joint_names_hard_coded", {"init_accepts_my_robot", "limits_follow_renamed_joints"},
          ("        self.joints = [joint.name for joint in info.joints]\n",
           '        self.joints = ["joint1", "joint2", "joint3"]\n')),
    wrong("a_typo_half_way_through_on_init", {"init_accepts_my_robot", "commands_reach_the_device"},
          ('        path = info.hardware_parameters.get("joint_limits_file", "")\n',
           '        path = info.hardware_parameter.get("joint_limits_file", "")\n'), names_file=PY),
    # 15.2
    wrong("limits_read_from_the_urdf", {"effort_saturated_at_the_yaml_max_effort", "position_rate_limited"},
          ("                hard = get_joint_limits(joint, params, info.limits.get(joint))\n",
           "                hard = info.limits[joint]\n")),
    wrong("urdf_limits_not_the_base", {"urdf_limits_where_the_yaml_is_silent"},
          ("get_joint_limits(joint, params, info.limits.get(joint))", "get_joint_limits(joint, params)")),
    wrong("soft_limits_ignored", SOFT_CHECKS,
          ("                if soft is not None:\n", "                if False:\n")),
    wrong("soft_limits_looked_up_under_joint1", {"limits_follow_renamed_joints"},
          ("                soft = get_soft_joint_limits(joint, params, info.soft_limits.get(joint))\n",
           '                soft = get_soft_joint_limits(joint.replace("left_", ""), params, info.soft_limits.get(joint))\n'
           '                soft = get_soft_joint_limits("joint1", params) if joint.endswith("joint1") else soft\n')),
    wrong("missing_limits_file_runs_unlimited", {"init_refuses_a_missing_limits_file"},
          ('        if not path:\n            self.logger.error("\'%s\' needs the hardware parameter joint_limits_file '
           '(the joint_limits.yaml)", info.name)\n            return CallbackReturn.ERROR\n', ""),
          ("            params = load_joint_limits_yaml(path)\n",
           "            params = load_joint_limits_yaml(path) if path else {}\n")),
    # the TODOs state the refusal's return value: CallbackReturn.ERROR, not FAILURE nor an exception
    Variant("refusal_returns_failure", {PY: [(
        '                                  "or position", joint.name, commands)\n                return CallbackReturn.ERROR\n',
        '                                  "or position", joint.name, commands)\n                return CallbackReturn.FAILURE\n')]},
        fails={"init_refusal_returns_error"}, only=True, says={"init_refusal_returns_error": "returned"}),
    Variant("unusable_limits_file_raises", {PY: [(
        "            self.logger.error(\"'%s': the joint limits cannot be used: %s\", info.name, exc)\n"
        "            return CallbackReturn.ERROR\n",
        "            raise ValueError(f\"the joint limits cannot be used: {exc}\") from exc\n")]},
        fails={"init_refusal_returns_error"}, names_file=PY, says={"init_refusal_returns_error": "raised ValueError"}),
    # validation before anything starts: the limits file is on_init's to check, not on_configure's
    Variant("limits_file_checked_only_in_on_configure", {PY: [
        ('        path = info.hardware_parameters.get("joint_limits_file", "")\n',
         "        self.info_for_limits = info\n        return CallbackReturn.SUCCESS\n\n"
         "    def load_limits(self, info):\n"
         '        path = info.hardware_parameters.get("joint_limits_file", "")\n'),
        ("        self.device = MyRobotDevice(self.modes)\n",
         "        if self.load_limits(self.info_for_limits) is not CallbackReturn.SUCCESS:\n"
         "            return CallbackReturn.ERROR\n        self.device = MyRobotDevice(self.modes)\n")]},
        fails={"init_refuses_a_missing_limits_file"}),
    Variant("urdf_safety_controller_ignored", {PY: [(
        "                soft = get_soft_joint_limits(joint, params, info.soft_limits.get(joint))\n",
        "                soft = get_soft_joint_limits(joint, params)\n")]},
        fails={"urdf_safety_controller_where_the_yaml_is_silent"}, only=True,
        says={"urdf_safety_controller_where_the_yaml_is_silent": "safety_controller"}),
    wrong("limiters_in_reverse_order", {"effort_saturated_at_the_yaml_max_effort"},
          ("zip(self.joints, self.modes, self.limiters, strict=True)",
           "zip(self.joints, self.modes, self.limiters[::-1], strict=True)")),
    # 15.3
    wrong("limits_not_applied", {"effort_saturated_at_the_yaml_max_effort", "position_rate_limited", *SOFT_CHECKS},
          ("            limiter.enforce(actual, desired, period)\n", "")),
    wrong("limited_command_not_sent", {"effort_saturated_at_the_yaml_max_effort", "position_range"},
          ("            commands.append(getattr(desired, mode))\n",
           '            commands.append(self.get_command(f"{joint}/{mode}"))\n')),
    wrong("position_joint_treated_as_effort", {"position_rate_limited", "position_range"},
          ("            setattr(desired, mode, self.get_command(f\"{joint}/{mode}\"))\n",
           "            desired.effort = self.get_command(f\"{joint}/{mode}\")\n"),
          ("            commands.append(getattr(desired, mode))\n", "            commands.append(desired.effort)\n")),
    wrong("period_hard_coded", {"position_rate_limited"},
          ("            limiter.enforce(actual, desired, period)\n", "            limiter.enforce(actual, desired, 0.01)\n")),
    wrong("velocity_left_out_of_actual", {"soft_limits_slow_the_effort_joint"},
          ('            actual = JointControlInterfacesData(joint, position=self.get_state(f"{joint}/position"),\n'
           '                                                velocity=self.get_state(f"{joint}/velocity"))\n',
           '            actual = JointControlInterfacesData(joint, position=self.get_state(f"{joint}/position"))\n')),
    wrong("commands_to_the_device_in_reverse", {"commands_reach_the_device"},
          ("        self.device.write(commands, period)\n", "        self.device.write(commands[::-1], period)\n")),
    # 15.4
    wrong("yaml_ros1_effort_type_kept", {"yaml_declares_jazzy_controllers", "yaml_controllers_on_my_robot"},
          ("    type: effort_controllers/JointGroupEffortController\n",
           "    type: effort_controllers/JointEffortController\n"), file=YAML),
    wrong("yaml_ros1_publish_rate_kept", {"yaml_controllers_on_my_robot"},
          ("    update_rate: 50  # [Hz]: ROS 1's publish_rate", "    publish_rate: 50  # [Hz]: ROS 1's publish_rate"),
          file=YAML),
    wrong("yaml_pid_commands_velocity", {"yaml_controllers_on_my_robot"},
          ("    command_interface: effort\n", "    command_interface: velocity\n"), file=YAML),
    wrong("yaml_pid_gains_not_per_joint", {"yaml_pid_gains"},
          ("    gains:\n      joint1:\n        p: 100.0\n        i: 0.01\n        d: 10.0\n",
           "    gains:\n      p: 100.0\n      i: 0.01\n      d: 10.0\n"), file=YAML),
    wrong("yaml_ros1_joint_names", {"yaml_controllers_on_my_robot"},
          ("    joints:\n      - joint3\n", "    joints:\n      - JointC\n"), file=YAML),
]

ALT_HARDWARE = '''"""Task 15, written another way (an alternative correct solution used by the grader's tests)."""

from rrbot_workshop import joint_limits as jl
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.hardware import SystemInterface
from rrbot_workshop.hardware.my_robot import MyRobotDevice
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType


class MyRobotHardware(SystemInterface):
    def __init__(self):
        super().__init__()
        self.device = None
        self.joints = []
        self.modes = []
        self.limiters = []

    def on_init(self, info):
        result = super().on_init(info)
        if result != CallbackReturn.SUCCESS:
            return result
        bad = []
        for joint in info.joints:
            kinds = {itf.name for itf in joint.command_interfaces}
            if len(joint.command_interfaces) != 1 or not kinds <= {"effort", "position"}:
                bad.append(f"joint {joint.name}: commands {sorted(kinds)}")
            if not {"position", "velocity"} <= {itf.name for itf in joint.state_interfaces}:
                bad.append(f"joint {joint.name}: no position or velocity state")
        if bad:
            for line in bad:
                self.logger.error(line)
            return CallbackReturn.ERROR
        if "joint_limits_file" not in info.hardware_parameters:
            self.logger.error("no joint_limits_file")
            return CallbackReturn.ERROR
        try:
            params = jl.load_joint_limits_yaml(info.hardware_parameters["joint_limits_file"])
        except ParameterError as exc:
            self.logger.error(str(exc))
            return CallbackReturn.ERROR
        for joint in info.joints:
            self.joints.append(joint.name)
            self.modes.append(joint.command_interfaces[0].name)
            limits = jl.get_joint_limits(joint.name, params, info.limits.get(joint.name))
            soft = jl.get_soft_joint_limits(joint.name, params, info.soft_limits.get(joint.name))
            if soft is None:
                limiter = jl.JointSaturationLimiter()
                limiter.init([joint.name], [limits])
            else:
                limiter = jl.JointSoftLimiter()
                limiter.init([joint.name], [limits], [soft])
            self.limiters.append(limiter)
        return CallbackReturn.SUCCESS

    def on_configure(self, previous_state):
        self.device = MyRobotDevice(self.modes)
        self.read(0.0, 0.0)
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state):
        self.device.enable()
        for joint, mode in zip(self.joints, self.modes):
            self.set_command(joint + "/" + mode, self.get_state(joint + "/position") if mode == "position" else 0.0)
        for limiter in self.limiters:
            limiter.reset_internals()
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state):
        self.device.disable()
        return CallbackReturn.SUCCESS

    def read(self, time, period):
        positions, velocities, efforts = self.device.read()
        for index, joint in enumerate(self.joints):
            self.set_state(joint + "/position", positions[index])
            self.set_state(joint + "/velocity", velocities[index])
            if joint + "/effort" in self.state_interface_names:
                self.set_state(joint + "/effort", efforts[index])
        return ReturnType.OK

    def write(self, time, period):
        out = [0.0] * len(self.joints)
        for index in range(len(self.joints)):
            joint, mode = self.joints[index], self.modes[index]
            actual = jl.JointControlInterfacesData(joint_name=joint)
            actual.position = self.get_state(joint + "/position")
            actual.velocity = self.get_state(joint + "/velocity")
            if mode == "effort":
                desired = jl.JointControlInterfacesData(joint_name=joint, effort=self.get_command(joint + "/effort"))
            else:
                desired = jl.JointControlInterfacesData(joint_name=joint, position=self.get_command(joint + "/position"))
            self.limiters[index].enforce(actual, desired, period)
            out[index] = desired.effort if mode == "effort" else desired.position
            self.set_command(joint + "/" + mode, out[index])  # the limited command, as ROS 1's enforceLimits left it
        self.device.write(out, period)
        return ReturnType.OK
'''

ALT_YAML = '''# MyRobot's controllers, written the other way round: the types under the controller manager.
controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    joint1_position_controller:
      type: pid_controller/PidController
    joint2_effort_controller:
      type: forward_command_controller/ForwardCommandController
    joint3_position_controller:
      type: forward_command_controller/ForwardCommandController

joint_state_broadcaster:
  ros__parameters: {update_rate: 50}

joint1_position_controller:
  ros__parameters:
    dof_names: [joint1]
    command_interface: effort
    reference_and_state_interfaces: [position, velocity]
    gains: {joint1: {p: 100, i: 0.01, d: 10}}

joint2_effort_controller:
  ros__parameters: {joints: [joint2], interface_name: effort}

joint3_position_controller:
  ros__parameters: {joints: [joint3], interface_name: position}
'''

#: The solution's controllers in flow style, each type in the controller's own section, the manager as /**/.
FLOW_YAML = """/**/controller_manager: {ros__parameters: {update_rate: 100}}
joint_state_broadcaster: {ros__parameters: {type: joint_state_broadcaster/JointStateBroadcaster, update_rate: 50}}
joint1_position_controller: {ros__parameters: {type: pid_controller/PidController, dof_names: [joint1],
  command_interface: effort, reference_and_state_interfaces: [position], gains: {joint1: {p: 100.0, i: 0.01, d: 10.0}}}}
joint2_effort_controller: {ros__parameters: {type: effort_controllers/JointGroupEffortController, joints: [joint2]}}
joint3_position_controller: {ros__parameters: {type: position_controllers/JointGroupPositionController,
  joints: [joint3]}}
"""

RIGHT = [
    Variant("yaml_flow_style_types_in_own_sections", {YAML: FLOW_YAML}),
    Variant("written_another_way", {PY: ALT_HARDWARE}),
    Variant("yaml_types_under_the_manager_and_forward_controllers", {YAML: ALT_YAML}),
    # the soft limiter chosen first, the limiters kept by joint name, the commands gathered in a dict
    Variant("limiters_by_joint_name", {PY: [
        ("        self.limiters: list[JointSaturationLimiter] = []  # one per joint (a JointSoftLimiter is one too)\n",
         "        self.limiters: list[JointSaturationLimiter] = []  # one per joint (a JointSoftLimiter is one too)\n"
         "        self.by_name: dict[str, JointSaturationLimiter] = {}\n"),
        ("                if soft is not None:\n                    self.limiters.append(JointSoftLimiter([joint], "
         "[hard], [soft]))\n                else:\n                    self.limiters.append(JointSaturationLimiter("
         "[joint], [hard]))\n",
         "                limiter = (JointSaturationLimiter([joint], [hard]) if soft is None\n"
         "                           else JointSoftLimiter([joint], [hard], [soft]))\n"
         "                self.by_name[joint] = limiter\n                self.limiters.append(limiter)\n"),
        ("        commands = []\n        for joint, mode, limiter in zip(self.joints, self.modes, self.limiters, "
         "strict=True):\n",
         "        sent = {}\n        for joint, mode in zip(self.joints, self.modes, strict=True):\n"
         "            limiter = self.by_name[joint]\n"),
        ("            commands.append(getattr(desired, mode))\n        self.device.write(commands, period)\n",
         "            sent[joint] = getattr(desired, mode)\n"
         "        self.device.write([sent[joint] for joint in self.joints], period)\n"),
    ]}),
    # ROS 1's habit: the yaml read with PyYAML and handed to the library as parameters
    Variant("yaml_read_by_hand", {PY: [
        ("            params = load_joint_limits_yaml(path)\n",
         "            import yaml\n            with open(path) as stream:\n                params = yaml.safe_load(stream)\n"
         "            if not isinstance(params, dict) or 'joint_limits' not in params:\n"
         "                raise ValueError(f'{path} has no joint_limits section')\n"),
        ("        except RRBotWorkshopError as exc:\n", "        except (RRBotWorkshopError, OSError, ValueError) as exc:\n"),
    ]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(15, WRONG + RIGHT, tmp_path_factory.mktemp("task15"))


def test_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 4


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict, variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(15), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(15))


def _formulas(text: str) -> set[str]:
    """The soft-limit formulas in a text (``k_position x (...)``, ``k_velocity x (...)``), written one way: ``x`` for
    the product, ``-`` for the minus, no backticks, single spaces."""
    plain = " ".join(text.replace("×", "x").replace("−", "-").replace("`", "").split())
    return set(re.findall(r"k_(?:position|velocity) x \([^)]*\)", plain))


def test_hint_formulas_are_notebook_15s() -> None:
    """Every soft-limit formula a task-15 hint writes is written the same way in notebook 15's text (the velocity
    allowed k_position x (distance to the bound), the effort cut to k_velocity x (allowed velocity - velocity))."""
    notebook = next((tracks.course_root() / "notebooks").glob("15_*.ipynb"))
    text = " ".join("".join(cell["source"]) for cell in json.loads(notebook.read_text())["cells"]
                    if cell["cell_type"] == "markdown")
    in_hints = set().union(*(_formulas(" ".join(spec.hints)) for spec in check_specs(15).values()))
    assert {"k_position x (distance to the bound)", "k_velocity x (allowed velocity - velocity)"} <= in_hints
    assert in_hints <= _formulas(text), f"hint formulas not in notebook 15: {sorted(in_hints - _formulas(text))}"


def test_exercise_as_handed_out_gets_a_clear_reason() -> None:
    """The untouched exercise scores 0, and its first causes' reasons say where to start: the learner's file and line,
    and the TODO still to write."""
    rubric = grade(15, track="exercises", record=False)
    assert rubric.score == 0, rubric.format()
    reasons = " ".join(check.detail for check in rubric.failed() if not check.blocked_by)
    for phrase in ("my_robot_hardware.py, line", "TODO(task 15.1)"):
        assert phrase in reasons, rubric.format()
