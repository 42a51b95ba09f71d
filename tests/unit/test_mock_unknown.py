"""Mock for what is not here: ``bringup(..., mock_hardware="unknown"|"all")``, the plugin-type check Jazzy's loaders
make, and ``./workshop bringup``.

The robot is tests/unit/data/packages/src/example_tiny (package ``tinybot_example``): a system (shoulder), an
actuator (elbow) and a sensor (wrist force-torque), each with a plugin the library does not have.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.bringup import System, systems
from rrbot_workshop.cli import main
from rrbot_workshop.description import packages
from rrbot_workshop.exceptions import HardwareError
from rrbot_workshop.hardware.mock_substitutes import MockActuator, MockSensor
from rrbot_workshop.middleware import plugins
from rrbot_workshop.msgs import Float64MultiArray

SRC = Path(__file__).resolve().parent / "data" / "packages" / "src"
TINYBOT = "package://tinybot_example/urdf/tinybot.urdf.xacro"
YAML = "tinybot_controllers.yaml"
ORIGINAL = {
    "TinyBotShoulder": "tinybot_example/TinyBotShoulderHardware",
    "TinyBotElbow": "tinybot_example/TinyElbowDrive",
    "TinyWristSensor": "tinybot_example/TinyWristSensor",
}


@pytest.fixture(autouse=True)
def _clean(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(packages.PACKAGE_PATH_ENV, raising=False)
    for system in list(systems().values()):
        system.shutdown()
    yield
    for system in list(systems().values()):
        system.shutdown()


def _plugins(system: System) -> dict[str, tuple[str, str]]:
    return {c.name: (c.type, c.plugin_name) for c in system.controller_manager.list_hardware_components()}


def test_a_mocked_velocity_joint_moves_and_a_declared_choice_is_kept() -> None:
    """calculate_dynamics is added only where the description does not say it and every command is
    position/velocity/acceleration."""
    from rrbot_workshop.description import parse_ros2_control
    from rrbot_workshop.hardware_interface.resource_loading import mock_hardware_infos

    def tag(name: str, command: str, params: str = "") -> str:
        return (f'<ros2_control name="{name}" type="system"><hardware><plugin>vendor/Driver</plugin>{params}'
                f'</hardware><joint name="{name}_j"><command_interface name="{command}"/>'
                '<state_interface name="position"/><state_interface name="velocity"/></joint></ros2_control>')

    links = '<link name="base"/>' + "".join(
        f'<link name="{n}_l"/><joint name="{n}_j" type="continuous"><parent link="base"/><child link="{n}_l"/>'
        "</joint>" for n in ("vel", "eff", "own"))
    urdf = ('<robot name="r">' + links + tag("vel", "velocity") + tag("eff", "effort")
            + tag("own", "velocity", '<param name="calculate_dynamics">false</param>') + "</robot>")
    infos, mocked = mock_hardware_infos(parse_ros2_control(urdf), "unknown")
    assert mocked == {"vel": "vendor/Driver", "eff": "vendor/Driver", "own": "vendor/Driver"}
    assert [i.hardware_parameters.get("calculate_dynamics") for i in infos] == ["true", None, "false"]
    with rw.bringup(urdf.replace(tag("eff", "effort"), ""), {"controller_manager": {"ros__parameters": {
            "update_rate": 100, "vc": {"type": "velocity_controllers/JointGroupVelocityController"}}},
            "vc": {"ros__parameters": {"joints": ["vel_j"]}}}, mock_hardware="unknown", spawn=["vc"]) as system:
        system.publish("/vc/commands", Float64MultiArray(data=[2.0]))
        system.spin(0.5)
        assert system.resource_manager.get_interface_value("vel_j/position") == pytest.approx(0.98, abs=0.03)


def test_unknown_plugins_fail_without_mock_hardware() -> None:
    """As Jazzy: a plugin nobody provides is an error naming the component; nothing is left running."""
    with pytest.raises(HardwareError, match="hardware component 'TinyBotShoulder'.*tinybot_example/TinyBotShoulder"):
        rw.bringup(TINYBOT, YAML, package_path=[SRC])
    assert systems() == {}


def test_unknown_plugins_become_the_mock_of_their_type_and_are_reported(caplog: pytest.LogCaptureFixture) -> None:
    """system -> GenericSystem, actuator -> MockActuator, sensor -> MockSensor; INFO log and mocked_hardware."""
    with caplog.at_level(logging.INFO, logger="rrbot_workshop.bringup.launch"):
        system = rw.bringup(TINYBOT, YAML, package_path=[SRC], mock_hardware="unknown",
                            spawn=["joint_state_broadcaster", "position_controller", "wrist_ft_broadcaster"])
    with system:
        assert system.mocked_hardware == ORIGINAL
        assert _plugins(system) == {
            "TinyBotShoulder": ("system", "mock_components/GenericSystem"),
            "TinyBotElbow": ("actuator", "rrbot_workshop/MockActuator"),
            "TinyWristSensor": ("sensor", "rrbot_workshop/MockSensor"),
        }
        for component, original in ORIGINAL.items():
            assert f"hardware component '{component}': plugin '{original}' replaced by its mock" in caplog.text
        # the mocks behave: positions follow the commands, the sensor holds its initial values
        system.publish("/position_controller/commands", Float64MultiArray(data=[1.0, -1.2]))
        system.spin(0.05)
        state = system.latest("/joint_states")
        assert dict(zip(state.name, state.position, strict=True)) == {"shoulder": 1.0, "elbow": -1.2}
        wrench = system.latest("/wrist_ft_broadcaster/wrench").wrench
        assert wrench.force.z == 1.5 and math.isnan(wrench.force.x)
        # the original <hardware><param>s stay; position-commanded joints get the mock's dynamics, as a driver moves
        assert system.hardware_infos[0].hardware_parameters == {"port": "/dev/ttyTINY0", "calculate_dynamics": "true"}
        assert system.hardware_infos[2].hardware_parameters == {}  # the sensor has no joint commands


def test_known_plugins_are_kept_with_unknown_and_replaced_with_all() -> None:
    """With the description's own switch (GenericSystem on the system), only the others are mocked by
    'unknown'; 'all' mocks every component that is not its type's mock already."""
    with rw.bringup(TINYBOT, package_path=[SRC], mock_hardware="unknown",
                    xacro_args={"use_mock_hardware": True}) as system:
        assert system.mocked_hardware == {k: v for k, v in ORIGINAL.items() if k != "TinyBotShoulder"}
    with rw.bringup("rrbot", xacro_args={"sim_mujoco": True}, mock_hardware="all") as system:
        assert system.mocked_hardware == {"rrbot": "rrbot_workshop/MujocoSystem"}
        assert _plugins(system)["rrbot"] == ("system", "mock_components/GenericSystem")
    with rw.bringup("rrbot", xacro_args={"use_mock_hardware": True}, mock_hardware="all") as system:
        assert system.mocked_hardware == {}


