"""Message dataclasses named like their ROS 2 counterparts.

Field names are the ROS field names, so ``msg.points[0].positions`` reads as it would in rclpy.
Times and durations (``stamp``, ``time_from_start``) are float seconds instead of
``builtin_interfaces`` structs. The ROS package of each type is in its docstring.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, cast

__all__ = [
    "Header",
    "MultiArrayDimension",
    "MultiArrayLayout",
    "Float64MultiArray",
    "Float64",
    "Bool",
    "String",
    "JointState",
    "InterfaceValue",
    "DynamicJointState",
    "DynamicInterfaceGroupValues",
    "JointTrajectoryPoint",
    "JointTrajectory",
    "JointTolerance",
    "JointTrajectoryControllerState",
    "JointControllerState",
    "JointJog",
    "MultiDOFCommand",
    "SingleDOFState",
    "MultiDOFStateStamped",
    "Vector3",
    "Quaternion",
    "Point",
    "Pose",
    "Twist",
    "TwistStamped",
    "Wrench",
    "WrenchStamped",
    "PoseWithCovariance",
    "TwistWithCovariance",
    "Odometry",
    "LifecycleState",
    "NamedLifecycleState",
    "ControllerManagerActivity",
    "SetBoolRequest",
    "SetBoolResponse",
    "ros_type_name",
    "message_problem",
]


def ros_type_name(msg_type: type) -> str:
    """The ROS 2 name of a message class, e.g. ``"sensor_msgs/msg/JointState"`` for :class:`JointState`.

    Read from the first ````pkg/msg/Name```` in the class docstring; a class without one gives its Python name.
    """
    doc = (msg_type.__doc__ or "").strip()
    if doc.startswith("``"):
        name = doc[2:].split("``", 1)[0]
        if name.count("/") == 2:
            return name
    return msg_type.__name__


def _nan() -> float:
    return math.nan


@dataclass
class Header:
    """``std_msgs/msg/Header``. ``stamp`` in [s]."""

    stamp: float = 0.0
    frame_id: str = ""


@dataclass
class MultiArrayDimension:
    """``std_msgs/msg/MultiArrayDimension``: one dimension of a multi-array's layout."""

    label: str = ""
    size: int = 0
    stride: int = 0


@dataclass
class MultiArrayLayout:
    """``std_msgs/msg/MultiArrayLayout``: how ``data`` is laid out; empty ``dim`` means one flat array."""

    dim: list[MultiArrayDimension] = field(default_factory=list)
    data_offset: int = 0


@dataclass
class Float64MultiArray:
    """``std_msgs/msg/Float64MultiArray``.

    ``layout`` is accepted as ROS 2 defines it (the original workshop's messages carry one) and, as in
    the forward command controllers of ros2_controllers, not used: ``data`` is read as one flat array.
    It is keyword-only here, so ``Float64MultiArray([0.7, 0.7])`` still fills ``data``.
    """

    layout: MultiArrayLayout = field(default_factory=MultiArrayLayout, kw_only=True)
    data: list[float] = field(default_factory=list)


@dataclass
class Float64:
    """``std_msgs/msg/Float64``."""

    data: float = 0.0


@dataclass
class Bool:
    """``std_msgs/msg/Bool``."""

    data: bool = False


@dataclass
class String:
    """``std_msgs/msg/String``."""

    data: str = ""


@dataclass
class JointState:
    """``sensor_msgs/msg/JointState``: positions [rad], velocities [rad/s], efforts [N m]."""

    header: Header = field(default_factory=Header)
    name: list[str] = field(default_factory=list)
    position: list[float] = field(default_factory=list)
    velocity: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)


@dataclass
class InterfaceValue:
    """``control_msgs/msg/InterfaceValue``: the interfaces of one prefix and their values."""

    interface_names: list[str] = field(default_factory=list)
    values: list[float] = field(default_factory=list)


