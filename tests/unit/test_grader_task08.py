"""The task-8 grader fails plausible wrong solutions: each test grades a copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed_with(tmp_path: Path, old: str, new: str, file: str = "displacement_controller.py",
                 more: tuple[tuple[str, str], ...] = ()) -> set[str]:
    source = tracks.task_dir(8, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    for before, after in ((old, new), *more):
        assert text.count(before) == 1, f"mutation {before!r} applies {text.count(before)} times"
        text = text.replace(before, after)
    path.write_text(text)
    return {c.name for c in grade(8, task_root=tmp_path).checks if not c.passed}


def test_command_is_the_displacement_alone_as_the_original_tests_expected(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "set_value(current + factor * displacement)", "set_value(factor * displacement)")
    assert "command_is_state_plus_displacement" in failed and "moves_the_rrbot" in failed


def test_displacement_applied_every_cycle(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "            self.displacements[i] = math.nan  # used once\n", "")
    assert "displacement_used_once" in failed


def test_no_nan_on_deactivate(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "            interface.set_value(math.nan)  # no stale command is left for the next "
                          "controller\n", "            pass\n")
    assert failed == {"nan_commands_on_deactivate"}


def test_a_message_for_some_of_the_joints_accepted(tmp_path: Path) -> None:
    """No size or name check: a JointJog for one joint moves that joint (and leaves NaN pending for the other)."""
    old = "        if len(msg.joint_names) != len(self.joints) or len(msg.displacements) != len(self.joints):\n"
    failed = _failed_with(tmp_path, old, "        if False:\n", more=(
        ("        if sorted(msg.joint_names) != sorted(self.joints):\n", "        if False:\n"),
        ("self.displacements = [float(by_name[joint]) for joint in self.joints]",
         "self.displacements = [float(by_name.get(joint, math.nan)) for joint in self.joints]"),
    ))
    assert "wrong_joint_count_refused" in failed


def test_matched_by_position_instead_of_name(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "self.displacements = [float(by_name[joint]) for joint in self.joints]",
                          "self.displacements = [float(d) for d in msg.displacements]")
    assert failed == {"displacements_matched_by_name", "moves_the_rrbot"}


def test_blup_rule_missing_from_the_schema(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, '      displacement_controller::forbidden_interface_name_prefix: ["blup_"]\n', "")
    assert failed == {"blup_prefix_refused_at_load"}


def test_validator_with_a_hard_coded_prefix(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "    if value.startswith(prefix):", '    if value.startswith("blup_"):')
    assert failed == {"validator_function"}


def test_slow_mode_ignored(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "factor = 0.5 if self.slow_mode else 1.0", "factor = 1.0")
    assert failed == {"slow_mode"}


def test_messages_from_before_activation_applied(tmp_path: Path) -> None:
    old = "        self.displacements = [math.nan] * len(self.joints)  # nothing received before activation is applied\n"
    failed = _failed_with(tmp_path, old, "")
    assert failed == {"activation_forgets_earlier_messages"}


def test_state_joints_ignored(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "for joint in self.state_joints])", "for joint in self.joints])")
    assert "configure_and_claimed_interfaces" in failed


def test_yaml_with_a_made_up_plugin_name(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, "type: displacement_controller/DisplacementController",
                          "type: rrbot_workshop/DisplacementController", file="rrbot_controllers.yaml")
    assert {"yaml_declares_the_controller", "moves_the_rrbot"} <= failed