def test_generic_system_on_a_sensor_is_refused_with_the_fix() -> None:
    """Jazzy exports GenericSystem only as a SystemInterface: its sensor loader does not find it."""
    with pytest.raises(HardwareError) as info:
        rw.bringup(TINYBOT, package_path=[SRC], mock_hardware="unknown", xacro_args={"generic_sensor": True})
    text = str(info.value)
    assert "'TinyWristSensor'" in text and 'type="sensor"' in text and "mock_components/GenericSystem" in text
    assert "SystemInterface" in text and 'type="system"' in text and "Fix:" in text
    assert systems() == {}
    # 'all' mocks the sensor by its type instead
    with rw.bringup(TINYBOT, package_path=[SRC], mock_hardware="all", xacro_args={"generic_sensor": True}) as system:
        assert _plugins(system)["TinyWristSensor"] == ("sensor", "rrbot_workshop/MockSensor")


def test_a_plugin_of_another_type_is_refused_on_an_actuator() -> None:
    """The same check for every plugin: an actuator tag with a SystemInterface plugin."""
    urdf = ('<robot name="one"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
            '<child link="b"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>'
            '<ros2_control name="Drive" type="actuator"><hardware><plugin>mock_components/GenericSystem</plugin>'
            '</hardware><joint name="j"><command_interface name="position"/><state_interface name="position"/>'
            "</joint></ros2_control></robot>")
    with pytest.raises(HardwareError, match="'Drive' is <ros2_control type=\"actuator\"> with plugin "
                                            "'mock_components/GenericSystem'"):
        rw.bringup(urdf)
    plugins.register("hardware", "test/SensorOnly", MockSensor)
    try:
        with pytest.raises(HardwareError, match="the plugin is a SensorInterface"):
            rw.bringup(urdf.replace("mock_components/GenericSystem", "test/SensorOnly"))
    finally:
        plugins.unregister("hardware", "test/SensorOnly")
    with rw.bringup(urdf.replace("mock_components/GenericSystem", "rrbot_workshop/MockActuator")) as system:
        assert isinstance(system.resource_manager.get_component("Drive")._impl, MockActuator)


def test_an_invalid_mode_is_refused_before_anything_runs() -> None:
    with pytest.raises(HardwareError, match=r"mock_hardware='some' is not valid \(valid: None, 'unknown', 'all'\)"):
        rw.bringup(TINYBOT, package_path=[SRC], mock_hardware="some")
    assert systems() == {}


def test_mock_sensor_ignores_command_mocking_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    urdf = ('<robot name="s"><link name="a"/><ros2_control name="Fts" type="sensor"><hardware>'
            '<plugin>rrbot_workshop/MockSensor</plugin><param name="mock_sensor_commands">true</param></hardware>'
            '<sensor name="fts"><state_interface name="force.z"><param name="initial_value">2.0</param>'
            "</state_interface></sensor></ros2_control></robot>")
    with caplog.at_level(logging.WARNING), rw.bringup(urdf) as system:
        system.spin(0.02)
        assert system.resource_manager.get_interface_value("fts/force.z") == 2.0
        assert system.controller_manager.list_hardware_interfaces().command_interfaces == []
    assert "mock_sensor_commands/mock_gpio_commands are ignored" in caplog.text


