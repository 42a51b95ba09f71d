"""The DiffBot, RRBot-on-DiffBot and two-RRBot descriptions: they parse, bring up, and move as specified."""

from __future__ import annotations

import math

import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.msgs import (
    Float64MultiArray,
    JointTrajectory,
    JointTrajectoryPoint,
    Twist,
    TwistStamped,
    Vector3,
)

ROOT = rw.description.descriptions_root()


def _drive(system, controller: str, v: float, w: float, seconds: float) -> None:  # noqa: ANN001
    """Send the twist every cycle (the diff drive stops after cmd_vel_timeout without one)."""
    for _ in range(system.clock.cycles_for(seconds)):
        system.publish(f"/{controller}/cmd_vel", TwistStamped(twist=Twist(linear=Vector3(x=v), angular=Vector3(z=w))))
        system.spin_cycles(1)


def test_diffbot_drives_a_circle_of_radius_v_over_omega() -> None:
    """0.5 m/s and 0.5 rad/s: a circle of 1 m radius; after a full turn the odometry is back near the start."""
    with rw.bringup(description="diffbot", controllers="diffbot_controllers.yaml",
                    spawn=["joint_state_broadcaster", "diffbot_base_controller"]) as system:
        _drive(system, "diffbot_base_controller", 0.5, 0.5, 1.0)
        points = []
        for _ in range(40):
            _drive(system, "diffbot_base_controller", 0.5, 0.5, 0.25)
            p = system.latest("/diffbot_base_controller/odom").pose.pose.position
            points.append((p.x, p.y))
        # every point after the ramp lies on the circle through the start with centre (0, 1)
        radii = [math.hypot(x, y - 1.0) for x, y in points]
        assert max(abs(r - 1.0) for r in radii) < 0.05, radii


def test_rrbot_on_diffbot_has_two_components_and_both_move_independently() -> None:
    with rw.bringup(description="rrbot_on_diffbot", controllers="rrbot_on_diffbot_controllers.yaml",
                    spawn=["joint_state_broadcaster", "diffbot_base_controller", "joint_trajectory_controller"]) as system:
        components = {c.name: c.plugin_name for c in system.controller_manager.list_hardware_components()}
        assert components == {"base_DiffBot": "mock_components/GenericSystem",
                              "arm_RRBot": "mock_components/GenericSystem"}
        goal = JointTrajectory(joint_names=["arm_joint1", "arm_joint2"],
                               points=[JointTrajectoryPoint(positions=[0.8, -0.4], time_from_start=2.0)])
        system.publish("/joint_trajectory_controller/joint_trajectory", goal)
        _drive(system, "diffbot_base_controller", 0.4, 0.0, 3.0)
        state = system.latest("/joint_states")
        arm = dict(zip(state.name, state.position, strict=True))
        assert arm["arm_joint1"] == pytest.approx(0.8, abs=1e-3) and arm["arm_joint2"] == pytest.approx(-0.4, abs=1e-3)
        odom = system.latest("/diffbot_base_controller/odom").pose.pose.position
        assert odom.x > 0.9 and abs(odom.y) < 1e-6  # straight ahead, ~0.4 m/s for 3 s after the ramp
        # stopping the base leaves the arm's controller running, and the other way round
        system.controller_manager.switch_controllers(deactivate=["diffbot_base_controller"])
        states = {c.name: c.state for c in system.controller_manager.list_controllers()}
        assert states["joint_trajectory_controller"] == "active" and states["diffbot_base_controller"] == "inactive"


def test_two_rrbots_are_controlled_independently() -> None:
    with rw.bringup(description="multi_rrbot", controllers="multi_rrbot_controllers.yaml",
                    spawn=["joint_state_broadcaster", "r1_forward_position_controller",
                           "r2_forward_position_controller"]) as system:
        system.publish("/r1_forward_position_controller/commands", Float64MultiArray(data=[0.5, 0.25]))
        system.spin(0.05)
        system.publish("/r2_forward_position_controller/commands", Float64MultiArray(data=[-0.3, 0.1]))
        system.spin(0.05)
        joints = dict(zip(system.latest("/joint_states").name, system.latest("/joint_states").position, strict=True))
        assert joints == {"r1_joint1": 0.5, "r1_joint2": 0.25, "r2_joint1": -0.3, "r2_joint2": 0.1}
        names = {c.name for c in system.controller_manager.list_hardware_components()}
        assert names == {"r1_rrbot", "r2_rrbot"}
        interfaces = [i.name for i in system.controller_manager.list_hardware_interfaces().state_interfaces]
        assert "r1_tcp_fts_sensor/fx" in interfaces and "r2_flange_gpios/digital_in_1" in interfaces


def test_two_rrbots_with_one_prefix_collide_with_a_clear_error() -> None:
    path = ROOT / "multi_rrbot" / "urdf" / "multi_rrbot.urdf.xacro"
    with pytest.raises(DescriptionError, match="'r1_base_link' is declared twice"):
        rw.bringup(description=path, xacro_args={"prefix_2": "r1_"})
