"""The task-8 grader against wrong solutions written as learners write them, and against right ones written otherwise.

Each wrong variant is a copy of ``solutions/task08_write_a_controller/`` with one mistake; it must lose points, fail
the checks named in ``fails``, and every failed check's reason must be whole and readable. Each alternative is
written differently from the solution (its own structure, names, YAML form) and must get full marks.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants

from rrbot_workshop.course import tracks

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

PY = "displacement_controller.py"
YAML = "rrbot_controllers.yaml"
ALTERNATIVES = Path(__file__).parent / "task08_alternatives"
SCENARIOS = "matches_the_reference"

WRONG = [
    Variant("command_is_the_displacement_alone_as_the_original_tests_expected",
            {PY: [("set_value(current + factor * displacement)", "set_value(factor * displacement)")]},
            fails={"command_is_state_plus_displacement", SCENARIOS, "moves_the_rrbot"}),
    Variant("displacement_applied_every_cycle",
            {PY: [("            self.displacements[i] = math.nan  # used once\n", "")]},
            fails={"displacement_used_once", SCENARIOS}),
    Variant("no_nan_on_deactivate",
            {PY: [("            interface.set_value(math.nan)  # no stale command is left for the next controller\n",
                   "            pass\n")]},
            fails={"nan_commands_on_deactivate", SCENARIOS}),
    Variant("nan_on_the_first_command_interface_only",
            {PY: [("        for interface in self.command_interfaces:\n"
                   "            interface.set_value(math.nan)  # no stale command is left for the next controller\n",
                   "        self.command_interfaces[0].set_value(math.nan)\n")]},
            fails={"nan_commands_on_deactivate", SCENARIOS}),
    Variant("a_message_for_some_of_the_joints_accepted",
            {PY: [("        if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints):\n",
                   "        if False:\n"),
                  ("        if sorted(msg.joint_names) != sorted(self.joints):\n", "        if False:\n"),
                  ("self.displacements = [float(by_name[joint]) for joint in self.joints]",
                   "self.displacements = [float(by_name.get(joint, math.nan)) for joint in self.joints]")]},
            fails={"wrong_joint_count_refused", SCENARIOS}),
    Variant("a_joint_named_twice_accepted",
            {PY: [("        if sorted(msg.joint_names) != sorted(self.joints):\n",
                   "        if any(name not in self.joints for name in msg.joint_names):\n"),
                  ("        by_name = dict(zip(msg.joint_names, msg.displacements, strict=True))\n"
                   "        self.displacements = [float(by_name[joint]) for joint in self.joints]\n",
                   "        pending = [math.nan] * len(self.joints)\n"
                   "        for name, displacement in zip(msg.joint_names, msg.displacements):\n"
                   "            pending[self.joints.index(name)] = float(displacement)\n"
                   "        self.displacements = pending\n")]},
            fails={"unknown_or_repeated_joint_refused", SCENARIOS}),
    Variant("unknown_joint_raises_in_the_callback",
            {PY: [("        if sorted(msg.joint_names) != sorted(self.joints):\n", "        if False:\n")]},
            fails={"unknown_or_repeated_joint_refused"}, names_file=PY),
    Variant("matched_by_position_instead_of_name",
            {PY: [("self.displacements = [float(by_name[joint]) for joint in self.joints]",
                   "self.displacements = [float(d) for d in msg.displacements]")]},
            fails={"displacements_matched_by_name", "moves_the_rrbot", SCENARIOS}),
    Variant("refused_message_clears_the_pending_one",
            {PY: [("    def _on_reference(self, msg: JointJog) -> None:\n",
                   "    def _on_reference(self, msg: JointJog) -> None:\n"
                   "        self.displacements = [math.nan] * len(self.joints)\n")]},
            fails={"refused_message_keeps_the_pending_one", SCENARIOS}),
    Variant("refusal_printed_not_logged",
            {PY: [('            self.logger.error("rejected a JointJog with %d', '            print("rejected a JointJog with %d'),
                  ('            self.logger.error("rejected a JointJog for joints', '            print("rejected a JointJog for joints')]},
            fails={"refusal_logged"}),
    Variant("messages_before_an_update_added_up",
            {PY: [("self.displacements = [float(by_name[joint]) for joint in self.joints]",
                   "self.displacements = [(0.0 if math.isnan(old) else old) + float(by_name[joint])\n"
                   "                              for old, joint in zip(self.displacements, self.joints)]")]},
            fails={"newer_message_replaces_pending", SCENARIOS}),
    Variant("blup_rule_missing_from_the_schema",
            {PY: [('      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n', "")]},
            fails={"blup_prefix_refused_at_load"}),
    Variant("validator_replaces_one_of",
            {PY: [('      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n', "")]},
            fails={"blup_prefix_refused_at_load"}),
    Variant("validator_after_one_of",
            {PY: [('      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n'
                   '      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n',
                   '      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n'
                   '      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n')]},
            fails={"blup_prefix_refused_at_load"}),
    Variant("validator_with_a_hard_coded_prefix",
            {PY: [("    if value.startswith(prefix):", '    if value.startswith("blup_"):')]},
            fails={"validator_function"}),
    Variant("validator_looks_anywhere_in_the_name",
            {PY: [("    if value.startswith(prefix):", "    if prefix in value:")]},
            fails={"validator_function"}),
    Variant("slow_mode_ignored",
            {PY: [("factor = 0.5 if self.slow_mode else 1.0", "factor = 1.0")]},
            fails={"slow_mode", SCENARIOS}),
    Variant("slow_mode_service_toggles",
            {PY: [("        self.slow_mode = bool(request.data)\n", "        self.slow_mode = not self.slow_mode\n")]},
            fails={"slow_mode", SCENARIOS}),
    Variant("slow_mode_applied_when_the_message_arrives",
            {PY: [("self.displacements = [float(by_name[joint]) for joint in self.joints]",
                   "self.displacements = [float(by_name[joint]) * (0.5 if self.slow_mode else 1.0) "
                   "for joint in self.joints]"),
                  ("factor = 0.5 if self.slow_mode else 1.0", "factor = 1.0")]},
            fails={"slow_mode", SCENARIOS}),
    Variant("messages_before_activation_applied",
            {PY: [("        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation "
                   "is applied\n", "")]},
            fails={"activation_forgets_earlier_messages", SCENARIOS}),
    Variant("state_read_when_the_message_arrives",
            {PY: [("        self.displacements = [float(by_name[joint]) for joint in self.joints]\n",
                   "        self.displacements = [float(by_name[joint]) for joint in self.joints]\n"
                   "        self.origin = [loan.get_value() for loan in self.state_interfaces]\n"),
                  ("            current = self.state_interfaces[i].get_value()\n", "            current = self.origin[i]\n")]},
            fails={"command_is_state_plus_displacement", SCENARIOS}),
    Variant("state_published_only_when_something_moved",
            {PY: [("        factor = 0.5 if self.slow_mode else 1.0\n",
                   "        factor = 0.5 if self.slow_mode else 1.0\n        moved = False\n"),
                  ("            self.displacements[i] = math.nan  # used once\n",
                   "            self.displacements[i] = math.nan  # used once\n            moved = True\n"),
                  ("        if self._state_publisher is not None:\n", "        if self._state_publisher is not None and moved:\n")]},
            fails={"state_published", SCENARIOS}),
    Variant("state_error_sign_reversed",
            {PY: [("error=set_point - process_value", "error=process_value - set_point")]},
            fails={"state_published", SCENARIOS}),
    Variant("state_frame_id_hard_coded",
            {PY: [("frame_id=self.joints[0]", 'frame_id="joint1"')]},
            fails={"state_published", SCENARIOS}),
    Variant("state_time_step_hard_coded_at_100_hz",
            {PY: [("time_step=period", "time_step=0.01")]},
            fails={"state_time_step_is_the_period", SCENARIOS, "moves_the_rrbot"}),
    Variant("state_joints_ignored",
            {PY: [("for joint in self.state_joints])", "for joint in self.joints])")]},
            fails={"configure_and_claimed_interfaces"}),
    Variant("state_joints_size_checked_one_way",
            {PY: [("        if len(self.state_joints) != len(self.joints):\n",
                   "        if len(self.state_joints) < len(self.joints):\n")]},
            fails={"state_joints_of_another_size_fail_configure"}),
    Variant("rrbot_joints_hard_coded",
            {PY: [('[f"{joint}/{self.interface_name}" for joint in self.joints])',
                   '["joint1/position", "joint2/position"])')]},
            fails={"configure_and_claimed_interfaces", SCENARIOS}),
    Variant("topics_spelled_with_the_notebooks_controller_name",
            {PY: [('"~/reference"', '"/displacement_controller/reference"'),
                  ('"~/set_slow_control_mode"', '"/displacement_controller/set_slow_control_mode"'),
                  ('"~/state"', '"/displacement_controller/state"')]},
            fails={"topics_and_service", SCENARIOS}),
    Variant("update_returns_nothing",
            {PY: [("        return ReturnType.OK\n", "")]},
            fails={"command_is_state_plus_displacement", "moves_the_rrbot"}),
    Variant("yaml_with_a_made_up_plugin_name",
            {YAML: [("type: displacement_controller/DisplacementController",
                     "type: rrbot_workshop/DisplacementController")]},
            fails={"yaml_declares_the_controller", "moves_the_rrbot"}),
    Variant("yaml_with_one_joint",
            {YAML: [("displacement_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n",
                     "displacement_controller:\n  ros__parameters:\n    joints:\n      - joint1\n")]},
            fails={"yaml_declares_the_controller", "moves_the_rrbot"}),
]

RIGHT = [
    Variant("pending_by_name_with_loops_and_a_gain", {PY: (ALTERNATIVES / "pending_by_name.py").read_text()}),
    Variant("counter_checks_and_precomputed_names_flow_yaml",
            {PY: (ALTERNATIVES / "counter_checks.py").read_text(),
             YAML: (ALTERNATIVES / "rrbot_controllers_flow.yaml").read_text()}),
    Variant("reference_like_checks_and_controlko_plugin_name", {
        PY: [("    if value.startswith(prefix):\n        return f\"'{value}' must not start with '{prefix}'\"\n"
              "    return None\n",
              "    return None if not value.startswith(prefix) else \"starts with \" + prefix\n"),
             ("        if sorted(msg.joint_names) != sorted(self.joints):\n",
              "        if len(set(msg.joint_names)) != len(msg.joint_names) or set(msg.joint_names) != set(self.joints):\n"),
             ("            self.logger.error(\"rejected a JointJog for joints %s",
              "            self.logger.warning(\"rejected a JointJog for joints %s"),
             ("        for interface in self.command_interfaces:\n"
              "            interface.set_value(math.nan)  # no stale command is left for the next controller\n",
              "        for i in range(len(self.command_interfaces)):\n"
              "            self.command_interfaces[i].set_value(float(\"nan\"))\n")],
        YAML: [("type: displacement_controller/DisplacementController", "type: controlko_controllers/DisplacementController"),
               ("displacement_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n"
                "    interface_name: position\n",
                "displacement_controller:\n  ros__parameters:\n    interface_name: \"position\"\n"
                "    joints: [\"joint1\", \"joint2\"]\n")],
    }),
    Variant("state_message_built_before_the_publisher_check", {
        PY: [("        if self._state_publisher is not None:\n"
              "            set_point = self.command_interfaces[0].get_value()\n"
              "            process_value = self.state_interfaces[0].get_value()\n"
              "            self._state_publisher.publish(JointControllerState(\n"
              "                header=Header(stamp=time, frame_id=self.joints[0]), set_point=set_point,\n"
              "                process_value=process_value, error=set_point - process_value, time_step=period, "
              "command=set_point))\n",
              "        msg = JointControllerState()\n"
              "        msg.header.stamp = time\n"
              "        msg.header.frame_id = self.joints[0]\n"
              "        msg.command = msg.set_point = self.command_interfaces[0].get_value()\n"
              "        msg.process_value = self.state_interfaces[0].get_value()\n"
              "        msg.error = msg.set_point - msg.process_value\n"
              "        msg.time_step = period\n"
              "        self._state_publisher.publish(msg)\n")],
    }),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(8, WRONG + RIGHT, tmp_path_factory.mktemp("task08"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_enough_variants() -> None:
    """The issue asks for at least 12 wrong and 3 right solutions per task."""
    assert len(WRONG) >= 12 and len(RIGHT) >= 3
