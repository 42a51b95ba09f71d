"""Tests of rrbot_workshop.hardware.mujoco_config: HardwareInfo -> checked MuJoCo build request."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_config import simulation_request
from rrbot_workshop.hardware.mujoco_model import ServoGains

_URDF = '<robot name="r"><link name="world"/></robot>'


def _info(**hardware: str) -> HardwareInfo:
    joint = ComponentInfo(
        name="joint1",
        type="joint",
        command_interfaces=[InterfaceInfo("position"), InterfaceInfo("effort")],
        state_interfaces=[InterfaceInfo("position"), InterfaceInfo("velocity")],
        parameters={"damping": "0.5", "position_kp": "250"},
    )
    sensor = ComponentInfo(
        name="fts", type="sensor", state_interfaces=[InterfaceInfo("fz")], parameters={"frame_id": "tool0"}
    )
    return HardwareInfo(
        name="sim", type="system", hardware_parameters=dict(hardware), joints=[joint], sensors=[sensor],
        robot_description=_URDF,
    )


def test_request_collects_interfaces_gains_and_parameters() -> None:
    """Joint params override hardware-wide gains; timestep, gravity vector and floor are read."""
    request = simulation_request(_info(timestep="0.002", position_kv="7", gravity="0 0 -1.62", add_floor="false"))
    assert request.urdf == _URDF and request.timestep == 0.002
    assert request.command_interfaces == {"joint1": ["position", "effort"]}
    assert request.force_torque_sensors == {"fts": "tool0"}
    assert request.gains["joint1"] == ServoGains(position_kp=250.0, position_kv=7.0, velocity_kv=100.0)
    assert request.joint_dynamics == {"joint1": {"damping": 0.5}}
    assert request.gravity == (0.0, 0.0, -1.62) and request.add_floor is False


def test_gravity_false_switches_it_off() -> None:
    """gravity=false gives a zero gravity vector."""
    assert simulation_request(_info(gravity="false")).gravity == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda i: setattr(i, "robot_description", ""), "robot_description"),
        (lambda i: i.hardware_parameters.update(timestep="0"), "timestep"),
        (lambda i: i.hardware_parameters.update(position_kp="-1"), "position_kp"),
        (lambda i: i.hardware_parameters.update(add_floor="maybe"), "add_floor"),
        (lambda i: i.hardware_parameters.update(gravity="1 2"), "gravity"),
        (lambda i: i.joints[0].parameters.update(friction="lots"), "friction"),
        (lambda i: i.joints[0].state_interfaces.append(InterfaceInfo("jerk")), "jerk"),
        (lambda i: i.joints[0].command_interfaces.append(InterfaceInfo("current")), "current"),
        (lambda i: i.sensors[0].parameters.clear(), "frame_id"),
        (lambda i: i.sensors[0].state_interfaces.append(InterfaceInfo("temperature")), "temperature"),
    ],
)
def test_what_cannot_be_simulated_is_rejected(change: Callable[[HardwareInfo], None], match: str) -> None:
    """Each bad description raises DescriptionError naming the parameter or interface."""
    info = _info()
    change(info)
    with pytest.raises(DescriptionError, match=match):
        simulation_request(info)
