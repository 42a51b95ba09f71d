"""What the ``<ros2_control>`` parser produces: ``HardwareInfo`` and its parts.

Field names follow ``hardware_interface/hardware_info.hpp`` in snake_case. Values from the description
(min, max, initial_value, parameters) stay strings, as in ros2_control; components convert them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = [
    "InterfaceInfo",
    "ComponentInfo",
    "TransmissionJointInfo",
    "TransmissionActuatorInfo",
    "TransmissionInfo",
    "MimicJoint",
    "JointLimits",
    "SoftJointLimits",
    "HardwareInfo",
]


@dataclass
class InterfaceInfo:
    """One ``<command_interface>`` or ``<state_interface>``.

    Attributes:
        name: Interface name (``"position"``, ``"fx"``, ``"digital_out_1"``).
        min: ``<param name="min">`` text, or ``""``.
        max: ``<param name="max">`` text, or ``""``.
        initial_value: ``<param name="initial_value">`` text, or ``""``.
        data_type: ``data_type`` attribute, default ``"double"``.
        size: ``size`` attribute, default 1.
        enable_limits: False if ``<limits enable="false"/>`` is set on the interface or its joint.
        parameters: Every ``<param>`` of the interface by name (including min, max, initial_value).
    """

    name: str
    min: str = ""
    max: str = ""
    initial_value: str = ""
    data_type: str = "double"
    size: int = 1
    enable_limits: bool = True
    parameters: dict[str, str] = field(default_factory=dict)


@dataclass
class ComponentInfo:
    """A ``<joint>``, ``<sensor>`` or ``<gpio>`` element.

    Attributes:
        name: Element name (with any prefix applied by xacro).
        type: ``"joint"``, ``"sensor"`` or ``"gpio"``.
        is_mimic: ``"true"``, ``"false"`` or ``""`` (not given): the ``mimic`` attribute.
        command_interfaces: Declared command interfaces, in order.
        state_interfaces: Declared state interfaces, in order.
        parameters: ``<param>`` children by name.
        enable_limits: False if ``<limits enable="false"/>`` is set on the element.
    """

    name: str
    type: str
    is_mimic: str = ""
    command_interfaces: list[InterfaceInfo] = field(default_factory=list)
    state_interfaces: list[InterfaceInfo] = field(default_factory=list)
    parameters: dict[str, str] = field(default_factory=dict)
    enable_limits: bool = True


@dataclass
class TransmissionJointInfo:
    """A ``<joint>`` inside a ``<transmission>``."""

    name: str
    role: str = ""
    mechanical_reduction: float = 1.0
    offset: float = 0.0
    state_interfaces: list[str] = field(default_factory=list)
    command_interfaces: list[str] = field(default_factory=list)


@dataclass
class TransmissionActuatorInfo:
    """An ``<actuator>`` inside a ``<transmission>``."""

    name: str
    role: str = ""
    mechanical_reduction: float = 1.0
    offset: float = 0.0
    state_interfaces: list[str] = field(default_factory=list)
    command_interfaces: list[str] = field(default_factory=list)


@dataclass
class TransmissionInfo:
    """A ``<transmission>`` element of the ``<ros2_control>`` tag."""

    name: str
    type: str = ""
    plugin: str = ""
    joints: list[TransmissionJointInfo] = field(default_factory=list)
    actuators: list[TransmissionActuatorInfo] = field(default_factory=list)
    parameters: dict[str, str] = field(default_factory=dict)


@dataclass
class MimicJoint:
    """A joint that follows another: ``position = offset + multiplier * mimicked``.

    Attributes:
        joint_index: Index of the mimic joint in ``HardwareInfo.joints``.
        mimicked_joint_index: Index of the followed joint in ``HardwareInfo.joints``.
        multiplier: Factor from the URDF ``<mimic>`` (default 1).
        offset: Offset from the URDF ``<mimic>`` in [rad] or [m] (default 0).
    """

    joint_index: int
    mimicked_joint_index: int
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass
class JointLimits:
    """Hard limits of one joint (``joint_limits::JointLimits``); units [rad], [rad/s], [N m] or SI linear."""

    has_position_limits: bool = False
    min_position: float = float("nan")
    max_position: float = float("nan")
    has_velocity_limits: bool = False
    max_velocity: float = float("nan")
    has_acceleration_limits: bool = False
    max_acceleration: float = float("nan")
    has_deceleration_limits: bool = False
    max_deceleration: float = float("nan")
    has_jerk_limits: bool = False
    max_jerk: float = float("nan")
    has_effort_limits: bool = False
    max_effort: float = float("nan")
    angle_wraparound: bool = False


@dataclass
class SoftJointLimits:
    """Soft limits from the URDF ``<safety_controller>``."""

    min_position: float = float("nan")
    max_position: float = float("nan")
    k_position: float = float("nan")
    k_velocity: float = float("nan")


@dataclass
class HardwareInfo:
    """Everything one ``<ros2_control>`` tag says about one hardware component.

    Attributes:
        name: ``name`` attribute of ``<ros2_control>``.
        type: ``type`` attribute: ``"system"``, ``"actuator"`` or ``"sensor"``.
        group: ``<hardware><group>``, or ``""``.
        rw_rate: Read/write rate in [Hz]; 0 means the controller manager's rate.
        is_async: ``is_async`` attribute.
        thread_priority: Async thread priority.
        hardware_plugin_name: ``<hardware><plugin>`` text, or ``""`` when there is no ``<hardware>``.
        hardware_parameters: ``<hardware><param>`` values by name.
        joints: ``<joint>`` elements in order.
        sensors: ``<sensor>`` elements in order.
        gpios: ``<gpio>`` elements in order.
        transmissions: ``<transmission>`` elements in order.
        mimic_joints: Joints that follow another (from the URDF ``<mimic>``).
        limits: Hard limits per joint name, merged from the URDF and the interfaces' min/max.
        soft_limits: Soft limits per joint name.
        async_params: ``<properties><async .../>`` attributes, if given.
        original_xml: The ``<ros2_control>`` element's XML text.
        robot_description: The whole URDF text the tag was parsed from, or ``""``. Simulated hardware
            (``rrbot_workshop/MujocoSystem``) builds its physics model from it, as Gazebo's plugin does.
        mocked_plugin: The plugin ``bringup(..., mock_hardware=...)`` replaced by a mock, or ``""`` (not in Jazzy:
            the library's record of a substitution).
    """

    name: str
    type: str
    group: str = ""
    rw_rate: int = 0
    is_async: bool = False
    thread_priority: int = 50
    hardware_plugin_name: str = ""
    hardware_parameters: dict[str, str] = field(default_factory=dict)
    joints: list[ComponentInfo] = field(default_factory=list)
    sensors: list[ComponentInfo] = field(default_factory=list)
    gpios: list[ComponentInfo] = field(default_factory=list)
    transmissions: list[TransmissionInfo] = field(default_factory=list)
    mimic_joints: list[MimicJoint] = field(default_factory=list)
    limits: dict[str, JointLimits] = field(default_factory=dict)
    soft_limits: dict[str, SoftJointLimits] = field(default_factory=dict)
    async_params: dict[str, str] = field(default_factory=dict)
    original_xml: str = ""
    robot_description: str = ""
    mocked_plugin: str = ""