@dataclass
class DynamicJointState:
    """``control_msgs/msg/DynamicJointState``: every interface of every joint, sensor and GPIO."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    interface_values: list[InterfaceValue] = field(default_factory=list)


@dataclass
class DynamicInterfaceGroupValues:
    """``control_msgs/msg/DynamicInterfaceGroupValues``: GPIO groups and their interface values."""

    header: Header = field(default_factory=Header)
    interface_groups: list[str] = field(default_factory=list)
    interface_values: list[InterfaceValue] = field(default_factory=list)


@dataclass
class JointTrajectoryPoint:
    """``trajectory_msgs/msg/JointTrajectoryPoint``. ``time_from_start`` in [s]."""

    positions: list[float] = field(default_factory=list)
    velocities: list[float] = field(default_factory=list)
    accelerations: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)
    time_from_start: float = 0.0

    def copy(self) -> JointTrajectoryPoint:
        """An independent copy (its lists are new), much cheaper than ``copy.deepcopy`` in a control cycle."""
        return JointTrajectoryPoint(list(self.positions), list(self.velocities), list(self.accelerations),
                                    list(self.effort), self.time_from_start)


@dataclass
class JointTrajectory:
    """``trajectory_msgs/msg/JointTrajectory``. ``header.stamp == 0`` means "start now"."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[JointTrajectoryPoint] = field(default_factory=list)


@dataclass
class JointTolerance:
    """``control_msgs/msg/JointTolerance``: 0 = use the default, -1 = no check."""

    name: str = ""
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass
class JointTrajectoryControllerState:
    """``control_msgs/msg/JointTrajectoryControllerState``."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    reference: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    feedback: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    output: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    desired: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    actual: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: list[str] = field(default_factory=list)


@dataclass
class JointControllerState:
    """``control_msgs/msg/JointControllerState`` (single-joint controller feedback)."""

    header: Header = field(default_factory=Header)
    set_point: float = 0.0
    process_value: float = 0.0
    process_value_dot: float = 0.0
    error: float = 0.0
    time_step: float = 0.0
    command: float = 0.0
    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp: float = 0.0
    antiwindup: bool = False


@dataclass
class JointJog:
    """``control_msgs/msg/JointJog``: displacements [rad] or velocities [rad/s] per joint; ``duration`` in [s]."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    displacements: list[float] = field(default_factory=list)
    velocities: list[float] = field(default_factory=list)
    duration: float = 0.0


@dataclass
class MultiDOFCommand:
    """``control_msgs/msg/MultiDOFCommand``: references per degree of freedom (and their derivatives)."""

    dof_names: list[str] = field(default_factory=list)
    values: list[float] = field(default_factory=list)
    values_dot: list[float] = field(default_factory=list)


@dataclass
class SingleDOFState:
    """``control_msgs/msg/SingleDOFState``."""

    name: str = ""
    reference: float = field(default_factory=_nan)
    feedback: float = field(default_factory=_nan)
    feedback_dot: float = field(default_factory=_nan)
    error: float = field(default_factory=_nan)
    error_dot: float = field(default_factory=_nan)
    time_step: float = 0.0
    output: float = field(default_factory=_nan)


@dataclass
class MultiDOFStateStamped:
    """``control_msgs/msg/MultiDOFStateStamped``."""

    header: Header = field(default_factory=Header)
    dof_states: list[SingleDOFState] = field(default_factory=list)


@dataclass
class Vector3:
    """``geometry_msgs/msg/Vector3``."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Point:
    """``geometry_msgs/msg/Point`` in [m]."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Quaternion:
    """``geometry_msgs/msg/Quaternion`` (x, y, z, w)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0


@dataclass
class Pose:
    """``geometry_msgs/msg/Pose``."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class Twist:
    """``geometry_msgs/msg/Twist``: linear [m/s], angular [rad/s]."""

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistStamped:
    """``geometry_msgs/msg/TwistStamped``."""

    header: Header = field(default_factory=Header)
    twist: Twist = field(default_factory=Twist)


@dataclass
class Wrench:
    """``geometry_msgs/msg/Wrench``: force [N], torque [N m]."""

    force: Vector3 = field(default_factory=Vector3)
    torque: Vector3 = field(default_factory=Vector3)


@dataclass
class WrenchStamped:
    """``geometry_msgs/msg/WrenchStamped``."""

    header: Header = field(default_factory=Header)
    wrench: Wrench = field(default_factory=Wrench)


