"""Tests of hardware.mujoco_model and hardware.mujoco_urdf: URDF -> MuJoCo model, one actuator per interface."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_model import ServoGains, build_model, classify_actuator

_INERTIAL = '<inertial><mass value="{m}"/><origin xyz="{xyz}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'

# A two-joint arm: world -> base (fixed) -> joint1 (z) -> link1 -> joint2 (y) -> link2 -> tool0 (fixed, offset).
_ARM = f"""<?xml version="1.0"?>
<robot name="arm">
  <link name="world"/>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <link name="base_link">{_INERTIAL.format(m=1, xyz="0 0 0.1")}
    <visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>
  <joint name="joint1" type="revolute"><parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="2" effort="50"/><dynamics damping="0.3"/></joint>
  <link name="link1">{_INERTIAL.format(m=1, xyz="0 0 0.2")}
    <visual><geometry><cylinder radius="0.05" length="0.4"/></geometry></visual></link>
  <joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" velocity="2" effort="0"/></joint>
  <link name="link2">{_INERTIAL.format(m=1, xyz="0.25 0 0")}
    <visual><geometry><mesh filename="package://rrbot/meshes/link2.dae"/></geometry></visual></link>
  <joint name="tool_joint" type="fixed"><parent link="link2"/><child link="tool0"/><origin xyz="0.5 0 0" rpy="0 1.5707963267948966 0"/></joint>
  <link name="tool0"/>
  <ros2_control name="arm" type="system"><hardware><plugin>rrbot_workshop/MujocoSystem</plugin></hardware></ros2_control>
</robot>
"""


def _build(**kwargs):  # type: ignore[no-untyped-def]
    interfaces = kwargs.pop("command_interfaces", {"joint1": ["position", "velocity", "effort"], "joint2": ["position"]})
    return build_model(_ARM, interfaces, kwargs.pop("sensors", {"fts": "tool0"}), **kwargs)


def test_one_actuator_per_command_interface_found_through_trnid() -> None:
    """Each (joint, interface) has an actuator on that joint, classified by its parameters."""
    sim = _build()
    model = sim.model
    assert model.nu == 4
    for joint, binding in sim.joints.items():
        for mode, actuator in binding.actuators.items():
            assert model.actuator_trnid[actuator, 0] == binding.joint_id
            saved = model.actuator_biasprm[actuator].copy()
            model.actuator_biasprm[actuator] = sim.nominal_biasprm[actuator]
            assert classify_actuator(model, actuator) == mode, joint
            model.actuator_biasprm[actuator] = saved
    assert set(sim.joints["joint1"].actuators) == {"position", "velocity", "effort"}


def test_actuators_start_disabled_and_enable_restores_gains() -> None:
    """All gains are zero after build; enable() puts the servo gains back."""
    sim = _build(gains={"joint2": ServoGains(position_kp=321.0, position_kv=12.0)})
    assert not np.any(sim.model.actuator_gainprm) and not np.any(sim.model.actuator_biasprm)
    actuator = sim.joints["joint2"].actuators["position"]
    sim.enable(actuator)
    assert sim.model.actuator_gainprm[actuator, 0] == 321.0
    assert list(sim.model.actuator_biasprm[actuator, :3]) == [0.0, -321.0, -12.0]


def test_effort_limit_becomes_force_range() -> None:
    """URDF effort 50 limits joint1's actuators to +-50; effort 0 leaves joint2 unlimited."""
    sim = _build()
    for actuator in sim.joints["joint1"].actuators.values():
        assert sim.model.actuator_forcelimited[actuator] and list(sim.model.actuator_forcerange[actuator]) == [-50, 50]
    assert not sim.model.actuator_forcelimited[sim.joints["joint2"].actuators["position"]]


def test_options_timestep_gravity_floor_and_radians() -> None:
    """Time step, gravity and the implicit-fast integrator are set; limits stay in radians; a floor exists."""
    sim = _build(timestep=0.002, gravity=(0.0, 0.0, -1.0))
    model = sim.model
    assert model.opt.timestep == 0.002 and list(model.opt.gravity) == [0, 0, -1]
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert list(model.jnt_range[sim.joints["joint1"].joint_id]) == [-3.0, 3.0]
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor") >= 0
    assert build_model(_ARM, {}, add_floor=False).model.ngeom == model.ngeom - 1


def test_fixed_frames_stay_bodies_and_visuals_are_kept() -> None:
    """tool0 (an empty link behind a fixed joint) is a body, and visual geoms (group 1) survive."""
    model = _build().model
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "tool0") >= 0
    assert np.count_nonzero(model.geom_group == 1) >= 2


def test_joint_dynamics_override_urdf() -> None:
    """damping/friction/armature parameters replace the URDF <dynamics> values."""
    sim = _build(joint_dynamics={"joint1": {"damping": 2.0, "friction": 0.5, "armature": 0.1}})
    dof = sim.joints["joint1"].dof_adr
    assert sim.model.dof_damping[dof] == 2.0 and sim.model.dof_frictionloss[dof] == 0.5
    assert sim.model.dof_armature[dof] == pytest.approx(0.1)
    assert _build().model.dof_damping[dof] == pytest.approx(0.3)


def test_force_torque_site_sits_at_the_frame() -> None:
    """The sensor site is at tool0's pose, 0.5 m along link2, and both sensors have sensordata slots."""
    sim = _build()
    model, data = sim.model, mujoco.MjData(sim.model)
    mujoco.mj_forward(model, data)
    ft = sim.force_torque_sensors["fts"]
    tool = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "tool0")
    assert np.allclose(data.site_xpos[ft.site_id], data.xpos[tool])
    assert np.allclose(data.site_xpos[ft.site_id], [0.5, 0.0, 0.6])
    assert ft.torque_adr == ft.force_adr + 3


def test_unknown_frame_is_rejected_with_the_valid_links() -> None:
    """A frame_id that is not a link raises DescriptionError listing the links."""
    with pytest.raises(DescriptionError, match="tool0"):
        _build(sensors={"fts": "tool9"})


@pytest.mark.parametrize(
    ("interfaces", "kwargs", "message"),
    [
        ({"joint9": ["position"]}, {}, "joint9"),
        ({"tool_joint": ["position"]}, {}, "tool_joint"),
        ({"joint1": ["acceleration"]}, {}, "acceleration"),
        ({"joint1": ["position"]}, {"timestep": 0.0}, "timestep"),
    ],
)
def test_build_model_rejects_bad_requests(interfaces: dict[str, list[str]], kwargs: dict[str, float], message: str) -> None:
    """Unknown or fixed joints, unsupported interfaces and a non-positive time step raise DescriptionError."""
    with pytest.raises(DescriptionError, match=message):
        build_model(_ARM, interfaces, **kwargs)


def test_moving_link_without_inertia_gives_a_hint() -> None:
    """MuJoCo's compile error is wrapped in a DescriptionError that mentions <inertial>."""
    urdf = _ARM.replace(_INERTIAL.format(m=1, xyz="0.25 0 0"), "")
    urdf = urdf.replace('<visual><geometry><mesh filename="package://rrbot/meshes/link2.dae"/></geometry></visual>', "")
    with pytest.raises(DescriptionError, match="inertial"):
        build_model(urdf, {"joint2": ["position"]})