# ============================================================================ ./workshop bringup
def test_cli_bringup_prints_hardware_mocks_controllers_and_joint_states(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["bringup", TINYBOT, "--controllers", YAML, "--package-path", str(SRC), "--mock-hardware", "unknown",
                 "--spawn", "joint_state_broadcaster", "--spawn", "position_controller", "--arg", "prefix:=",
                 "--seconds", "0.5"])
    out = capsys.readouterr().out
    assert code == 0
    assert "System 'tinybot' at t = 0.500 s" in out
    assert ("TinyBotShoulder  system  mock_components/GenericSystem  active  "
            "[mock, replaces tinybot_example/TinyBotShoulderHardware]") in out
    assert "TinyWristSensor  sensor  rrbot_workshop/MockSensor  active  [mock, replaces tinybot_example/TinyWristSensor]" in out
    assert "position_controller  position_controllers/JointGroupPositionController  active" in out
    assert "shoulder  position 0.2000  velocity 0.0000" in out  # initial_value of the shoulder's position
    assert systems() == {}  # shut down at the end


def test_cli_bringup_errors_are_one_line_with_exit_status_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bringup", TINYBOT, "--package-path", str(SRC)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown hardware plugin 'tinybot_example/TinyBotShoulderHardware'" in err[0]
    assert main(["bringup", "package://nobody/urdf/x.xacro"]) == 2
    assert "unknown package 'nobody'" in capsys.readouterr().err
    assert main(["bringup", TINYBOT, "--package-path", str(SRC), "--arg", "no-equals"]) == 2
    assert "--arg 'no-equals' must be NAME:=VALUE" in capsys.readouterr().err
    assert main(["bringup", TINYBOT, "--package-path", str(SRC), "--mock-hardware", "some"]) == 2
    assert main(["bringup", TINYBOT, "--package-path", str(SRC), "--seconds", "-1"]) == 2
    assert "--seconds must be" in capsys.readouterr().err


def test_a_mocked_joint_takes_several_control_modes_where_genericsystem_refuses_them() -> None:
    """Example 7's controller claims position and velocity of each joint. Its driver accepts that; a GenericSystem
    with calculate_dynamics refuses it, as Jazzy's does. A mocked driver takes both and follows the position."""
    from rrbot_workshop.exceptions import SwitchError

    def urdf(plugin: str, params: str = "") -> str:
        return ('<robot name="r"><link name="base"/><link name="l"/><joint name="j" type="revolute">'
                '<parent link="base"/><child link="l"/><limit lower="-3" upper="3" effort="1" velocity="9"/></joint>'
                f'<ros2_control name="arm" type="system"><hardware><plugin>{plugin}</plugin>{params}</hardware>'
                '<joint name="j"><command_interface name="position"/><command_interface name="velocity"/>'
                '<state_interface name="position"/><state_interface name="velocity"/></joint></ros2_control></robot>')

    yaml = {"controller_manager": {"ros__parameters": {"update_rate": 100, "jtc": {
        "type": "joint_trajectory_controller/JointTrajectoryController"}}},
        "jtc": {"ros__parameters": {"joints": ["j"], "command_interfaces": ["position", "velocity"],
                                    "state_interfaces": ["position", "velocity"]}}}
    with rw.bringup(urdf("vendor/ArmDriver"), yaml, mock_hardware="unknown", spawn=["jtc"]) as system:
        from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

        system.publish("/jtc/joint_trajectory", JointTrajectory(
            joint_names=["j"], points=[JointTrajectoryPoint(positions=[0.4], time_from_start=1.0)]))
        system.spin(1.5)
        assert system.resource_manager.get_interface_value("j/position") == pytest.approx(0.4, abs=1e-3)
    with pytest.raises(SwitchError, match="2 control modes at once"):
        rw.bringup(urdf("mock_components/GenericSystem", '<param name="calculate_dynamics">true</param>'), yaml,
                   spawn=["jtc"])
    assert systems() == {}


def test_cli_bringup_args_fill_the_yaml_vars_and_the_namespace_applies(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """``--arg`` is a launch argument: xacro's argument and the YAML's $(var) (example 1's joint_prefix);
    ``--namespace`` picks the YAML's sections for that manager. Without the argument: one error naming it."""
    yaml_file = tmp_path / "prefixed_controllers.yaml"
    yaml_file.write_text(
        "/**/controller_manager:\n  ros__parameters:\n    update_rate: 100\n"
        "/**/forward_position_controller:\n  ros__parameters:\n"
        "    type: forward_command_controller/ForwardCommandController\n"
        "    joints: [$(var joint_prefix)1, $(var joint_prefix)2]\n    interface_name: position\n")
    code = main(["bringup", "rrbot", "--controllers", str(yaml_file), "--arg", "joint_prefix:=joint",
                 "--namespace", "/arm_1", "--spawn", "forward_position_controller", "--seconds", "0.1"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "forward_position_controller" in out and "active" in out
    assert main(["bringup", "rrbot", "--controllers", str(yaml_file), "--spawn", "forward_position_controller"]) == 2
    assert "joint_prefix" in capsys.readouterr().err