@dataclass
class PoseWithCovariance:
    """``geometry_msgs/msg/PoseWithCovariance`` (row-major 6x6 covariance)."""

    pose: Pose = field(default_factory=Pose)
    covariance: list[float] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class TwistWithCovariance:
    """``geometry_msgs/msg/TwistWithCovariance``."""

    twist: Twist = field(default_factory=Twist)
    covariance: list[float] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Odometry:
    """``nav_msgs/msg/Odometry``."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
class LifecycleState:
    """``lifecycle_msgs/msg/State``: ``id`` (0 unknown, 1 unconfigured, 2 inactive, 3 active, 4 finalized) and
    ``label``."""

    id: int = 0
    label: str = "unknown"


@dataclass
class NamedLifecycleState:
    """``controller_manager_msgs/msg/NamedLifecycleState``: a controller's or hardware component's state."""

    name: str = ""
    state: LifecycleState = field(default_factory=LifecycleState)


@dataclass
class ControllerManagerActivity:
    """``controller_manager_msgs/msg/ControllerManagerActivity``: every controller's and hardware component's
    state, published on ``/controller_manager/activity`` each time one of them changes."""

    header: Header = field(default_factory=Header)
    controllers: list[NamedLifecycleState] = field(default_factory=list)
    hardware_components: list[NamedLifecycleState] = field(default_factory=list)


@dataclass
class SetBoolRequest:
    """``std_srvs/srv/SetBool`` request."""

    data: bool = False


@dataclass
class SetBoolResponse:
    """``std_srvs/srv/SetBool`` response."""

    success: bool = False
    message: str = ""


# --------------------------------------------------------------------------- field types, as rclpy checks them
_SCALARS: dict[str, tuple[tuple[type, ...], str]] = {
    "float": ((numbers.Real,), "a number"),
    "int": ((numbers.Integral,), "a whole number"),
    "bool": ((bool, numbers.Integral), "a bool"),
    "str": ((str,), "a string"),
}


@functools.cache
def _field_types(msg_type: type) -> tuple[tuple[str, str], ...]:
    """``(field, annotation text)`` of a message dataclass (annotations are strings under postponed evaluation)."""
    return tuple((f.name, str(f.type)) for f in dataclasses.fields(msg_type))


def _value_problem(value: Any, kind: str, path: str) -> str | None:
    scalar = _SCALARS.get(kind)
    if scalar is not None:
        types, what = scalar
        if not isinstance(value, types) or (kind == "float" and isinstance(value, complex)):
            return f"field '{path}' must be {what}, got {type(value).__name__} {_short(value)}"
        return None
    nested = globals().get(kind)
    if isinstance(nested, type) and dataclasses.is_dataclass(nested):
        if not isinstance(value, nested):
            return f"field '{path}' must be a {kind} message, got {type(value).__name__} {_short(value)}"
        return message_problem(value, path)
    return None


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def message_problem(msg: Any, path: str = "") -> str | None:
    """What makes ``msg`` a message rclpy would refuse to build, or None: a field of the wrong type (None, a string
    for a number, a number for a list, a list holding a wrong item), named by its path (``points[0].positions``).

    ROS checks field types when a message is built or published; here messages are plain dataclasses, so the bus
    checks them when they are published from outside a node. Numbers may be ints or floats (numpy's too), and lists
    may be tuples or numpy arrays.
    """
    if not dataclasses.is_dataclass(msg) or isinstance(msg, type):
        return None
    for name, annotation in _field_types(type(msg)):
        value: Any = getattr(msg, name, None)
        where = f"{path}.{name}" if path else name
        if annotation.startswith("list[") and annotation.endswith("]"):
            kind = annotation[5:-1]
            if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") or not hasattr(value, "__iter__"):
                return f"field '{where}' must be a list, got {type(value).__name__} {_short(value)}"
            for index, item in enumerate(cast(Iterable[Any], value)):
                problem = _value_problem(item, kind, f"{where}[{index}]")
                if problem:
                    return problem
        else:
            problem = _value_problem(value, annotation, where)
            if problem:
                return problem
    return None
