"""The RRBot description (descriptions/rrbot): xacro arguments, <ros2_control> tag, kinematics, MuJoCo model."""

from __future__ import annotations

import io
import math
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import mujoco
import numpy as np
import pytest
import yaml
import yourdfpy

from rrbot_workshop.description import descriptions_root, parse_ros2_control, process_xacro

RRBOT = descriptions_root() / "rrbot"
XACRO = RRBOT / "urdf" / "rrbot.urdf.xacro"

LINKS = ["base_link", "link1", "link2", "tool0", "base", "flange"]
JOINTS = ["base_joint", "joint1", "joint2", "link2-tool0", "base_link-base_joint", "tool0-flange_joint"]
JOINT_STATES = ["position", "velocity", "acceleration", "effort"]
FTS_STATES = ["fx", "fy", "fz", "tx", "ty", "tz"]


@pytest.fixture(scope="module")
def urdf() -> str:
    """RRBot with default arguments."""
    return process_xacro(XACRO)


def _names(urdf: str, tag: str) -> list[str]:
    return [e.get("name", "") for e in ET.fromstring(urdf.lstrip()).findall(tag)]


def _mujoco_model(urdf: str) -> mujoco.MjModel:
    extension = '<mujoco><compiler discardvisual="false" fusestatic="false"/></mujoco>'
    return mujoco.MjModel.from_xml_string(urdf.replace('<robot name="rrbot">', f'<robot name="rrbot">{extension}', 1))


def test_default_arguments_give_links_and_joints_of_task_1(urdf: str) -> None:
    """World, pedestal, two links, three frames; two revolute joints and four fixed ones."""
    assert sorted(_names(urdf, "link")) == sorted(["world", *LINKS])
    assert sorted(_names(urdf, "joint")) == sorted(JOINTS)


def test_joint_limits_are_those_of_the_workshop(urdf: str) -> None:
    """joint1 +-380 deg, joint2 -60..240 deg, 180 deg/s, 1000 N m; both with small damping and friction."""
    joints = {j.get("name"): j for j in ET.fromstring(urdf.lstrip()).findall("joint")}
    expected = {"joint1": (-380, 380), "joint2": (-60, 240)}
    for name, (lower, upper) in expected.items():
        limit = joints[name].find("limit")
        assert limit is not None
        assert float(limit.get("lower", "nan")) == pytest.approx(math.radians(lower))
        assert float(limit.get("upper", "nan")) == pytest.approx(math.radians(upper))
        assert float(limit.get("velocity", "nan")) == pytest.approx(math.pi)
        assert float(limit.get("effort", "nan")) == 1000.0
        dynamics = joints[name].find("dynamics")
        assert dynamics is not None and 0 < float(dynamics.get("damping", "0")) <= 1
        assert 0 < float(dynamics.get("friction", "0")) <= 1


def test_mock_hardware_by_default(urdf: str) -> None:
    """One system ``rrbot`` on GenericSystem: 2 joints, the FTS sensor and the flange GPIOs."""
    (info,) = parse_ros2_control(urdf)
    assert (info.name, info.type, info.hardware_plugin_name) == ("rrbot", "system", "mock_components/GenericSystem")
    assert info.hardware_parameters == {"mock_sensor_commands": "false", "calculate_dynamics": "false"}
    assert [j.name for j in info.joints] == ["joint1", "joint2"]
    for joint in info.joints:
        assert [i.name for i in joint.command_interfaces] == ["position", "velocity"]
        assert [i.name for i in joint.state_interfaces] == JOINT_STATES
        initial = {i.name: i.initial_value for i in joint.state_interfaces}
        assert initial == {"position": "0.0", "velocity": "", "acceleration": "", "effort": "0.0"}
    (sensor,) = info.sensors
    assert sensor.name == "tcp_fts_sensor" and sensor.parameters == {"frame_id": "tool0"}
    assert [i.name for i in sensor.state_interfaces] == FTS_STATES
    (gpio,) = info.gpios
    assert gpio.name == "flange_gpios"
    assert [i.name for i in gpio.state_interfaces] == ["digital_in_1", "digital_in_2", "digital_out_1",
                                                        "digital_out_2"]
    assert [i.name for i in gpio.command_interfaces] == ["digital_out_1", "digital_out_2"]
    assert all(i.data_type == "double" for i in gpio.state_interfaces + gpio.command_interfaces)


def test_mock_parameters_follow_the_arguments() -> None:
    """``mock_sensor_commands`` and ``calculate_dynamics`` reach GenericSystem's parameters."""
    (info,) = parse_ros2_control(process_xacro(XACRO, mock_sensor_commands=True, calculate_dynamics=True))
    assert info.hardware_parameters == {"mock_sensor_commands": "true", "calculate_dynamics": "true"}


def test_sim_mujoco_selects_mujoco_system_with_effort_commands() -> None:
    """``sim_mujoco`` wins over mock hardware and adds an effort command interface per joint."""
    (info,) = parse_ros2_control(process_xacro(XACRO, sim_mujoco=True, use_mock_hardware=True))
    assert info.hardware_plugin_name == "rrbot_workshop/MujocoSystem"
    for joint in info.joints:
        assert [i.name for i in joint.command_interfaces] == ["position", "velocity", "effort"]


def test_no_mock_no_sim_selects_the_task_7_driver() -> None:
    """Without mock hardware or simulation the RRBot driver plugin is used, with no mock parameters."""
    (info,) = parse_ros2_control(process_xacro(XACRO, use_mock_hardware=False))
    assert info.hardware_plugin_name == "controlko_hardware_interface/RRBotHardwareInterface"
    assert info.hardware_parameters == {}


