"""``rrbot-workshop lint``: every problem of a controllers YAML reported at once, with line and closest valid name."""

from __future__ import annotations

from pathlib import Path

import pytest

from rrbot_workshop.tools.lint import Finding, format_findings, lint_controllers, lint_description

REPO = Path(__file__).resolve().parents[2]
RRBOT = REPO / "descriptions" / "rrbot" / "urdf" / "rrbot.urdf.xacro"
CONFIG = REPO / "descriptions" / "rrbot" / "config"

_GOOD = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    forward_position_controller:
      type: forward_command_controller/ForwardCommandController

forward_position_controller:
  ros__parameters:
    joints: [joint1, joint2]
    interface_name: position
"""


def _lint(tmp_path: Path, text: str, description: Path | None = RRBOT, **xacro_args: str) -> list[Finding]:
    path = tmp_path / "controllers.yaml"
    path.write_text(text)
    return lint_controllers(path, description=description, xacro_args=xacro_args)


def _errors(findings: list[Finding]) -> list[str]:
    return [str(f) for f in findings if f.level == "error"]


@pytest.mark.parametrize("name, args", [
    ("rrbot_controllers.yaml", {}),
    ("rrbot_chained_controllers.yaml", {}),
    ("rrbot_sim_position_controllers.yaml", {"sim_mujoco": "true"}),
    ("rrbot_sim_effort_controllers.yaml", {"sim_mujoco": "true"}),
    ("../../diffbot/config/diffbot_controllers.yaml", {}),
    ("../../rrbot_on_diffbot/config/rrbot_on_diffbot_controllers.yaml", {}),
    ("../../multi_rrbot/config/multi_rrbot_controllers.yaml", {}),
])
def test_course_configurations_have_no_errors_or_warnings(name: str, args: dict[str, str]) -> None:
    """The YAML files the course ships load on Jazzy as they are (notes about changed defaults aside)."""
    package = name.split("/")[2] if name.startswith("..") else "rrbot"
    description = REPO / "descriptions" / package / "urdf" / f"{package}.urdf.xacro"
    findings = lint_controllers(CONFIG / name, description=description, xacro_args=args)
    assert [f for f in findings if f.level != "note"] == []


def test_clean_file_says_no_problems(tmp_path: Path) -> None:
    assert format_findings(_lint(tmp_path, _GOOD)) == "no problems found"


def test_yaml_syntax_error_is_one_finding_with_line_and_column(tmp_path: Path) -> None:
    findings = _lint(tmp_path, _GOOD.replace("joints: [joint1, joint2]", "joints: [joint1, joint2"))
    assert len(findings) == 1
    assert findings[0].level == "error" and findings[0].line > 0 and "column" in findings[0].message


def test_unknown_type_suggests_the_closest_known_one_at_its_line(tmp_path: Path) -> None:
    text = _GOOD.replace("ForwardCommandController", "ForwardComandController")
    (finding,) = _errors_of(_lint(tmp_path, text))
    assert finding.line == 7 and finding.where == "controller_manager.forward_position_controller.type"
    assert "did you mean 'forward_command_controller/ForwardCommandController'" in finding.message


def _errors_of(findings: list[Finding]) -> list[Finding]:
    return [f for f in findings if f.level == "error"]


def test_misspelt_parameter_is_a_warning_with_the_closest_declared_name(tmp_path: Path) -> None:
    findings = _lint(tmp_path, _GOOD.replace("interface_name: position", "interface_name: position\n    joint: [a]"))
    (warning,) = [f for f in findings if f.level == "warning"]
    assert warning.line == 13 and "declares no parameter 'joint'" in warning.message
    assert "did you mean 'joints'" in warning.message


def test_wrong_type_and_missing_required_are_both_reported(tmp_path: Path) -> None:
    """Two parameter errors in one controller: both appear, not only the first."""
    text = _GOOD.replace("joints: [joint1, joint2]", "joints: 3").replace("    interface_name: position\n", "")
    messages = _errors(_lint(tmp_path, text, description=None))
    assert any("joints" in m and "type" in m for m in messages), messages
    assert any("interface_name" in m for m in messages), messages


def test_removed_humble_keys_are_warnings_with_the_jazzy_replacement(tmp_path: Path) -> None:
    """Jazzy's manager no longer reads the key and loads the file anyway: a warning, not an error."""
    text = _GOOD.replace("update_rate: 100", "update_rate: 100\n    configure_components_on_start: [RRBot]")
    findings = _lint(tmp_path, text)
    assert _errors(findings) == []
    (warning,) = [str(f) for f in findings if f.level == "warning"]
    assert "hardware_components_initial_state.inactive" in warning and ":4:" in warning and "ignores it" in warning


