"""MyRobot (notebook 15): its simulated devices (rrbot_workshop/hardware/my_robot.py) and its package (descriptions/my_robot)."""

from __future__ import annotations

import math
import statistics

import pytest

import rrbot_workshop as rw
from rrbot_workshop import joint_limits as jl
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.hardware.my_robot import MyRobotDevice, ToolForceTorqueSensor
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import Float64MultiArray

PACKAGE = rw.description.descriptions_root() / "my_robot"
XACRO = PACKAGE / "description/urdf/my_robot.urdf.xacro"
SPAWN = ["joint_state_broadcaster", "effort_controller", "position_controller", "tool_fts_broadcaster"]


# --------------------------------------------------------------------------------------------- the device


def test_effort_joint_integrates_torque_against_inertia_and_damping() -> None:
    device = MyRobotDevice(["effort"], inertia=2.0, damping=1.0)
    device.enable()
    device.write([4.0], 0.5)
    positions, velocities, efforts = device.read()
    assert velocities == [pytest.approx(0.5 * (4.0 - 0.0) / 2.0)]  # semi-implicit Euler: v first
    assert positions == [pytest.approx(0.5 * 1.0)]
    assert efforts == [4.0]
    device.write([0.0], 0.5)
    assert device.read()[1] == [pytest.approx(1.0 - 0.5 * 1.0 * 1.0 / 2.0)]  # damping slows it


def test_position_joint_reaches_its_command_within_the_period() -> None:
    device = MyRobotDevice(["position"], initial_positions=[0.2])
    device.enable()
    device.write([0.7], 0.01)
    positions, velocities, _ = device.read()
    assert positions == [0.7] and velocities == [pytest.approx(50.0)]


def test_the_device_applies_what_it_is_sent_without_limits() -> None:
    device = MyRobotDevice(["effort", "position"])
    device.enable()
    device.write([1e6, 42.0], 0.01)
    assert device.last_commands == [1e6, 42.0] and device.read()[0][1] == 42.0


def test_nan_is_no_command_and_a_disabled_device_ignores_commands() -> None:
    device = MyRobotDevice(["effort", "position"], initial_positions=[0.0, 0.3])
    device.enable()
    device.write([math.nan, math.nan], 0.01)
    assert device.read()[0] == [0.0, 0.3] and device.read()[2][0] == 0.0
    device.disable()
    device.write([5.0, 1.0], 0.01)
    assert device.read()[0] == [0.0, 0.3]
    assert not device.enabled


def test_device_refuses_unknown_modes_and_wrong_counts() -> None:
    with pytest.raises(ValueError, match="velocity"):
        MyRobotDevice(["effort", "velocity"])
    with pytest.raises(ValueError, match="inertia"):
        MyRobotDevice(["effort"], inertia=0.0)
    with pytest.raises(ValueError, match="initial_positions"):
        MyRobotDevice(["effort"], initial_positions=[0.0, 1.0])
    with pytest.raises(ValueError, match="2 commands for 1 joints"):
        MyRobotDevice(["effort"]).write([0.0, 0.0], 0.01)


# --------------------------------------------------------------------------------------------- the tool sensor


def _sensor_urdf(interfaces: str = "fx fy fz tx ty tz", params: str = "") -> str:
    states = "".join(f'<state_interface name="{i}"/>' for i in interfaces.split())
    return (f'<robot name="r"><link name="a"/><ros2_control name="tool" type="sensor"><hardware>'
            f"<plugin>my_robot/ToolForceTorqueSensor</plugin>{params}</hardware>"
            f'<sensor name="fts">{states}</sensor></ros2_control></robot>')


def test_tool_sensor_reads_the_tool_weight_with_seeded_noise() -> None:
    readings = []
    for _ in range(2):
        component = HardwareComponent(ToolForceTorqueSensor())
        info = parse_ros2_control(_sensor_urdf(params='<param name="tool_weight">5.0</param><param name="seed">3'
                                                      "</param>"))[0]
        assert component.initialize(info) is State.UNCONFIGURED
        states = {h.name: h for h in component.export_state_interfaces()}
        assert component.configure() is State.INACTIVE and component.activate() is State.ACTIVE
        series = []
        for k in range(200):
            component.read(k * 0.01, 0.01)
            series.append(states["fts/fz"].get_value())
        readings.append(series)
    assert readings[0] == readings[1]  # the same seed, the same numbers
    assert statistics.mean(readings[0]) == pytest.approx(-5.0, abs=0.02)
    assert 0.02 < statistics.stdev(readings[0]) < 0.1


