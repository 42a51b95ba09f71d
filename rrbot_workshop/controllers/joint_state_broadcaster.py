"""``joint_state_broadcaster/JointStateBroadcaster``: state interfaces -> ``/joint_states``.

The broadcaster claims no command interface. It reads state interfaces (all of them, unless both
``joints`` and ``interfaces`` are given) and publishes two messages every cycle:

* ``/joint_states`` (``sensor_msgs/JointState``): one entry per joint that has a ``position``,
  ``velocity`` or ``effort`` interface (after ``map_interface_to_joint_state`` renames custom names);
  a field the joint does not have is NaN;
* ``/dynamic_joint_states`` (``control_msgs/DynamicJointState``): every interface of every prefix
  (joints, sensors, GPIOs), under the same names: an interface that ``map_interface_to_joint_state`` maps
  is listed as ``position``, ``velocity`` or ``effort`` here too, as Jazzy does.

Rules follow the Jazzy release (ros2_controllers 4.x):

* ``joints`` or ``interfaces`` empty -> every state interface (``ALL``).
* With ``use_urdf_to_filter`` (default) and a parsable robot description, ``/joint_states`` keeps only
  the URDF's non-fixed joints, in alphabetical order (Jazzy walks urdfdom's ``std::map`` of joints).
  Without a description the names follow the order of the state interfaces.
* ``extra_joints`` are appended with position, velocity and effort 0.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from typing import Any

from rrbot_workshop.controller_interface.base import (
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.hardware_interface.handles import value_snapshot
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.topics import Publisher
from rrbot_workshop.msgs import DynamicJointState, Header, InterfaceValue, JointState

__all__ = ["JointStateBroadcaster", "urdf_movable_joints"]

_JOINT_STATE_FIELDS = ("position", "velocity", "effort")


def urdf_movable_joints(urdf: str) -> tuple[set[str], list[str]] | None:
    """Joints of a URDF: every joint name, and the non-fixed ones in alphabetical order.

    Args:
        urdf: URDF text.

    Returns:
        ``(all_joint_names, sorted_non_fixed_joint_names)``, or None if the text is empty or not a
        ``<robot>`` document.
    """
    if not urdf.strip():
        return None
    try:
        root = ET.fromstring(urdf)
    except ET.ParseError:
        return None
    if root.tag != "robot":
        return None
    every: set[str] = set()
    movable: list[str] = []
    for joint in root.findall("joint"):
        name = joint.get("name")
        if not name:
            continue
        every.add(name)
        if joint.get("type", "") != "fixed":
            movable.append(name)
    return every, sorted(movable)


class JointStateBroadcaster(ControllerInterface):
    """Publishes ``/joint_states`` and ``/dynamic_joint_states`` from state interfaces."""

    PARAMETERS = """
joint_state_broadcaster:
  use_local_topics:
    type: bool
    default_value: false
    description: "Publish on ~/joint_states and ~/dynamic_joint_states instead of the global topics."
  joints:
    type: string_array
    default_value: []
    description: "Joints to publish; used only together with 'interfaces'."
  extra_joints:
    type: string_array
    default_value: []
    description: "Joints added to the messages with position, velocity and effort 0."
  interfaces:
    type: string_array
    default_value: []
    description: "Interfaces to publish; used only together with 'joints'."
  map_interface_to_joint_state:
    position:
      type: string
      default_value: "position"
      description: "State interface published in JointState.position."
    velocity:
      type: string
      default_value: "velocity"
      description: "State interface published in JointState.velocity."
    effort:
      type: string
      default_value: "effort"
      description: "State interface published in JointState.effort."
  use_urdf_to_filter:
    type: bool
    default_value: true
    description: "Keep only the robot description's non-fixed joints in /joint_states."
  publish_dynamic_joint_states:
    type: bool
    default_value: true
    description: "Publish /dynamic_joint_states (Jazzy default: true)."
  frame_id:
    type: string
    default_value: "base_link"
    description: "header.frame_id of the published messages."
