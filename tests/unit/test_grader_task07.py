"""The task-7 grader against wrong and alternative solutions of the RRBot driver, written as learners would.

Each wrong solution is the solution with one mistake (among them the original workshop's own bugs) and must lose
points, failing the checks named; each alternative is written differently and must get full marks.
"""

from __future__ import annotations

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

PY = "rrbot_hardware_interface.py"
YAML = "rrbot_controllers.yaml"


def wrong(name: str, fails: set[str], *changes: tuple[str, str], file: str = PY, names_file: str = "",
          only: bool = False, says: dict[str, str] | None = None) -> Variant:
    return Variant(name, {file: list(changes)}, fails=fails, names_file=names_file, only=only, says=says or {})


def one(name: str, fails: set[str], *changes: tuple[str, str], file: str = PY, says: dict[str, str] | None = None,
        names_file: str = "") -> Variant:
    """A slip of one rule: only the checks in ``fails`` lose points."""
    return wrong(name, fails, *changes, file=file, names_file=names_file, only=True, says=says)


#: The checks that the generated comparison with the library's driver builds on: a slip in one of them may show there.
SUMMARY = "same_as_the_library_driver"
#: Variants with several slips at once (each shows its own hints).
MANY_SLIPS = {"joint_names_hard_coded"}


WRONG = [
    # the original workshop's bugs
    wrong("mix_check_commented_out", {"mixed_modes_refused", "same_as_the_library_driver"}, ("        if len(modes) > 1:\n", "        if False:\n")),
    wrong("velocity_branch_copy_pasted", {"mode_follows_the_controllers"},
          ("            self.next_mode = ControlMode.VELOCITY\n", "            self.next_mode = ControlMode.POSITION\n")),
    one("effort_carries_the_acceleration", {"effort_reads_nan"},
          ('                self.set_state(f"{joint}/acceleration", a)\n',
           '                self.set_state(f"{joint}/acceleration", a)\n'
           '                self.set_state(f"{joint}/effort", a)\n')),
    wrong("sensor_gets_the_gpio_values", {"sensor_values"},
          ("            values = self.device.read_sensor_values(len(sensor.state_interfaces))\n",
           "            values = [float(b) for b in self.device.read_gpio()[0]] * 3\n")),
    wrong("a_colon_missing", {"init_accepts_rrbot", "configure_opens_the_device", "same_as_the_library_driver"},
          ("    def on_deactivate(self, previous_state: State) -> CallbackReturn:\n",
           "    def on_deactivate(self, previous_state: State) -> CallbackReturn\n"), names_file=PY),
    # 7.1
    wrong("no_description_check", {"init_refuses_joint_interfaces"},
          ('            if commands != ["position", "velocity"]:\n', "            if False:\n"),
          ('            if "position" not in states or "velocity" not in states:\n', "            if False:\n")),
    wrong("only_joint1_checked", {"init_refuses_joint_interfaces"},
          ("        for joint in info.joints:\n            commands", "        for joint in info.joints[:1]:\n            commands")),
    one("extra_command_interfaces_accepted", {"init_refuses_joint_interfaces"},
          ('            if commands != ["position", "velocity"]:\n',
           '            if "position" not in commands or "velocity" not in commands:\n')),
    one("second_sensor_and_gpio_accepted", {"init_refuses_a_second_sensor_or_gpio"},
          ("        if len(info.sensors) > 1 or len(info.gpios) > 1:\n", "        if False:\n")),
    one("second_gpio_accepted", {"init_refuses_a_second_sensor_or_gpio"},
          ("        if len(info.sensors) > 1 or len(info.gpios) > 1:\n", "        if len(info.sensors) > 1:\n")),
    one("printed_instead_of_logged", {"init_logs_why"},
          ('                self.logger.error("joint \'%s\' has command interfaces %s; the RRBot device takes exactly '
           'position "\n                                  "and velocity", joint.name, commands)\n',
           '                print("wrong command interfaces")\n'),
          ('                self.logger.error("joint \'%s\' has state interfaces %s; it needs position and velocity",\n'
           '                                  joint.name, states)\n', '                print("wrong state interfaces")\n')),
    wrong("joint_names_hard_coded", {"init_accepts_rrbot", "configure_opens_the_device"},
          ("        for joint in info.joints:\n            commands",
           "        if [j.name for j in info.joints] != ['joint1', 'joint2']:\n            return CallbackReturn.ERROR\n"
           "        for joint in info.joints:\n            commands"),
          ("        self.joints = [joint.name for joint in info.joints]\n", '        self.joints = ["joint1", "joint2"]\n')),
    # 7.2
    one("device_sized_for_two_joints", {"configure_opens_the_device"},
          ('RRBotDevice(len(self.joints), seed=', "RRBotDevice(2, seed=")),
    wrong("device_given_the_joint_list", {"configure_opens_the_device"},
          ('RRBotDevice(len(self.joints), seed=', "RRBotDevice(self.joints, seed="), names_file=PY),
    wrong("states_not_filled_at_configure", {"configure_opens_the_device"}, ("        self.read(0.0, 0.0)\n", "")),
    one("effort_left_at_its_initial_value", {"effort_reads_nan"},
          ('                self.set_state(f"{joint}/effort", math.nan)  # the device measures no torque\n',
           "                pass\n")),
    one("effort_set_to_zero", {"effort_reads_nan"},
          ('self.set_state(f"{joint}/effort", math.nan)', 'self.set_state(f"{joint}/effort", 0.0)')),
    one("seed_ignored", {"seed_parameter"}, ('seed=int(self.info.hardware_parameters.get("seed", "0"))', "seed=0")),
    one("seed_read_from_another_parameter", {"seed_parameter"},
          ('hardware_parameters.get("seed", "0")', 'hardware_parameters.get("random_seed", "0")')),
    one("movement_never_enabled", {"activate_without_a_jump"},
          ("        self.device.init()\n", "")),
    wrong("commands_zero_at_activation", {"activate_without_a_jump"},
          ('            self.set_command(f"{joint}/position", position)  # a controller taking over starts where the '
           'joint is\n', '            self.set_command(f"{joint}/position", 0.0)\n')),
    one("commands_at_the_initial_position", {"activate_without_a_jump"},
          ('            self.set_command(f"{joint}/position", position)  # a controller taking over starts where the '
           'joint is\n', '            self.set_command(f"{joint}/position", 0.1)\n')),
    one("velocity_commands_kept_at_activation", {"activate_without_a_jump"},
          ('            self.set_command(f"{joint}/velocity", velocity)\n', "")),
    one("deactivate_does_not_stop", {"deactivate_disables_movement"}, ("        self.device.stop()\n", "")),
    one("claims_not_forgotten_at_configure", {"claims_forgotten_at_configure"},
          ("        self.claimed = set()\n        for joint", "        for joint")),
    wrong("on_configure_raises", {"configure_opens_the_device", "joint_states_and_commands", "mode_follows_the_controllers"},
          ('        self.claimed = set()\n        for joint', '        self.claimed = set()\n        self.claimed += "x"\n'
           '        for joint'), names_file=PY),
    # 7.3
    one("period_hard_coded", {"joint_states_and_commands"},
          ("self.device.write_joint_commands(positions, velocities, period)",
           "self.device.write_joint_commands(positions, velocities, 0.01)")),
    one("joint2_state_from_joint1", {"joint_states_and_commands"},
          ('            self.set_state(f"{joint}/position", p)\n', '            self.set_state(f"{joint}/position", positions[0])\n')),
    one("commands_in_reverse_joint_order", {"joint_states_and_commands"},
          ('        positions = [self.get_command(f"{joint}/position") for joint in self.joints]\n',
           '        positions = [self.get_command(f"{joint}/position") for joint in reversed(self.joints)]\n')),
    wrong("acceleration_not_filled", {"acceleration_states", "same_as_the_library_driver"},
          ('                self.set_state(f"{joint}/acceleration", a)\n', "                pass\n")),
    one("sensor_names_hard_coded", {"sensor_values"},
          ('            for interface, value in zip(sensor.state_interfaces, values, strict=True):\n'
           '                self.set_state(f"{sensor.name}/{interface.name}", value)\n',
           '            for name, value in zip(("fx", "fy", "fz", "tx", "ty", "tz"), values):\n'
           '                self.set_state(f"{sensor.name}/{name}", value)\n')),
    wrong("sensor_values_in_reverse", {"sensor_values"},
          ("zip(sensor.state_interfaces, values, strict=True)", "zip(sensor.state_interfaces, values[::-1], strict=True)")),
    wrong("gpio_inputs_from_input_1", {"gpio_states", SUMMARY}, ("bits[int(number) - 1]", "bits[0]")),
    one("read_skipped_while_inactive", {"gpio_states"},
          ("        positions, velocities, accelerations = self.device.read_joint_states()\n",
           "        if not self.device.movement_enabled and period > 0.0:\n            return ReturnType.OK\n"
           "        positions, velocities, accelerations = self.device.read_joint_states()\n")),
    wrong("gpio_outputs_never_written", {"gpio_outputs"}, ("            self.device.write_gpios(outputs)\n", "            pass\n")),
    wrong("gpio_threshold_at_half", {"gpio_outputs"}, ("value > 0.5", "value >= 0.5")),
    wrong("gpio_nan_switches_on", {"gpio_outputs"},
          ("                if not math.isnan(value):\n                    outputs", "                if True:\n                    outputs"),
          ("= value > 0.5", "= bool(value)")),
    wrong("digital_out_states_echo_the_commands", {"gpio_states", SUMMARY},
          ('                self.set_state(f"{gpio.name}/{interface.name}", 1.0 if bits[int(number) - 1] else 0.0)\n',
           '                if kind == "digital_out":\n'
           '                    self.set_state(f"{gpio.name}/{interface.name}", self.get_command(f"{gpio.name}/{interface.name}"))\n'
           '                else:\n'
           '                    self.set_state(f"{gpio.name}/{interface.name}", 1.0 if bits[int(number) - 1] else 0.0)\n')),
    wrong("read_failure_swallowed", {"device_failure_reported"},
          ("        positions, velocities, accelerations = self.device.read_joint_states()\n",
           "        try:\n            positions, velocities, accelerations = self.device.read_joint_states()\n"
           "        except Exception:\n            return ReturnType.OK\n")),
    one("sensor_failure_swallowed", {"device_failure_reported"},
          ("            values = self.device.read_sensor_values(len(sensor.state_interfaces))\n",
           "            try:\n                values = self.device.read_sensor_values(len(sensor.state_interfaces))\n"
           "            except ConnectionError:\n                values = [math.nan] * len(sensor.state_interfaces)\n")),
    one("write_failure_swallowed", {"device_failure_reported"},
          ("        self.device.write_joint_commands(positions, velocities, period)\n",
           "        try:\n            self.device.write_joint_commands(positions, velocities, period)\n"
           "        except Exception as exc:\n            self.logger.warning('device: %s', exc)\n")),
    # 7.4
    wrong("only_the_started_interfaces_looked_at", {"mixed_modes_refused"},
          ("        modes = {name.rpartition(\"/\")[2] for name in self._after(start_interfaces, stop_interfaces)}\n",
           "        modes = {name.rpartition(\"/\")[2] for name in start_interfaces}\n")),
    wrong("stopped_interfaces_not_released", {"mode_follows_the_controllers"},
          ("        return (self.claimed - set(stop_interfaces)) | started\n", "        return self.claimed | started\n")),
    wrong("only_joint1_looked_at", {"mixed_modes_refused", "same_as_the_library_driver"},
          ('        started = {name for name in start_interfaces if name.rpartition("/")[0] in self.joints}\n'
           '        return (self.claimed - set(stop_interfaces)) | started\n',
           '        started = {name for name in start_interfaces if name.rpartition("/")[0] in self.joints}\n'
           '        return {n for n in (self.claimed - set(stop_interfaces)) | started if n.startswith(self.joints[0])}\n')),
    one("gpio_interfaces_counted_as_a_mode", {"mode_follows_the_controllers"},
          ('        started = {name for name in start_interfaces if name.rpartition("/")[0] in self.joints}\n',
           "        started = set(start_interfaces)\n")),
    one("rejection_without_a_reason", {"refusal_gives_a_reason"},
          ('            self.mode_switch_rejection = ("the RRBot device runs all joints in one mode; this switch would '
           'command "\n                                          "them in position and in velocity at once")\n', ""),
          ('            self.logger.error("%s", self.mode_switch_rejection)\n',
           '            self.logger.error("one mode for all joints")\n')),
    wrong("mode_set_in_prepare_claims_never_kept", {"mixed_modes_refused"},
          ("        self.claimed = self._after(start_interfaces, stop_interfaces)\n", "")),
    # 7.5
    one("yaml_commands_position_only", {"yaml_defines_the_incompatible_controller"},
          ("      - position\n      - velocity\n    state_interfaces:\n      - position\n      - velocity\n",
           "      - position\n    state_interfaces:\n      - position\n      - velocity\n"), file=YAML),
    one("yaml_forward_command_type", {"yaml_defines_the_incompatible_controller"},
          ("    incompatible_joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n",
           "    incompatible_joint_trajectory_controller:\n      type: forward_command_controller/ForwardCommandController\n"),
          file=YAML),
    one("yaml_joint1_only", {"yaml_defines_the_incompatible_controller"},
          ("incompatible_joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n",
           "incompatible_joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - joint1\n"), file=YAML),
    # --- return values exactly as stated; state reset when configured again; orders; outputs on, then NaN
    one("refusal_returns_failure", {"init_refusal_returns_error"},
        ('                                  "and velocity", joint.name, commands)\n                return CallbackReturn.ERROR\n',
         '                                  "and velocity", joint.name, commands)\n                return CallbackReturn.FAILURE\n'),
        ("                                  joint.name, states)\n                return CallbackReturn.ERROR\n",
         "                                  joint.name, states)\n                return CallbackReturn.FAILURE\n"),
        says={"init_refusal_returns_error": "FAILURE"}),
    one("refusal_raises_instead_of_returning_error", {"init_refusal_returns_error"},
        ('                self.logger.error("joint \'%s\' has command interfaces %s; the RRBot device takes exactly '
         'position "\n                                  "and velocity", joint.name, commands)\n'
         "                return CallbackReturn.ERROR\n",
         "                raise ValueError(f\"joint '{joint.name}' has command interfaces {commands}; the RRBot device "
         "takes position and velocity\")\n"),
        says={"init_refusal_returns_error": "raised ValueError"}),
    one("mode_refusal_raises", {"refusal_gives_a_reason"},
        ('            self.logger.error("%s", self.mode_switch_rejection)\n            return ReturnType.ERROR\n',
         "            raise RuntimeError(self.mode_switch_rejection)\n"),
        says={"refusal_gives_a_reason": "raised RuntimeError"}),
    wrong("nan_switches_an_output_off", {"gpio_outputs"},
          ("                if not math.isnan(value):\n                    outputs", "                if True:\n                    outputs"),
          says={"gpio_outputs": "keeps its value"}),
    wrong("outputs_never_switched_off", {"gpio_outputs"},
          ('                    outputs[int(interface.name.rpartition("_")[2]) - 1] = value > 0.5\n',
           '                    if value > 0.5:\n                        outputs[int(interface.name.rpartition("_")[2]) - 1] = True\n')),
    wrong("device_opened_in_on_init", {"configure_opens_the_device"},
          ("        self.joints = [joint.name for joint in info.joints]\n",
           "        self.joints = [joint.name for joint in info.joints]\n"
           '        self.device = RRBotDevice(len(self.joints), seed=int(info.hardware_parameters.get("seed", "0")))\n'),
          ('        self.device = RRBotDevice(len(self.joints), seed=int(self.info.hardware_parameters.get("seed", "0")))\n',
           ""), names_file=PY),
    one("joints_sorted_by_name", {"joint_states_and_commands"},
        ("        self.joints = [joint.name for joint in info.joints]\n",
         "        self.joints = sorted(joint.name for joint in info.joints)\n"),
        says={"joint_states_and_commands": "description's joint order"}),
    wrong("velocity_commands_never_written", {"joint_states_and_commands"},
          ("self.device.write_joint_commands(positions, velocities, period)",
           "self.device.write_joint_commands(positions, positions, period)"),
          says={"joint_states_and_commands": "velocity"}),
    one("claims_forgotten_only_at_cleanup", {"claims_forgotten_at_configure"},
        ("        self.claimed = set()\n        for joint", "        for joint"),
        ("        self.device = None\n        return CallbackReturn.SUCCESS\n\n    # ---",
         "        self.device = None\n        self.claimed = set()\n        return CallbackReturn.SUCCESS\n\n    # ---"),
        says={"claims_forgotten_at_configure": "after a failure"}),
    wrong("claims_forgotten_at_activation_instead", {SUMMARY},
          ("        self.claimed = set()\n        for joint", "        for joint"),
          ("        self.device.init()\n", "        self.device.init()\n        self.claimed = set()\n")),
]

ALT_DRIVER = '"""Task 7: the RRBot driver, written another way (an alternative correct solution used by the grader\'s tests)."""\n\nfrom __future__ import annotations\n\nimport math\n\nfrom rrbot_workshop.hardware import SystemInterface\nfrom rrbot_workshop.hardware.rrbot_device import ControlMode, RRBotDevice\nfrom rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType\n\nMODE_OF = {"position": ControlMode.POSITION, "velocity": ControlMode.VELOCITY}\n\n\nclass RRBotHardwareInterface(SystemInterface):\n    def __init__(self):\n        super().__init__()\n        self.device = None\n        self.joint_names = []\n        self.held = {}  # joint command interface -> True while a controller holds it\n        self.wanted_mode = None\n\n    def on_init(self, info):\n        result = super().on_init(info)\n        if result != CallbackReturn.SUCCESS:\n            return result\n        problems = []\n        for joint in info.joints:\n            command_names = set()\n            for itf in joint.command_interfaces:\n                command_names.add(itf.name)\n            if command_names != {"position", "velocity"} or len(joint.command_interfaces) != 2:\n                problems.append(f"{joint.name}: commands {sorted(command_names)}")\n            state_names = {itf.name for itf in joint.state_interfaces}\n            if not {"position", "velocity"}.issubset(state_names):\n                problems.append(f"{joint.name}: states {sorted(state_names)}")\n        if len(info.sensors) >= 2:\n            problems.append("more than one sensor")\n        if len(info.gpios) >= 2:\n            problems.append("more than one gpio")\n        if problems:\n            for problem in problems:\n                self.logger.error("cannot drive %s", problem)\n            return CallbackReturn.ERROR\n        for joint in info.joints:\n            self.joint_names.append(joint.name)\n        return CallbackReturn.SUCCESS\n\n    def on_configure(self, previous_state):\n        seed_text = self.info.hardware_parameters["seed"] if "seed" in self.info.hardware_parameters else "0"\n        self.device = RRBotDevice(number_of_dofs=len(self.joint_names), seed=int(seed_text))\n        self.held = {}\n        for name in self.state_interface_names:\n            if name.endswith("/effort"):\n                self.set_state(name, float("nan"))\n        if self.read(0.0, 0.0) != ReturnType.OK:\n            return CallbackReturn.ERROR\n        return CallbackReturn.SUCCESS\n\n    def on_activate(self, previous_state):\n        self.device.init()\n        for index, joint in enumerate(self.joint_names):\n            self.set_command(joint + "/position", self.get_state(joint + "/position"))\n            self.set_command(joint + "/velocity", self.get_state(joint + "/velocity"))\n        return CallbackReturn.SUCCESS\n\n    def on_deactivate(self, previous_state):\n        self.device.stop()\n        return CallbackReturn.SUCCESS\n\n    def on_cleanup(self, previous_state):\n        self.device = None\n        return CallbackReturn.SUCCESS\n\n    def read(self, time, period):\n        try:\n            positions, velocities, accelerations = self.device.read_joint_states()\n            for index, joint in enumerate(self.joint_names):\n                self.set_state(joint + "/position", positions[index])\n                self.set_state(joint + "/velocity", velocities[index])\n                if joint + "/acceleration" in self.state_interface_names:\n                    self.set_state(joint + "/acceleration", accelerations[index])\n            for sensor in self.info.sensors:\n                count = len(sensor.state_interfaces)\n                for index, itf in enumerate(sensor.state_interfaces):\n                    self.set_state(sensor.name + "/" + itf.name, self.device.read_sensor_values(count)[index])\n            for gpio in self.info.gpios:\n                for itf in gpio.state_interfaces:\n                    inputs, outputs = self.device.read_gpio()  # one call per interface: each reads the device anew\n                    number = int(itf.name.split("_")[-1])\n                    bit = inputs[number - 1] if itf.name.startswith("digital_in") else outputs[number - 1]\n                    self.set_state(gpio.name + "/" + itf.name, float(bit))\n        except Exception as exc:  # noqa: BLE001 - a failing device is reported as ERROR\n            self.logger.error("the device failed: %s", exc)\n            return ReturnType.ERROR\n        return ReturnType.OK\n\n    def write(self, time, period):\n        try:\n            positions, velocities = [], []\n            for joint in self.joint_names:\n                positions.append(self.get_command(joint + "/position"))\n                velocities.append(self.get_command(joint + "/velocity"))\n            self.device.write_joint_commands(positions, velocities, period)\n            for gpio in self.info.gpios:\n                outputs = self.device.read_gpio()[1]\n                for itf in gpio.command_interfaces:\n                    command = self.get_command(gpio.name + "/" + itf.name)\n                    if command == command:  # not NaN\n                        outputs[int(itf.name.split("_")[-1]) - 1] = bool(command > 0.5)\n                self.device.write_gpios(outputs)\n        except Exception as exc:  # noqa: BLE001\n            self.logger.error("the device failed: %s", exc)\n            return ReturnType.ERROR\n        return ReturnType.OK\n\n    def _held_after(self, start_interfaces, stop_interfaces):\n        after = dict(self.held)\n        for name in stop_interfaces:\n            after.pop(name, None)\n        for name in start_interfaces:\n            if name.split("/")[0] in self.joint_names:\n                after[name] = True\n        return after\n\n    def prepare_command_mode_switch(self, start_interfaces, stop_interfaces):\n        kinds = set()\n        for name in self._held_after(start_interfaces, stop_interfaces):\n            kinds.add(name.split("/")[-1])\n        if "position" in kinds and "velocity" in kinds:\n            self.mode_switch_rejection = "position and velocity at once: the RRBot device has one mode"\n            self.logger.error(self.mode_switch_rejection)\n            return ReturnType.ERROR\n        return ReturnType.OK\n\n    def perform_command_mode_switch(self, start_interfaces, stop_interfaces):\n        self.held = self._held_after(start_interfaces, stop_interfaces)\n        kinds = {name.split("/")[-1] for name in self.held}\n        if kinds:\n            self.device.set_control_mode(MODE_OF[kinds.pop()])\n        return ReturnType.OK\n'

