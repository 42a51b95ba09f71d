"""The task-8 grader against wrong solutions written as learners write them, and against right ones written otherwise.

Each wrong variant is a copy of ``solutions/task08_write_a_controller/`` with one mistake; it must lose points, fail
the checks named in ``fails``, and every failed check's reason must be whole and readable. Each alternative is
written differently from the solution (its own structure, names, YAML form) and must get full marks.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from grader_causes import assert_one_cause, check_specs, unknown_after
from grader_variants import Variant, assert_full_marks, assert_loses_points, grade_variants, reason_problems

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")

PY = "displacement_controller.py"
YAML = "rrbot_controllers.yaml"
ALTERNATIVES = Path(__file__).parent / "task08_alternatives"
SCENARIOS = "matches_the_reference"

ONCE = "            self.displacements[i] = math.nan  # used once\n"
NAN = "            interface.set_value(math.nan)  # no stale command is left for the next controller\n"
BY_NAME = "self.displacements = [float(by_name[joint]) for joint in self.joints]"
COUNT = "        if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints):\n"
NAMES = "        if sorted(msg.joint_names) != sorted(self.joints):\n"
SIZE = ("            self.logger.error(\"'state_joints' has %d joints and 'joints' %d: they must have the same size\",\n"
        "                              len(self.state_joints), len(self.joints))\n"
        "            return CallbackReturn.FAILURE\n")
PUBLISH = ("        if self._state_publisher is not None:\n"
           "            set_point = self.command_interfaces[0].get_value()\n"
           "            process_value = self.state_interfaces[0].get_value()\n"
           "            self._state_publisher.publish(JointControllerState(\n"
           "                header=Header(stamp=time, frame_id=self.joints[0]), set_point=set_point,\n"
           "                process_value=process_value, error=set_point - process_value, time_step=period, "
           "command=set_point))\n")
YAML_ENTRY = ("displacement_controller:\n  ros__parameters:\n    joints:\n      - joint1\n      - joint2\n"
              "    interface_name: position\n")
DECLARED = "    displacement_controller:\n      type: displacement_controller/DisplacementController\n"

WRONG = [
    # ------------------------------------------------------------------ the arithmetic of update
    Variant("command_is_the_displacement_alone_as_the_original_tests_expected",
            {PY: [("set_value(current + factor * displacement)", "set_value(factor * displacement)")]},
            fails={"command_is_state_plus_displacement", SCENARIOS, "moves_the_rrbot"}, only=True,
            says={"command_is_state_plus_displacement": "23.24"}),
    Variant("displacement_applied_every_cycle", {PY: [(ONCE, "")]},
            fails={"displacement_used_once", SCENARIOS, "moves_the_rrbot"}, only=True),
    Variant("every_joint_written_every_cycle_from_its_state",
            {PY: [("            if math.isnan(displacement):\n                continue\n"
                   "            current = self.state_interfaces[i].get_value()\n"
                   "            self.command_interfaces[i].set_value(current + factor * displacement)\n",
                   "            current = self.state_interfaces[i].get_value()\n"
                   "            step = 0.0 if math.isnan(displacement) else factor * displacement\n"
                   "            self.command_interfaces[i].set_value(current + step)\n")]},
            fails={"displacement_used_once", SCENARIOS}, only=True, says={"displacement_used_once": "one more update"}),
    Variant("state_read_when_the_message_arrives",
            {PY: [(f"        {BY_NAME}\n",
                   f"        {BY_NAME}\n        self.origin = [loan.get_value() for loan in self.state_interfaces]\n"),
                  ("            current = self.state_interfaces[i].get_value()\n", "            current = self.origin[i]\n")]},
            fails={"command_is_state_plus_displacement", SCENARIOS}, only=True, says={"command_is_state_plus_displacement":
                                                                                       "move to"}),
    Variant("update_returns_nothing", {PY: [("        return ReturnType.OK\n", "")]},
            fails={"update_returns_ok", "moves_the_rrbot"}, only=True, says={"update_returns_ok": "ReturnType.OK"}),
    # ------------------------------------------------------------------ deactivation, activation
    Variant("no_nan_on_deactivate", {PY: [(NAN, "            pass\n")]},
            fails={"nan_commands_on_deactivate", SCENARIOS}, only=True, says={"nan_commands_on_deactivate": "NaN"}),
    Variant("nan_on_the_first_command_interface_only",
            {PY: [("        for interface in self.command_interfaces:\n" + NAN,
                   "        self.command_interfaces[0].set_value(math.nan)\n")]},
            fails={"nan_commands_on_deactivate", SCENARIOS}, only=True),
    Variant("zero_instead_of_nan_on_deactivate", {PY: [(NAN, "            interface.set_value(0.0)\n")]},
            fails={"nan_commands_on_deactivate", SCENARIOS}, only=True),
    Variant("messages_before_activation_applied",
            {PY: [("        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation "
                   "is applied\n", "")]},
            fails={"activation_forgets_earlier_messages", SCENARIOS}, only=True),
    Variant("pending_cleared_on_deactivate_but_not_on_activate",
            {PY: [("        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation "
                   "is applied\n", ""),
                  ("        for interface in self.command_interfaces:\n",
                   "        self.displacements = [math.nan] * len(self.joints)\n"
                   "        for interface in self.command_interfaces:\n")]},
            fails={"activation_forgets_earlier_messages", SCENARIOS}, only=True,
            says={"activation_forgets_earlier_messages": "before the first activation"}),
    # ------------------------------------------------------------------ messages
    Variant("a_message_for_some_of_the_joints_accepted",
            {PY: [(COUNT, "        if False:\n"), (NAMES, "        if False:\n"),
                  (BY_NAME, "self.displacements = [float(by_name.get(joint, math.nan)) for joint in self.joints]")]},
            fails={"wrong_joint_count_refused", "unknown_or_repeated_joint_refused", SCENARIOS}),
    Variant("count_compared_with_the_names_only",
            {PY: [(COUNT, "        if len(msg.joint_names) != len(self.joints):\n"),
                  ("        by_name = dict(zip(msg.joint_names, msg.displacements, strict=True))\n",
                   "        by_name = dict(zip(msg.joint_names, msg.displacements))\n"),
                  (BY_NAME, "self.displacements = [float(by_name.get(joint, math.nan)) for joint in self.joints]")]},
            fails={"wrong_joint_count_refused", SCENARIOS}, only=True, says={"wrong_joint_count_refused": "[1.0]"}),
    Variant("a_joint_named_twice_accepted",
            {PY: [(NAMES, "        if any(name not in self.joints for name in msg.joint_names):\n"),
                  ("        by_name = dict(zip(msg.joint_names, msg.displacements, strict=True))\n"
                   f"        {BY_NAME}\n",
                   "        pending = [math.nan] * len(self.joints)\n"
                   "        for name, displacement in zip(msg.joint_names, msg.displacements):\n"
                   "            pending[self.joints.index(name)] = float(displacement)\n"
                   "        self.displacements = pending\n")]},
            fails={"unknown_or_repeated_joint_refused", SCENARIOS}, only=True,
            says={"unknown_or_repeated_joint_refused": "joint1"}),
    Variant("names_compared_as_sets", {PY: [(NAMES, "        if set(msg.joint_names) != set(self.joints):\n"),
                                             (COUNT, "        if len(msg.displacements) != len(msg.joint_names):\n")]},
            fails={"wrong_joint_count_refused", SCENARIOS}, only=True,
            says={"wrong_joint_count_refused": "['joint1', 'joint2', 'joint2']"}),
    Variant("unknown_joint_raises_in_the_callback", {PY: [(NAMES, "        if False:\n")]},
            fails={"unknown_or_repeated_joint_refused", SCENARIOS}, names_file=PY, only=True,
            says={"unknown_or_repeated_joint_refused": "KeyError"}),
    Variant("matched_by_position_instead_of_name",
            {PY: [(BY_NAME, "self.displacements = [float(d) for d in msg.displacements]")]},
            fails={"displacements_matched_by_name", "moves_the_rrbot", SCENARIOS}, only=True),
    Variant("refused_message_clears_the_pending_one",
            {PY: [("    def _on_reference(self, msg: JointJog) -> None:\n",
                   "    def _on_reference(self, msg: JointJog) -> None:\n"
                   "        self.displacements = [math.nan] * len(self.joints)\n")]},
            fails={"refused_message_keeps_the_pending_one", SCENARIOS}, only=True),
    Variant("refusal_printed_not_logged",
            {PY: [('            self.logger.error("rejected a JointJog with %d', '            print("rejected a JointJog with %d'),
                  ('            self.logger.error("rejected a JointJog for joints', '            print("rejected a JointJog for joints')]},
            fails={"refusal_logged"}, only=True, says={"refusal_logged": "log"}),
    Variant("refusal_logged_at_debug_level",
            {PY: [('            self.logger.error("rejected a JointJog with %d', '            self.logger.debug("rejected a JointJog with %d'),
                  ('            self.logger.error("rejected a JointJog for joints', '            self.logger.debug("rejected a JointJog for joints')]},
            fails={"refusal_logged"}, only=True),
    Variant("messages_before_an_update_added_up",
            {PY: [(BY_NAME, "self.displacements = [(0.0 if math.isnan(old) else old) + float(by_name[joint])\n"
                            "                              for old, joint in zip(self.displacements, self.joints)]")]},
            fails={"newer_message_replaces_pending", SCENARIOS}, only=True),
    # ------------------------------------------------------------------ slow mode
    Variant("slow_mode_ignored", {PY: [("factor = 0.5 if self.slow_mode else 1.0", "factor = 1.0")]},
            fails={"slow_mode", SCENARIOS}, only=True, says={"slow_mode": "halved"}),
    Variant("slow_mode_service_toggles",
            {PY: [("        self.slow_mode = bool(request.data)\n", "        self.slow_mode = not self.slow_mode\n")]},
            fails={"slow_mode", SCENARIOS}, only=True),
    Variant("slow_mode_applied_when_the_message_arrives",
            {PY: [(BY_NAME, "self.displacements = [float(by_name[joint]) * (0.5 if self.slow_mode else 1.0) "
                            "for joint in self.joints]"),
                  ("factor = 0.5 if self.slow_mode else 1.0", "factor = 1.0")]},
            fails={"slow_mode", SCENARIOS}, only=True, says={"slow_mode": "mode at the update"}),
    Variant("slow_mode_service_answers_nothing",
            {PY: [('        return SetBoolResponse(success=True, message="slow mode" if self.slow_mode else "fast mode")\n',
                   "")]},
            fails={"slow_mode"}, only=True, says={"slow_mode": "success=True"}),
    Variant("slow_mode_reset_only_in_init", {PY: [("        self.slow_mode = False\n        node = self.get_node()\n",
                                                   "        node = self.get_node()\n")]},
            fails={"configure_again_after_cleanup"}, only=True, says={"configure_again_after_cleanup": "fast mode"}),
    # ------------------------------------------------------------------ ~/state
    Variant("state_published_only_when_something_moved",
            {PY: [("        factor = 0.5 if self.slow_mode else 1.0\n",
                   "        factor = 0.5 if self.slow_mode else 1.0\n        moved = False\n"),
                  (ONCE, ONCE + "            moved = True\n"),
                  ("        if self._state_publisher is not None:\n", "        if self._state_publisher is not None and moved:\n")]},
            fails={"state_published", SCENARIOS}, only=True, says={"state_published": "nothing was published"}),
    Variant("state_error_sign_reversed", {PY: [("error=set_point - process_value", "error=process_value - set_point")]},
            fails={"state_published", SCENARIOS}, only=True, says={"state_published": "error"}),
    Variant("state_frame_id_hard_coded", {PY: [("frame_id=self.joints[0]", 'frame_id="joint1"')]},
            fails={"state_published", SCENARIOS}, only=True, says={"state_published": "frame_id"}),
    Variant("state_stamp_is_the_period", {PY: [("stamp=time,", "stamp=period,")]},
            fails={"state_published", SCENARIOS}, only=True, says={"state_published": "stamp"}),
    Variant("state_published_before_the_command_is_written",
            {PY: [(PUBLISH, ""),
                  ("        factor = 0.5 if self.slow_mode else 1.0\n", PUBLISH + "        factor = 0.5 if self.slow_mode else 1.0\n")]},
            fails={"state_published", SCENARIOS}, only=True, says={"state_published": "set_point"}),
    Variant("state_time_step_hard_coded_at_100_hz", {PY: [("time_step=period", "time_step=0.01")]},
            fails={"state_time_step_is_the_period", SCENARIOS, "moves_the_rrbot"}, only=True,
            says={"state_time_step_is_the_period": "time_step"}),
    Variant("state_time_step_from_the_update_rate_parameter",
            {PY: [("time_step=period", "time_step=1.0 / (self.get_node().get_parameter('update_rate', 0) or 1.0 / period)")]},
            fails={"state_time_step_is_the_period"}, only=True, says={"state_time_step_is_the_period": "0.008 s"}),
    # ------------------------------------------------------------------ configure
    Variant("state_joints_ignored", {PY: [("for joint in self.state_joints])", "for joint in self.joints])")]},
            fails={"configure_and_claimed_interfaces", "command_is_state_plus_displacement", "state_published",
                   SCENARIOS}, only=True, says={"configure_and_claimed_interfaces": "sensor"}),
    Variant("state_joints_size_checked_one_way",
            {PY: [("        if len(self.state_joints) != len(self.joints):\n",
                   "        if len(self.state_joints) < len(self.joints):\n")]},
            fails={"state_joints_of_another_size_fail_configure"}, only=True),
    Variant("size_mismatch_returns_error", {PY: [(SIZE, SIZE.replace("FAILURE", "ERROR"))]},
            fails={"size_mismatch_returns_failure_and_logs"}, only=True,
            says={"size_mismatch_returns_failure_and_logs": "CallbackReturn.FAILURE"}),
    Variant("size_mismatch_raises",
            {PY: [(SIZE, "            raise ValueError(\"state_joints and joints must have the same size\")\n")]},
            fails={"size_mismatch_returns_failure_and_logs"}, only=True, names_file=PY,
            says={"size_mismatch_returns_failure_and_logs": "raised"}),
    Variant("size_mismatch_refused_without_a_word",
            {PY: [(SIZE, "            return CallbackReturn.FAILURE\n")]},
            fails={"size_mismatch_returns_failure_and_logs"}, only=True,
            says={"size_mismatch_returns_failure_and_logs": "log"}),
    Variant("joints_added_to_at_each_configure",
            {PY: [("        self.joints = list(params.joints)\n", "        self.joints += list(params.joints)\n")]},
            fails={"configure_again_after_cleanup"}, only=True,
            says={"configure_again_after_cleanup": "command_interface_configuration"}),
    Variant("rrbot_joints_hard_coded",
            {PY: [('[f"{joint}/{self.interface_name}" for joint in self.joints])',
                   '["joint1/position", "joint2/position"])')]},
            fails={"configure_and_claimed_interfaces", SCENARIOS}),
    Variant("topics_spelled_with_the_notebooks_controller_name",
            {PY: [('"~/reference"', '"/displacement_controller/reference"'),
                  ('"~/set_slow_control_mode"', '"/displacement_controller/set_slow_control_mode"'),
                  ('"~/state"', '"/displacement_controller/state"')]},
            fails={"topics_and_service", SCENARIOS}, says={"topics_and_service": "~/reference"}),
    # ------------------------------------------------------------------ 8.1 the validator and the schema
    Variant("blup_rule_missing_from_the_schema",
            {PY: [('      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n', "")]},
            fails={"blup_prefix_refused_at_load"}, only=True, says={"blup_prefix_refused_at_load": "blup_position"}),
    Variant("validator_replaces_one_of",
            {PY: [('      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n', "")]},
            fails={"blup_prefix_refused_at_load"}, only=True, says={"blup_prefix_refused_at_load": "torque"}),
    Variant("validator_after_one_of",
            {PY: [('      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n'
                   '      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n',
                   '      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n'
                   '      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n')]},
            fails={"blup_prefix_refused_at_load"}, only=True),
    Variant("validator_with_a_hard_coded_prefix",
            {PY: [("    if value.startswith(prefix):", '    if value.startswith("blup_"):')]},
            fails={"validator_function"}, only=True, says={"validator_function": "xx_"}),
    Variant("validator_looks_anywhere_in_the_name",
            {PY: [("    if value.startswith(prefix):", "    if prefix in value:")]},
            fails={"validator_function"}, only=True, says={"validator_function": "velocity_blup_"}),
    Variant("validator_ignores_case",
            {PY: [("    if value.startswith(prefix):", "    if value.lower().startswith(prefix.lower()):")]},
            fails={"validator_function"}, only=True, says={"validator_function": "Blup_effort"}),
    # ------------------------------------------------------------------ 8.5 the YAML
    Variant("yaml_with_a_made_up_plugin_name",
            {YAML: [("type: displacement_controller/DisplacementController",
                     "type: rrbot_workshop/DisplacementController")]},
            fails={"yaml_declares_the_controller"}, only=True, says={"yaml_declares_the_controller": "type"}),
    Variant("yaml_with_one_joint",
            {YAML: [(YAML_ENTRY, YAML_ENTRY.replace("      - joint2\n", ""))]},
            fails={"yaml_declares_the_controller"}, only=True, says={"yaml_declares_the_controller": "joints"}),
    Variant("yaml_in_velocity", {YAML: [(YAML_ENTRY, YAML_ENTRY.replace("position", "velocity"))]},
            fails={"yaml_declares_the_controller"}, only=True, says={"yaml_declares_the_controller": "interface_name"}),
    Variant("yaml_declaration_left_out", {YAML: [(DECLARED, "")]},
            fails={"yaml_declares_the_controller"}, only=True,
            says={"yaml_declares_the_controller": "declares no displacement_controller"}),
    Variant("yaml_broadcaster_deleted",
            {YAML: [("    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n", "")]},
            fails={"yaml_declares_the_controller"}, only=True, says={"yaml_declares_the_controller": "joint_state_broadcaster"}),
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


OWN_SECTION_YAML = """\
# displacement_controller's type in its own section, as Jazzy's spawner reads it with --param-file
controller_manager:
  ros__parameters:
    update_rate: 100  # [Hz]
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    forward_position_controller:
      type: forward_command_controller/ForwardCommandController

forward_position_controller:
  ros__parameters:
    joints: [joint1, joint2]
    interface_name: position

displacement_controller:
  ros__parameters:
    type: displacement_controller/DisplacementController
    joints:
      - joint1
      - joint2
    interface_name: position
"""

FLOW_YAML = """\
controller_manager: {ros__parameters: {update_rate: 100, joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster},
  forward_position_controller: {type: forward_command_controller/ForwardCommandController}}}
forward_position_controller: {ros__parameters: {joints: [joint1, joint2], interface_name: position}}
displacement_controller: {ros__parameters: {type: controlko_controllers/DisplacementController, joints: [joint2, joint1], interface_name: position, state_joints: []}}
"""

RIGHT += [
    Variant("type_in_the_controllers_own_section", {YAML: OWN_SECTION_YAML}),
    Variant("flow_style_type_in_own_section_joints_in_another_order", {YAML: FLOW_YAML}),
    Variant("slow_mode_also_reset_at_activation_and_cleanup_undoes_configure", {PY: [
        ("        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation is applied\n",
         "        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation is applied\n"
         "        self.slow_mode = False\n"),
        ("    def on_deactivate(self, previous_state: State) -> CallbackReturn:\n",
         "    def on_cleanup(self, previous_state: State) -> CallbackReturn:\n"
         "        self.joints, self.state_joints, self.displacements = [], [], []\n"
         "        return CallbackReturn.SUCCESS\n\n"
         "    def on_deactivate(self, previous_state: State) -> CallbackReturn:\n")]}),
    Variant("refusals_logged_as_warnings_with_one_check", {PY: [
        (COUNT + '            self.logger.error("rejected a JointJog with %d joint names and %d displacements: %s needs one "\n'
         '                              "displacement for each of %s", len(msg.joint_names), len(msg.displacements),\n'
         "                              self.get_name(), self.joints)\n"
         "            return\n" + NAMES,
         "        if len(msg.displacements) != len(msg.joint_names) or sorted(msg.joint_names) != sorted(self.joints):\n"),
        ('            self.logger.error("rejected a JointJog for joints %s: this controller moves %s", msg.joint_names,\n',
         '            self.logger.warning("ignoring JointJog %s: expected one displacement for each of %s", msg.joint_names,\n')]}),
]


@pytest.fixture(scope="module")
def rubrics(tmp_path_factory: pytest.TempPathFactory) -> dict:
    return grade_variants(8, WRONG + RIGHT, tmp_path_factory.mktemp("task08"))


@pytest.mark.parametrize("variant", WRONG, ids=str)
def test_wrong_solution_loses_points(rubrics: dict, variant: Variant) -> None:
    assert_loses_points(rubrics[variant.name], variant)


@pytest.mark.parametrize("variant", [v for v in WRONG if v.only], ids=str)
def test_one_slip_shows_hints_at_one_check(rubrics: dict, variant: Variant) -> None:
    """The checks a single slip fails build on one of them (graded(after=...)): only that one is a cause."""
    assert_one_cause(rubrics[variant.name], check_specs(8), variant.name)


def test_after_names_checks_of_the_grader() -> None:
    assert not unknown_after(check_specs(8))


@pytest.mark.parametrize("variant", RIGHT, ids=str)
def test_alternative_solution_gets_full_marks(rubrics: dict, variant: Variant) -> None:
    assert_full_marks(rubrics[variant.name])


def test_enough_variants() -> None:
    """At least 12 wrong and 3 right solutions, both YAML layouts among the right ones, one-slip variants for most."""
    assert len(WRONG) >= 12 and len(RIGHT) >= 3
    assert {"type_in_the_controllers_own_section", "flow_style_type_in_own_section_joints_in_another_order"} <= {
        v.name for v in RIGHT}
    assert sum(v.only for v in WRONG) >= 30


def test_the_exercise_as_handed_out_gets_a_clear_reason() -> None:
    """Untouched, the task scores 0; each check failing on its own names the learner's file (the TODO it stops at), the
    others say which check they wait for, and only the first cause shows a hint."""
    rubric = grade(8, track="exercises", record=False)
    assert rubric.score == 0 < rubric.max_score, rubric.format()
    assert not reason_problems(rubric), rubric.format()
    for check in rubric.failed():
        assert check.reason.startswith(("your displacement_controller.py", "your rrbot_controllers.yaml",
                                        "fails because")), rubric.format()
    assert [c.name for c in rubric.checks if c.hint] == ["validator_function"], rubric.format()
