"""Joint limits as ros2_control computes them: URDF ``<limit>`` first, then the command interfaces' min/max.

The rules (``joint_limits_urdf.hpp`` and ``component_parser.cpp``):

* A URDF ``<limit>`` gives position limits to revolute and prismatic joints, ``angle_wraparound`` to continuous
  joints, and velocity and effort limits (absolute values) to all. Without ``<limit>`` nothing is set.
* A command interface's ``min``/``max`` can only tighten: position takes the intersection; velocity and effort
  take ``min(|min|, max)``; ``acceleration`` gives deceleration (min) and acceleration (max), each mirroring
  the other when only one is given; ``jerk`` takes ``max`` only.
* ``<limits enable="false"/>`` on an interface (or on its joint) switches that interface's limit off.
* Soft limits come from ``<safety_controller>``, clipped to the hard position limits.
"""

from __future__ import annotations

import logging
import math
import sys

from rrbot_workshop.description.info import InterfaceInfo, JointLimits, SoftJointLimits
from rrbot_workshop.description.urdf_model import UrdfJoint

__all__ = ["joint_limits_from_urdf", "update_interface_limits", "soft_limits_from_urdf", "compute_joint_limits"]

logger = logging.getLogger(__name__)

_DOUBLE_MAX = sys.float_info.max


def joint_limits_from_urdf(joint: UrdfJoint) -> JointLimits:
    """Limits from the URDF ``<limit>`` alone (``joint_limits::getJointLimits``)."""
    limits = JointLimits()
    if joint.limit is None:
        return limits
    limits.has_position_limits = joint.type in ("revolute", "prismatic")
    if limits.has_position_limits:
        limits.min_position = joint.limit.lower
        limits.max_position = joint.limit.upper
    elif joint.type == "continuous":
        limits.angle_wraparound = True
    limits.has_velocity_limits = True
    limits.max_velocity = abs(joint.limit.velocity)
    limits.has_acceleration_limits = False
    limits.has_effort_limits = True
    limits.max_effort = abs(joint.limit.effort)
    return limits


def _min_max(interface: InterfaceInfo, joint: str) -> tuple[float, float] | None:
    """The interface's (min, max) as floats (NaN where not given), or None if neither is given or one is bad."""
    if not interface.min and not interface.max:
        return None
    try:
        low = float(interface.min) if interface.min else math.nan
        high = float(interface.max) if interface.max else math.nan
    except ValueError:
        logger.warning(
            "joint '%s', command interface '%s': min '%s' / max '%s' are not numbers; these limits are skipped",
            joint, interface.name, interface.min, interface.max,
        )
        return None
    return low, high


def update_interface_limits(interfaces: list[InterfaceInfo], limits: JointLimits, joint: str = "") -> None:
    """Tighten ``limits`` in place with the min/max of a joint's command interfaces.

    Args:
        interfaces: The joint's command interfaces.
        limits: Limits from the URDF; updated in place.
        joint: Joint name, for log messages.
    """
    for itf in interfaces:
        values = _min_max(itf, joint)
        applies = itf.enable_limits and values is not None
        if itf.name == "position":
            keep = limits.has_position_limits and itf.enable_limits
            limits.min_position = limits.min_position if keep else -_DOUBLE_MAX
            limits.max_position = limits.max_position if keep else _DOUBLE_MAX
            if applies and values is not None:
                low, high = values
                if not math.isnan(low):
                    limits.min_position = max(low, limits.min_position)
                if not math.isnan(high):
                    limits.max_position = min(high, limits.max_position)
                limits.has_position_limits = True
            limits.has_position_limits = limits.has_position_limits and itf.enable_limits
        elif itf.name in ("velocity", "effort"):
            has = f"has_{itf.name}_limits"
            key = f"max_{itf.name}"
            current = getattr(limits, key) if getattr(limits, has) else _DOUBLE_MAX
            setattr(limits, key, current)
            if applies and values is not None:
                low, high = values
                bound = current if math.isnan(high) else high
                if not math.isnan(low):
                    bound = min(abs(low), bound)
                setattr(limits, key, min(bound, current))
                setattr(limits, has, True)
            setattr(limits, has, getattr(limits, has) and itf.enable_limits)
        elif itf.name == "acceleration":
            if values is None:
                continue
            decel, accel = values
            if math.isfinite(decel):
                limits.max_deceleration = abs(decel)
                if not math.isfinite(accel):
                    limits.max_acceleration = abs(decel)
                limits.has_deceleration_limits = itf.enable_limits
            if math.isfinite(accel):
                limits.max_acceleration = accel
                if not math.isfinite(limits.max_deceleration):
                    limits.max_deceleration = abs(accel)
                limits.has_acceleration_limits = itf.enable_limits
        elif itf.name == "jerk":
            if itf.min:
                logger.warning("joint '%s': the jerk interface takes only 'max'; 'min' is ignored", joint)
            if values is not None and itf.max and math.isfinite(values[1]):
                limits.max_jerk = abs(values[1])
                limits.has_jerk_limits = itf.enable_limits
        elif itf.min or itf.max:
            logger.warning(
                "joint '%s': min/max of command interface '%s' are not used for limits "
                "(limits come from position, velocity, effort, acceleration and jerk)", joint, itf.name,
            )


def soft_limits_from_urdf(joint: UrdfJoint, limits: JointLimits) -> SoftJointLimits | None:
    """Soft limits from ``<safety_controller>``, clipped to the hard position limits; None without one."""
    if joint.safety is None:
        return None
    soft = SoftJointLimits(
        min_position=joint.safety.soft_lower_limit,
        max_position=joint.safety.soft_upper_limit,
        k_position=joint.safety.k_position,
        k_velocity=joint.safety.k_velocity,
    )
    if limits.has_position_limits:
        soft.min_position = max(soft.min_position, limits.min_position)
        soft.max_position = min(soft.max_position, limits.max_position)
    return soft


def compute_joint_limits(joint: UrdfJoint, command_interfaces: list[InterfaceInfo]) -> JointLimits:
    """URDF limits tightened by the command interfaces (what ``HardwareInfo.limits[joint]`` holds)."""
    limits = joint_limits_from_urdf(joint)
    update_interface_limits(command_interfaces, limits, joint.name)
    return limits