def test_prefix_applies_to_every_name() -> None:
    """With prefix r1_, every link and joint (except world), the sensor, GPIO, tag and frame_id are prefixed."""
    urdf = process_xacro(XACRO, prefix="r1_")
    assert sorted(_names(urdf, "link")) == sorted(["world", *(f"r1_{n}" for n in LINKS)])
    assert sorted(_names(urdf, "joint")) == sorted(f"r1_{n}" for n in JOINTS)
    (info,) = parse_ros2_control(urdf)
    assert info.name == "r1_rrbot"
    assert [j.name for j in info.joints] == ["r1_joint1", "r1_joint2"]
    assert info.sensors[0].name == "r1_tcp_fts_sensor" and info.sensors[0].parameters["frame_id"] == "r1_tool0"
    assert info.gpios[0].name == "r1_flange_gpios"


def test_two_prefixed_robots_in_one_urdf_do_not_collide(tmp_path: Path) -> None:
    """Two RRBots (r1_, r2_) in one URDF: unique link, joint, component and interface names."""
    composed = tmp_path / "two.urdf.xacro"
    composed.write_text("""<?xml version="1.0"?>
<robot name="two" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find rrbot)/urdf/common.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.xacro"/>
  <xacro:include filename="$(find rrbot)/urdf/rrbot/rrbot_macro.ros2_control.xacro"/>
  <link name="world"/>
  <xacro:rrbot prefix="r1_" parent="world"><origin xyz="0 -1 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot prefix="r2_" parent="world"><origin xyz="0 1 0" rpy="0 0 0"/></xacro:rrbot>
  <xacro:rrbot_ros2_control name="rrbot" prefix="r1_"/>
  <xacro:rrbot_ros2_control name="rrbot" prefix="r2_"/>
</robot>""")
    urdf = process_xacro(composed)
    for tag in ("link", "joint", "material"):
        duplicates = [n for n, count in Counter(_names(urdf, tag)).items() if count > 1]
        assert duplicates == [], f"duplicate {tag} names: {duplicates}"
    infos = parse_ros2_control(urdf)
    assert [i.name for i in infos] == ["r1_rrbot", "r2_rrbot"]
    interfaces = [f"{c.name}/{itf.name}" for info in infos for c in info.joints + info.sensors + info.gpios
                  for itf in c.state_interfaces]
    assert len(interfaces) == len(set(interfaces)) == 2 * (2 * 4 + 6 + 4)


def test_forward_kinematics_of_tool0(urdf: str) -> None:
    """tool0 is at (-0.6, 0, 0.3 + 0.5) at zero; at joint2 = pi/2 the arm points up: (0, 0, 0.3 + 0.5 + 0.6)."""
    robot = yourdfpy.URDF.load(io.StringIO(urdf), load_meshes=False, build_scene_graph=True)
    assert robot.actuated_joint_names == ["joint1", "joint2"]
    robot.update_cfg([0.0, 0.0])
    np.testing.assert_allclose(robot.get_transform("tool0", "world")[:3, 3], [-0.6, 0.0, 0.8], atol=1e-9)
    robot.update_cfg([0.0, math.pi / 2])
    np.testing.assert_allclose(robot.get_transform("tool0", "world")[:3, 3], [0.0, 0.0, 1.4], atol=1e-9)
    robot.update_cfg([math.pi / 2, 0.0])
    np.testing.assert_allclose(robot.get_transform("flange", "world")[:3, 3], [0.0, -0.6, 0.8], atol=1e-9)


def test_mujoco_compiles_the_urdf_with_plausible_inertias(urdf: str) -> None:
    """MuJoCo accepts the URDF; moving links weigh 2 kg and 1 kg; joint ranges, damping and friction carry over."""
    model = _mujoco_model(urdf)
    assert model.njnt == 2 and model.nv == 2
    masses = {model.body(i).name: float(model.body_mass[i]) for i in range(model.nbody)}
    assert masses["link1"] == pytest.approx(2.0) and masses["link2"] == pytest.approx(1.0)
    for body in ("link1", "link2"):
        inertia = model.body_inertia[model.body(body).id]
        assert np.all(inertia > 0)
        assert inertia[0] + inertia[1] >= inertia[2] - 1e-12  # triangle inequality of principal moments
    np.testing.assert_allclose(model.jnt_range[1], [math.radians(-60), math.radians(240)])
    np.testing.assert_allclose(model.dof_damping, [0.1, 0.1])
    np.testing.assert_allclose(model.dof_frictionloss, [0.05, 0.05])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.xpos[model.body("tool0").id], [-0.6, 0.0, 0.8], atol=1e-9)


def test_controllers_yaml_has_the_three_controllers() -> None:
    """update_rate 100; JSB, forward position controller and JTC with the workshop's parameters."""
    config = yaml.safe_load((RRBOT / "config" / "rrbot_controllers.yaml").read_text())
    manager = config["controller_manager"]["ros__parameters"]
    assert manager["update_rate"] == 100
    assert {name: spec["type"] for name, spec in manager.items() if isinstance(spec, dict)} == {
        "joint_state_broadcaster": "joint_state_broadcaster/JointStateBroadcaster",
        "forward_position_controller": "forward_command_controller/ForwardCommandController",
        "joint_trajectory_controller": "joint_trajectory_controller/JointTrajectoryController",
    }
    forward = config["forward_position_controller"]["ros__parameters"]
    assert forward == {"joints": ["joint1", "joint2"], "interface_name": "position"}
    jtc = config["joint_trajectory_controller"]["ros__parameters"]
    assert jtc == {
        "joints": ["joint1", "joint2"], "command_interfaces": ["position"],
        "state_interfaces": ["position", "velocity"], "allow_partial_joints_goal": False,
        "constraints": {"stopped_velocity_tolerance": 0.01, "goal_time": 0.0},
    }