def test_manager_parameter_of_wrong_type_or_unknown_name(tmp_path: Path) -> None:
    text = _GOOD.replace("update_rate: 100", "update_rate: 100\n    enforce_command_limits: 'yes'\n    handle_exception: true")
    findings = _lint(tmp_path, text)
    assert any("must be of type bool" in f.message for f in _errors_of(findings))
    assert any("did you mean 'handle_exceptions'" in f.message for f in findings if f.level == "warning")


def test_interface_missing_from_the_description_names_the_closest(tmp_path: Path) -> None:
    text = _GOOD.replace("interface_name: position", "interface_name: effort")
    errors = _errors(_lint(tmp_path, text))
    assert any("'joint1/effort'" in e and "rrbot.urdf.xacro does not declare" in e for e in errors), errors


def test_reference_interfaces_of_another_controller_count_as_existing() -> None:
    """A chain's preceding controller claims the PIDs' references: not an error."""
    findings = lint_controllers(CONFIG / "rrbot_chained_controllers.yaml", description=RRBOT)
    assert _errors(findings) == []


def test_parameters_for_an_undeclared_controller_are_flagged(tmp_path: Path) -> None:
    text = _GOOD + "\nforward_position_controler:\n  ros__parameters:\n    joints: [joint1]\n"
    (warning,) = [f for f in _lint(tmp_path, text) if f.level == "warning"]
    assert "did you mean 'forward_position_controller'" in warning.message


def test_broken_description_is_reported_with_its_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='r'><link name='a'/></robot>")
    (finding,) = lint_description(bad)
    assert finding.level == "error" and finding.source == str(bad) and "ros2_control" in finding.message


def test_a_packages_own_cpp_controller_is_a_note_and_an_undeclared_type_an_error(tmp_path: Path) -> None:
    """A demo's own controller (declared in its package's plugin description file) loads in Jazzy: lint says the
    library cannot run it, as a note. The same type without the declaration stays an unknown type (an error)."""
    from rrbot_workshop.tools.lint import lint_controllers

    pkg = tmp_path / "arm_demo"
    (pkg / "bringup" / "config").mkdir(parents=True)
    (pkg / "package.xml").write_text('<?xml version="1.0"?><package format="3"><name>arm_demo</name>'
                                     "<version>0.0.1</version></package>")
    yaml_file = pkg / "bringup" / "config" / "arm.yaml"
    yaml_file.write_text("controller_manager:\n  ros__parameters:\n    update_rate: 50\n"
                         "arm_controller:\n  ros__parameters:\n    type: arm_demo/ArmController\n    joints: [j1]\n")
    unknown = lint_controllers(yaml_file)
    assert [(f.level, f.where) for f in unknown] == [("error", "arm_controller.type")]
    (pkg / "arm_demo_plugins.xml").write_text(
        '<library path="arm_demo"><class name="arm_demo/ArmController" type="arm_demo::ArmController" '
        'base_class_type="controller_interface::ControllerInterface"/></library>')
    declared = lint_controllers(yaml_file)
    assert [(f.level, f.where) for f in declared] == [("note", "arm_controller.type")]
    assert "arm_demo/arm_demo_plugins.xml" in declared[0].message and "controller_types" in declared[0].message


_PID = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    arm_pid:
      type: pid_controller/PidController

arm_pid:
  ros__parameters:
    dof_names: [joint1]
    command_interface: velocity
    reference_and_state_interfaces: [position]
{extra}    gains:
      joint1: {{p: 1.0, feedforward_gain: {gain}}}
"""


def test_a_feedforward_gain_with_the_mode_off_is_a_warning(tmp_path: Path) -> None:
    """Jazzy's pid_controller leaves feedforward_gain out unless feed-forward mode is on
    (test_update_chained_feedforward_off_with_gain): lint warns at the gain's line."""
    (finding,) = _lint(tmp_path, _PID.format(extra="", gain=0.95))
    assert finding.level == "warning" and finding.line == 13
    assert finding.where == "arm_pid.gains.joint1.feedforward_gain"
    assert "is 0.95, but feed-forward mode is off" in finding.message and "enable_feedforward: true" in finding.message


@pytest.mark.parametrize("extra, gain", [
    ("    enable_feedforward: true\n", 0.95),
    ("", 0.0),
])
def test_a_feedforward_gain_that_acts_or_is_zero_is_not_reported(tmp_path: Path, extra: str, gain: float) -> None:
    """With enable_feedforward: true the gain acts; a zero gain changes nothing either way."""
    assert _lint(tmp_path, _PID.format(extra=extra, gain=gain)) == []


def test_a_feedforward_mode_from_a_launch_argument_is_not_judged(tmp_path: Path) -> None:
    """enable_feedforward given as an unsubstituted $(var): only the missing argument is reported."""
    findings = _lint(tmp_path, _PID.format(extra="    enable_feedforward: $(var ff)\n", gain=0.95))
    assert [f.where for f in findings] == ["$(var ff)"]
