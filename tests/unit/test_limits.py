"""Joint limits: URDF <limit> tightened by command-interface min/max, as ros2_control computes them."""

from __future__ import annotations

import sys

import pytest

from rrbot_workshop.description.info import InterfaceInfo
from rrbot_workshop.description.limits import compute_joint_limits, joint_limits_from_urdf, soft_limits_from_urdf
from rrbot_workshop.description.urdf_model import UrdfJoint, UrdfLimit, UrdfSafety

REVOLUTE = UrdfJoint("j", "revolute", "a", "b", limit=UrdfLimit(lower=-2.0, upper=2.0, effort=-10.0, velocity=-3.0))


def test_urdf_limit_gives_position_velocity_and_absolute_effort() -> None:
    """Revolute: position limits; velocity and effort as absolute values; no acceleration limit."""
    limits = joint_limits_from_urdf(REVOLUTE)
    assert limits.has_position_limits and (limits.min_position, limits.max_position) == (-2.0, 2.0)
    assert (limits.max_velocity, limits.max_effort) == (3.0, 10.0)
    assert not limits.has_acceleration_limits and not limits.angle_wraparound


def test_joint_without_urdf_limit_has_no_limits() -> None:
    """No <limit>: nothing is set (not even angle_wraparound)."""
    limits = joint_limits_from_urdf(UrdfJoint("j", "continuous", "a", "b"))
    assert not (limits.has_position_limits or limits.has_velocity_limits or limits.angle_wraparound)


def test_interfaces_only_tighten() -> None:
    """Position intersects; velocity/effort take min(|min|, max) but never exceed the URDF value."""
    limits = compute_joint_limits(REVOLUTE, [
        InterfaceInfo("position", min="-5", max="1"),
        InterfaceInfo("velocity", min="-0.5", max="7"),
        InterfaceInfo("effort", max="20"),
    ])
    assert (limits.min_position, limits.max_position) == (-2.0, 1.0)
    assert limits.max_velocity == 0.5 and limits.max_effort == 10.0


def test_acceleration_min_and_max_mirror_each_other() -> None:
    """Only ``max`` given: deceleration mirrors it; only ``min``: acceleration mirrors |min|."""
    only_max = compute_joint_limits(REVOLUTE, [InterfaceInfo("acceleration", max="4")])
    assert only_max.has_acceleration_limits and not only_max.has_deceleration_limits
    assert (only_max.max_acceleration, only_max.max_deceleration) == (4.0, 4.0)
    only_min = compute_joint_limits(REVOLUTE, [InterfaceInfo("acceleration", min="-6")])
    assert only_min.has_deceleration_limits and not only_min.has_acceleration_limits
    assert (only_min.max_acceleration, only_min.max_deceleration) == (6.0, 6.0)


def test_jerk_uses_max_only() -> None:
    """``jerk`` limits come from ``max``; ``min`` alone gives none."""
    assert compute_joint_limits(REVOLUTE, [InterfaceInfo("jerk", max="-9")]).max_jerk == 9.0
    assert not compute_joint_limits(REVOLUTE, [InterfaceInfo("jerk", min="-9")]).has_jerk_limits


def test_disabled_interface_drops_its_limit() -> None:
    """enable_limits=False on the position interface removes position limits (bounds become +-DBL_MAX)."""
    limits = compute_joint_limits(REVOLUTE, [InterfaceInfo("position", min="-1", max="1", enable_limits=False)])
    assert not limits.has_position_limits
    assert (limits.min_position, limits.max_position) == (-sys.float_info.max, sys.float_info.max)


def test_non_numeric_min_max_are_skipped_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    """A min/max that is not a number leaves the URDF limit and logs a warning."""
    limits = compute_joint_limits(REVOLUTE, [InterfaceInfo("velocity", min="-1", max="fast")])
    assert limits.max_velocity == 3.0
    assert "not numbers" in caplog.text


def test_soft_limits_are_clipped_to_hard_limits() -> None:
    """<safety_controller> bounds outside the hard limits are clipped."""
    joint = UrdfJoint("j", "revolute", "a", "b", limit=REVOLUTE.limit,
                      safety=UrdfSafety(soft_lower_limit=-5.0, soft_upper_limit=1.5, k_position=3.0, k_velocity=4.0))
    soft = soft_limits_from_urdf(joint, joint_limits_from_urdf(joint))
    assert soft is not None
    assert (soft.min_position, soft.max_position, soft.k_position, soft.k_velocity) == (-2.0, 1.5, 3.0, 4.0)
    assert soft_limits_from_urdf(REVOLUTE, joint_limits_from_urdf(REVOLUTE)) is None