ALT_YAML_BLOCK = (
    "incompatible_joint_trajectory_controller:\n"
    "  ros__parameters: {joints: [joint2, joint1], command_interfaces: [velocity, position],\n"
    "                    state_interfaces: [velocity, position]}\n"
)

#: The incompatible controller declared by a type in its own section (Jazzy's spawner reads it there).
OWN_SECTION_TYPE = [
    ("    incompatible_joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n", ""),
    ("incompatible_joint_trajectory_controller:\n  ros__parameters:\n",
     "incompatible_joint_trajectory_controller:\n  ros__parameters:\n"
     "    type: joint_trajectory_controller/JointTrajectoryController\n"),
]

RIGHT = [
    Variant("written_another_way", {PY: ALT_DRIVER}),
    Variant("yaml_type_in_its_own_section", {YAML: OWN_SECTION_TYPE}),
    # the mode chosen in perform_command_mode_switch, POSITION when nothing is claimed; the device read each time
    Variant("mode_chosen_in_perform", {PY: [
        ("        if modes == {\"position\"}:\n            self.next_mode = ControlMode.POSITION\n"
         "        elif modes == {\"velocity\"}:\n            self.next_mode = ControlMode.VELOCITY\n", ""),
        ("        self.device.set_control_mode(self.next_mode)\n",
         "        velocity = any(name.endswith(\"/velocity\") for name in self.claimed)\n"
         "        self.device.set_control_mode(ControlMode.VELOCITY if velocity else ControlMode.POSITION)\n"),
        ("            self.set_command(f\"{joint}/velocity\", velocity)\n",
         "            self.set_command(f\"{joint}/velocity\", 0.0)  # the device is at rest when enabled\n"),
    ]}),
    # commands from the state interfaces, effort set in read, a loop instead of comprehensions, ERROR on a failure
    Variant("states_first_then_commands", {PY: [
        ("        self.device.init()\n        positions, velocities, _ = self.device.read_joint_states()\n"
         "        for joint, position, velocity in zip(self.joints, positions, velocities, strict=True):\n"
         "            self.set_command(f\"{joint}/position\", position)  # a controller taking over starts where the "
         "joint is\n            self.set_command(f\"{joint}/velocity\", velocity)\n",
         "        self.device.init()\n        self.read(0.0, 0.0)\n        for joint in self.joints:\n"
         "            for kind in (\"position\", \"velocity\"):\n"
         "                self.set_command(f\"{joint}/{kind}\", self.get_state(f\"{joint}/{kind}\"))\n"),
        ("        positions = [self.get_command(f\"{joint}/position\") for joint in self.joints]\n"
         "        velocities = [self.get_command(f\"{joint}/velocity\") for joint in self.joints]\n",
         "        positions, velocities = [], []\n        for joint in self.joints:\n"
         "            positions.append(self.get_command(f\"{joint}/position\"))\n"
         "            velocities.append(self.get_command(f\"{joint}/velocity\"))\n"),
        ("        positions, velocities, accelerations = self.device.read_joint_states()\n",
         "        try:\n            positions, velocities, accelerations = self.device.read_joint_states()\n"
         "        except ConnectionError as exc:\n            self.logger.error(\"device: %s\", exc)\n"
         "            return ReturnType.ERROR\n"),
    ]}),
    Variant("yaml_in_flow_style", {YAML: [
        ("incompatible_joint_trajectory_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n"
         "    command_interfaces:\n      - position\n      - velocity\n    state_interfaces:\n      - position\n"
         "      - velocity\n", ALT_YAML_BLOCK),
    ]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(7, WRONG + RIGHT, tmp_path_factory.mktemp("task07"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


@pytest.mark.parametrize("variant", [v for v in WRONG if v.name not in MANY_SLIPS], ids=str)
def test_one_slip_shows_hints_for_one_check(rubrics: dict, variant: Variant) -> None:
    assert_one_cause(rubrics[variant.name], check_specs(7), variant.name)


def test_a_failure_the_grader_provokes_is_not_the_reason(rubrics: dict) -> None:
    """The claims check unplugs the device in read; the reason names the claims in on_configure, not that read."""
    check = next(c for c in rubrics["claims_forgotten_only_at_cleanup"].checks if c.name == "claims_forgotten_at_configure")
    assert not check.passed and "in read" not in check.detail and "unplugged" not in check.detail, check.detail


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(7))


def test_there_are_enough_variants() -> None:
    assert len(WRONG) >= 12 and len(RIGHT) >= 3
