"""``rrbot-workshop lint`` on a description: a ``<hardware>`` block with two ``<plugin>`` tags is an error.

Jazzy's ``<ros2_control>`` parser reads ``<hardware>`` with ``FirstChildElement("plugin")``: it takes the first
plugin and ignores the others without a word. A xacro switch whose two branches are both taken (an ``xacro:if``
without its ``xacro:unless``) produces exactly that, so the linter reports it; the parser itself stays as Jazzy's.
"""

from __future__ import annotations

from pathlib import Path

from rrbot_workshop.cli import main
from rrbot_workshop.description import parse_ros2_control
from rrbot_workshop.tools.lint import lint_controllers, lint_description

_URDF = """\
<?xml version="1.0"?>
<robot name="one" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="use_mock_hardware" default="false"/>
  <link name="base"/>
  <link name="arm"/>
  <joint name="j" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <ros2_control name="one" type="system">
    <hardware>
{hardware}
    </hardware>
    <joint name="j">
      <command_interface name="position"/>
      <state_interface name="position"/>
    </joint>
  </ros2_control>
</robot>
"""

_BOTH_TAKEN = """\
      <xacro:if value="$(arg use_mock_hardware)">
        <plugin>mock_components/GenericSystem</plugin>
      </xacro:if>
      <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>"""

_ONE_TAKEN = """\
      <xacro:if value="$(arg use_mock_hardware)">
        <plugin>mock_components/GenericSystem</plugin>
      </xacro:if>
      <xacro:unless value="$(arg use_mock_hardware)">
        <plugin>controlko_hardware_interface/RRBotHardwareInterface</plugin>
      </xacro:unless>"""

_CONTROLLERS = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
"""


def _description(tmp_path: Path, hardware: str) -> Path:
    path = tmp_path / "one.urdf.xacro"
    path.write_text(_URDF.format(hardware=hardware))
    return path


def test_two_plugins_in_one_hardware_block_are_an_error_naming_both(tmp_path: Path) -> None:
    path = _description(tmp_path, _BOTH_TAKEN)
    findings = lint_description(path, {"use_mock_hardware": "true"})
    assert [f.level for f in findings] == ["error"], findings
    message = str(findings[0])
    assert "<ros2_control name='one'><hardware>" in message
    assert "2 <plugin> tags (mock_components/GenericSystem, controlko_hardware_interface/RRBotHardwareInterface)" \
        in message
    assert "silently use the first (mock_components/GenericSystem)" in message
    assert findings[0].source == str(path)


def test_the_parser_itself_takes_the_first_plugin_as_jazzy_does(tmp_path: Path) -> None:
    """The library's parser keeps Jazzy's behaviour; only the linter complains."""
    from rrbot_workshop.description import process_xacro

    urdf = process_xacro(_description(tmp_path, _BOTH_TAKEN), use_mock_hardware=True)
    (info,) = parse_ros2_control(urdf)
    assert info.hardware_plugin_name == "mock_components/GenericSystem"


def test_a_switch_taking_one_branch_is_clean_both_ways(tmp_path: Path) -> None:
    path = _description(tmp_path, _ONE_TAKEN)
    for value in ("true", "false"):
        assert lint_description(path, {"use_mock_hardware": value}) == []


def test_one_plugin_outside_a_switch_is_clean(tmp_path: Path) -> None:
    path = _description(tmp_path, "      <plugin>mock_components/GenericSystem</plugin>")
    assert lint_description(path) == []


def test_the_controllers_lint_reports_it_for_its_description(tmp_path: Path) -> None:
    description = _description(tmp_path, _BOTH_TAKEN)
    controllers = tmp_path / "controllers.yaml"
    controllers.write_text(_CONTROLLERS)
    findings = lint_controllers(controllers, description, {"use_mock_hardware": "true"})
    errors = [f for f in findings if f.level == "error"]
    assert len(errors) == 1 and "2 <plugin> tags" in errors[0].message, findings
    assert errors[0].source == str(description)


def test_cli_exits_with_an_error_and_prints_it(tmp_path: Path, capsys) -> None:  # noqa: ANN001 - pytest fixture
    path = _description(tmp_path, _BOTH_TAKEN)
    status = main(["lint", str(path), "--xacro-arg", "use_mock_hardware:=true"])
    out = capsys.readouterr().out
    assert status != 0
    assert "2 <plugin> tags" in out and "1 error(s)" in out, out
