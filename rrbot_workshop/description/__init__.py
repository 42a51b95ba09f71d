"""Robot description: xacro processing and the ``<ros2_control>`` parser."""

from rrbot_workshop.description.info import (
    ComponentInfo,
    HardwareInfo,
    InterfaceInfo,
    JointLimits,
    MimicJoint,
    SoftJointLimits,
    TransmissionInfo,
)
from rrbot_workshop.description.parser import parse_ros2_control
from rrbot_workshop.description.xacro import descriptions_root, process_xacro, resolve_package_uri

__all__ = [
    "process_xacro",
    "descriptions_root",
    "resolve_package_uri",
    "parse_ros2_control",
    "HardwareInfo",
    "ComponentInfo",
    "InterfaceInfo",
    "JointLimits",
    "SoftJointLimits",
    "MimicJoint",
    "TransmissionInfo",
]
