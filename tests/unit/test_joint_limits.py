"""Command limits (``enforce_command_limits``): the saturation and soft limits of Jazzy's joint_limits, on commands.

Behaviour after ros2_control's joint_limits tests (jazzy: test_joint_range_limiter.cpp, test_joint_soft_limiter.cpp):
position commands within range and reachable at the velocity limit, velocity commands within ±max and the range,
effort commands that do not push further out at a limit.
"""

from __future__ import annotations

import math

import pytest
import yaml

import rrbot_workshop as rw
from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.hardware_interface.joint_limits import (
    JointCommandLimiter,
    limit_effort,
    limit_position,
    limit_velocity,
)
from rrbot_workshop.msgs import Float64MultiArray

LIMITS = JointLimits(has_position_limits=True, min_position=-1.0, max_position=1.0, has_velocity_limits=True,
                     max_velocity=2.0, has_effort_limits=True, max_effort=5.0)


def test_position_is_clamped_to_the_range_and_to_one_velocity_step() -> None:
    assert limit_position(5.0, 0.99, LIMITS, 0.01) == 1.0
    assert limit_position(0.5, 0.0, LIMITS, 0.01) == pytest.approx(0.02)  # 2 rad/s for 10 ms
    assert limit_position(-0.5, 0.0, LIMITS, 0.1) == pytest.approx(-0.2)
    assert math.isnan(limit_position(math.nan, 0.0, LIMITS, 0.01))


def test_velocity_is_clamped_and_does_not_leave_the_range() -> None:
    assert limit_velocity(10.0, 0.0, math.nan, LIMITS, 0.01) == 2.0
    assert limit_velocity(1.5, 0.995, math.nan, LIMITS, 0.01) == pytest.approx(0.5)  # 5 mm left in 10 ms
    assert limit_velocity(1.0, 1.0, math.nan, LIMITS, 0.01) == 0.0  # at the upper limit: no further
    assert limit_velocity(-1.0, 1.0, math.nan, LIMITS, 0.01) == -1.0  # back into the range is fine
    with_acc = JointLimits(has_velocity_limits=True, max_velocity=2.0, has_acceleration_limits=True, max_acceleration=10.0)
    assert limit_velocity(2.0, 0.0, 0.0, with_acc, 0.01) == pytest.approx(0.1)


def test_effort_is_clamped_and_stops_pushing_out_at_a_limit() -> None:
    assert limit_effort(9.0, 0.0, 0.0, LIMITS) == 5.0
    assert limit_effort(3.0, 1.0, 0.0, LIMITS) == 0.0
    assert limit_effort(-3.0, 1.0, 0.0, LIMITS) == -3.0
    assert limit_effort(3.0, 0.0, 2.5, LIMITS) == 0.0  # beyond the velocity limit
    assert limit_effort(3.0, 0.0, 2.0, LIMITS) == 3.0  # at it: Jazzy cuts only beyond


def test_soft_limits_slow_the_joint_into_the_soft_range() -> None:
    soft = SoftJointLimits(min_position=-0.5, max_position=0.5, k_position=10.0)
    # 0.4 rad: at most 10 * (0.5 - 0.4) = 1 rad/s towards the soft upper limit
    assert limit_velocity(2.0, 0.4, math.nan, LIMITS, 0.01, soft) == pytest.approx(1.0)
    assert limit_position(1.0, 0.4, LIMITS, 0.01, soft) == pytest.approx(0.41)


def test_limiter_starts_from_the_joint_position() -> None:
    limiter = JointCommandLimiter("j", LIMITS)
    out = limiter.enforce({"position": 1.0}, {"position": 0.5}, 0.01)
    assert out["position"] == pytest.approx(0.52)
    assert limiter.enforce({"position": 1.0}, {"position": 0.5}, 0.01)["position"] == pytest.approx(0.54)


def _rrbot(enforce: bool) -> rw.System:
    config = yaml.safe_load((rw.description.descriptions_root() / "rrbot/config/rrbot_controllers.yaml").read_text())
    config["controller_manager"]["ros__parameters"]["enforce_command_limits"] = enforce
    return rw.bringup("rrbot", config, xacro_args={"use_mock_hardware": True},
                      spawn=["joint_state_broadcaster", "forward_position_controller"])


@pytest.mark.parametrize("enforce", [False, True])
def test_rrbot_with_and_without_enforcement(enforce: bool) -> None:
    """Jazzy's default (false) writes a command beyond joint2's 240 degree limit as it is; with enforcement the joints
    move at most 180 degrees/s and joint2 stops at its limit."""
    with _rrbot(enforce) as system:
        system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.5, 10.0]))
        system.spin(0.02)
        early = list(system.latest("/joint_states").position)
        system.spin(2.0)
        final = list(system.latest("/joint_states").position)
    if enforce:
        assert early[0] == pytest.approx(math.pi * 0.01, rel=1e-6)
        assert final == pytest.approx([0.5, math.radians(240)])
    else:
        assert early == [0.5, 10.0] and final == [0.5, 10.0]
