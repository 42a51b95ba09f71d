"""The task-7 grader fails plausible wrong solutions, among them the original workshop's own bugs: each test grades a
copy of the solution with one mistake."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import grade

HAS_SOLUTIONS = (tracks.course_root() / "solutions").is_dir()
pytestmark = pytest.mark.skipif(not HAS_SOLUTIONS, reason="this copy of the course has no solutions/")


def _failed_with(tmp_path: Path, *changes: tuple[str, str], file: str = "rrbot_hardware_interface.py") -> set[str]:
    source = tracks.task_dir(7, "solutions")
    copy = tmp_path / source.name
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__"))
    path = copy / file
    text = path.read_text()
    for old, new in changes:
        assert text.count(old) == 1, f"mutation {old!r} applies {text.count(old)} times"
        text = text.replace(old, new)
    path.write_text(text)
    return {c.name for c in grade(7, task_root=tmp_path).checks if not c.passed}


def test_the_originals_commented_out_check_accepts_position_and_velocity(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("        if len(modes) > 1:\n", "        if False:\n"))
    assert failed == {"incompatible_controllers_refused"}


def test_the_originals_copy_paste_keeps_position_mode_for_velocity(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("            self.next_mode = ControlMode.VELOCITY\n",
                                     "            self.next_mode = ControlMode.POSITION\n"))
    assert "mode_switch_per_controller" in failed


def test_the_originals_effort_on_the_acceleration_buffer(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('                self.set_state(f"{joint}/acceleration", a)\n',
                                     '                self.set_state(f"{joint}/acceleration", a)\n'
                                     '                self.set_state(f"{joint}/effort", a)\n'))
    assert failed == {"effort_is_not_the_acceleration"}


def test_the_originals_sensor_and_gpio_values_swapped(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("            values = self.device.read_sensor_values(len(sensor.state_interfaces))\n",
                                     "            values = [float(b) for b in self.device.read_gpio()[0]] * 3\n"))
    assert "sensor_values" in failed


def test_gpio_outputs_never_written(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("            self.device.write_gpios(outputs)\n", "            pass\n"))
    assert failed == {"gpio_values"}


def test_commands_not_seeded_at_activation(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, (
        '            self.set_command(f"{joint}/position", position)  # a controller taking over starts where the '
        'joint is\n', '            self.set_command(f"{joint}/position", 0.0)\n'))
    assert "lifecycle" in failed


def test_movement_never_enabled(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("        self.device.init()\n", ""))
    assert {"lifecycle", "joint_values", "mode_switch_per_controller"} <= failed


def test_no_description_check(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('            if commands != ["position", "velocity"]:\n', "            if False:\n"),
                          ('            if "position" not in states or "velocity" not in states:\n',
                           "            if False:\n"))
    assert failed == {"description_checked_at_init"}


def test_a_swallowed_device_failure(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("        positions, velocities, accelerations = self.device.read_joint_states()\n",
                                     "        try:\n"
                                     "            positions, velocities, accelerations = self.device.read_joint_states()\n"
                                     "        except Exception:\n"
                                     "            return ReturnType.OK\n"))
    assert failed == {"device_failure_reported"}


def test_seed_ignored(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('seed=int(self.info.hardware_parameters.get("seed", "0"))', "seed=0"))
    assert failed == {"seed_parameter"}


def test_rejection_without_a_reason(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ('            self.mode_switch_rejection = ("the RRBot device runs all joints in one '
                                     'mode; this switch would command "\n'
                                     '                                          "them in position and in velocity at '
                                     'once")\n', ""))
    assert failed == {"incompatible_controllers_refused"}


def test_yaml_without_the_incompatible_controller(tmp_path: Path) -> None:
    failed = _failed_with(tmp_path, ("      - position\n      - velocity\n    state_interfaces:\n      - position\n"
                                     "      - velocity\n", "      - position\n    state_interfaces:\n      - position\n"
                                     "      - velocity\n"), file="rrbot_controllers.yaml")
    assert failed == {"yaml_defines_the_incompatible_controller"}