@pytest.mark.parametrize("urdf", [_sensor_urdf("fx fy force_z"), _sensor_urdf(params='<param name="noise">loud</param>')],
                         ids=["unknown_interface", "noise_not_a_number"])
def test_tool_sensor_refuses_what_it_cannot_read(urdf: str) -> None:
    component = HardwareComponent(ToolForceTorqueSensor())
    assert component.initialize(parse_ros2_control(urdf)[0]) is not State.UNCONFIGURED


# --------------------------------------------------------------------------------------------- the package


def test_package_files_are_laid_out_as_the_demos() -> None:
    names = {p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*") if p.is_file()}
    assert {"package.xml", "CMakeLists.txt", "description/urdf/my_robot.urdf.xacro",
            "description/ros2_control/my_robot.ros2_control.xacro", "bringup/config/my_robot_controllers.yaml",
            "bringup/config/joint_limits.yaml"} <= names
    assert "install(\n  DIRECTORY description/urdf description/ros2_control" in (PACKAGE / "CMakeLists.txt").read_text()


@pytest.mark.parametrize(("args", "components"), [
    ({}, [("my_robot", "system", "my_robot/MyRobotHardware"),
          ("my_robot_tool_sensor", "sensor", "my_robot/ToolForceTorqueSensor")]),
    ({"use_mock_hardware": True}, [("my_robot", "system", "mock_components/GenericSystem"),
                                   ("my_robot_tool_sensor", "system", "mock_components/GenericSystem")]),
    ({"sim_mujoco": True}, [("my_robot", "system", "rrbot_workshop/MujocoSystem")]),
], ids=["own_hardware", "mock", "mujoco"])
def test_package_components_per_switch(args: dict, components: list) -> None:
    infos = parse_ros2_control(process_xacro(XACRO, **args))
    assert [(i.name, i.type, i.hardware_plugin_name) for i in infos] == components
    arm = infos[0]
    assert [(j.name, [c.name for c in j.command_interfaces]) for j in arm.joints] == [
        ("joint1", ["effort"]), ("joint2", ["effort"]), ("joint3", ["position"])]


def test_the_joint_limits_file_overrides_the_urdf_with_soft_limits_on_joint1_and_joint3() -> None:
    info = parse_ros2_control(process_xacro(XACRO, use_mock_hardware=True))[0]
    params = jl.load_joint_limits_yaml(PACKAGE / "bringup/config/joint_limits.yaml")
    joint1 = jl.get_joint_limits("joint1", params, info.limits["joint1"])
    assert (joint1.max_effort, joint1.max_velocity, joint1.max_position) == (8.0, 1.5, 2.5)
    assert info.limits["joint1"].max_effort == 20.0
    assert jl.get_soft_joint_limits("joint1", params).max_position == 2.0
    assert jl.get_soft_joint_limits("joint2", params) is None
    assert jl.get_soft_joint_limits("joint3", params).min_position == -1.4


def test_mock_bringup_moves_as_commanded() -> None:
    with rw.bringup("my_robot", "my_robot_controllers.yaml", xacro_args={"use_mock_hardware": True},
                    spawn=SPAWN, name="test_my_robot_mock") as system:
        system.publish("/effort_controller/commands", Float64MultiArray(data=[2.0, -1.5]))
        system.publish("/position_controller/commands", Float64MultiArray(data=[0.8]))
        system.spin(0.1)
        state = system.latest("/joint_states")
        assert state.name == ["joint1", "joint2", "joint3"]
        assert state.effort[:2] == [2.0, -1.5] and state.position[2] == 0.8
        assert system.latest("/tool_fts_broadcaster/wrench") is not None


def test_mujoco_bringup_moves_effort_joints_and_holds_the_position_joint() -> None:
    with rw.bringup("my_robot", "my_robot_controllers.yaml", xacro_args={"sim_mujoco": True}, spawn=SPAWN,
                    name="test_my_robot_mujoco") as system:
        system.publish("/effort_controller/commands", Float64MultiArray(data=[1.0, -0.5]))
        system.publish("/position_controller/commands", Float64MultiArray(data=[1.0]))
        system.spin(0.5)
        q = system.latest("/joint_states").position
        assert q[0] > 0.2 and q[1] < -0.2 and q[2] == pytest.approx(1.0, abs=0.01)
        wrench = system.latest("/tool_fts_broadcaster/wrench").wrench
        assert wrench.force.z == pytest.approx(-0.6 * 9.81, abs=0.05)  # the flange and the tool hang below it