"""

    def __init__(self) -> None:
        super().__init__()
        self._joints: list[str] = []
        self._interfaces: list[str] = []
        self._use_urdf_to_filter = True
        self._extra_joints: list[str] = []
        self._frame_id = ""
        self._map: dict[str, str] = {}
        self._urdf: tuple[set[str], list[str]] | None = None
        self._joint_state_pub: Publisher | None = None
        self._dynamic_pub: Publisher | None = None
        self.joint_names: list[str] = []
        # per claimed state interface: (prefix, mapped name) the value goes to, or None if skipped
        self._targets: list[tuple[str, str] | None] = []
        self._read_values: Callable[[], Sequence[Any]] = tuple  # every loan's value, in claim order (set at activation)
        self._js_plan: list[list[int]] = []
        self._dynamic_plan: list[tuple[str, list[str], list[int] | None]] = []

    def _use_all_available_interfaces(self) -> bool:
        return not self._joints or not self._interfaces

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``ALL`` when ``joints`` or ``interfaces`` is empty, else joints x interfaces (joint-major)."""
        if self._use_all_available_interfaces():
            return InterfaceConfiguration(InterfaceConfigurationType.ALL)
        names = [f"{j}/{i}" for j in self._joints for i in self._interfaces]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters, create the publishers and parse the robot description."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        self._joints = list(params.joints)
        self._interfaces = list(params.interfaces)
        if self._use_all_available_interfaces():
            self.logger.info("'joints' or 'interfaces' is empty: every available state interface is published")
            self._joints, self._interfaces = [], []
        self._extra_joints = list(params.extra_joints)
        self._use_urdf_to_filter = bool(params.use_urdf_to_filter)
        self._frame_id = params.frame_id
        if not self._frame_id:
            self.logger.warning("'frame_id' is empty: the messages carry no frame")

        # custom interface name -> JointState field; a standard name listed in 'interfaces' keeps its meaning
        self._map = {}
        mapping = params.map_interface_to_joint_state
        for field_name in _JOINT_STATE_FIELDS:
            custom = getattr(mapping, field_name)
            if field_name in self._interfaces and custom != field_name:
                self.logger.warning(
                    "map_interface_to_joint_state.%s = '%s' is not applied: '%s' itself is listed in 'interfaces'",
                    field_name, custom, field_name,
                )
                self._map[field_name] = field_name
            else:
                self._map[custom] = field_name

        node = self.get_node()
        prefix = "~/" if params.use_local_topics else ""
        self._joint_state_pub = node.create_publisher(JointState, prefix + "joint_states")
        self._dynamic_pub = (
            node.create_publisher(DynamicJointState, prefix + "dynamic_joint_states")
            if params.publish_dynamic_joint_states
            else None
        )

        self._urdf = urdf_movable_joints(self.get_robot_description())
        if self._urdf is None and self._use_urdf_to_filter and not self._joints:
            self.logger.warning(
                "no parsable robot description: /joint_states lists every prefix with position, velocity "
                "or effort, unfiltered"
            )
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Work out the joint names and the message layouts from the assigned state interfaces.

        What a cycle needs is prepared here: the loans' read functions in order, and for each field of each message
        the position of its value among the numbers read, so ``update`` only reads numbers.
        """
        if not self.state_interfaces:
            self.logger.error("'%s': no state interfaces to publish; it cannot activate", self.get_name())
            return CallbackReturn.ERROR
        self._targets = []
        # prefix -> mapped interface name -> index of its value among the values read, in claim order
        layout: dict[str, dict[str, int]] = {}
        for index, loan in enumerate(self.state_interfaces):
            prefix, itf = loan.prefix_name, loan.interface_name
            if getattr(loan, "data_type", "double") not in ("double", "float32"):
                self._targets.append(None)  # both messages carry doubles: Jazzy leaves other types out of both
                continue
            mapped = self._map.get(itf, itf)
            # Jazzy keeps one value per (prefix, mapped name): two interfaces that map to the same name share it,
            # and the later one in claim order wins (TestCustomInterfaceMapping shows the mapped name in both messages)
            layout.setdefault(prefix, {})[mapped] = index
            self._targets.append((prefix, mapped))

        # Jazzy walks the interfaces backwards and reverses the result: each name sits at its last occurrence.
        names: list[str] = []
        filter_with_urdf = self._use_urdf_to_filter and not self._joints and self._urdf is not None
        for target in reversed(self._targets):
            if target is None:
                continue
            prefix, mapped = target
            if mapped not in _JOINT_STATE_FIELDS or prefix in names:
                continue
            if filter_with_urdf and self._urdf is not None and prefix not in self._urdf[0]:
                continue
            names.append(prefix)
        names.reverse()
        if filter_with_urdf and self._urdf is not None:
            names = [j for j in self._urdf[1] if j in names]
        extras = []
        for extra in self._extra_joints:
            if extra not in layout:
                extras.append(extra)
                names.append(extra)
        self.joint_names = names
        self._read_values = value_snapshot(self.state_interfaces)
        # JointState: per field, for each joint, the index of its value (-1: NaN, -2: an extra joint's 0.0)
        self._js_plan = [
            [-2 if j in extras else layout.get(j, {}).get(f, -1) for j in names] for f in _JOINT_STATE_FIELDS
        ]
        # DynamicJointState: (prefix, interface names, value indices or None for an extra joint)
        self._dynamic_plan = [(prefix, list(itfs), list(itfs.values())) for prefix, itfs in layout.items()]
        self._dynamic_plan += [(extra, list(_JOINT_STATE_FIELDS), None) for extra in extras]
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Forget the layout; it is rebuilt on the next activation."""
        self.joint_names = []
        self._targets = []
        self._read_values = tuple
        self._js_plan = []
        self._dynamic_plan = []
        return CallbackReturn.SUCCESS

    def update(self, time: float, period: float) -> ReturnType:
        """Read the state values and publish the two messages, stamped with ``time``.

        The messages are built when someone reads them (a subscriber, ``system.latest``, a recorder); the values are
        the ones read in this cycle.
        """
        values = self._read_values()
        # this cycle's values and layout go with each message (a new layout after a restart is a new list)
        if self._joint_state_pub is not None:
            self._joint_state_pub.publish_lazy(_joint_state, time, self._frame_id, self.joint_names, self._js_plan,
                                               values)
        if self._dynamic_pub is not None:
            self._dynamic_pub.publish_lazy(_dynamic_joint_state, time, self._frame_id, self._dynamic_plan, values)
        return ReturnType.OK


def _joint_state(time: float, frame: str, names: list[str], plan: list[list[int]], values: Sequence[Any]) -> JointState:
    fields = [[_pick(values, k) for k in indices] for indices in plan]
    return JointState(header=Header(stamp=time, frame_id=frame), name=list(names),
                      position=fields[0], velocity=fields[1], effort=fields[2])


def _dynamic_joint_state(
    time: float, frame: str, plan: list[tuple[str, list[str], list[int] | None]], values: Sequence[Any]
) -> DynamicJointState:
    # Jazzy lists the mapped names too; it walks unordered maps, so its order is unspecified: ours is claim order
    msg = DynamicJointState(header=Header(stamp=time, frame_id=frame))
    for prefix, itfs, indices in plan:
        vals = [0.0] * len(itfs) if indices is None else [_as_float(values[k]) for k in indices]
        msg.joint_names.append(prefix)
        msg.interface_values.append(InterfaceValue(interface_names=list(itfs), values=vals))
    return msg


def _pick(values: Sequence[Any], index: int) -> float:
    if index >= 0:
        return float(values[index])
    return math.nan if index == -1 else 0.0


def _as_float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan
