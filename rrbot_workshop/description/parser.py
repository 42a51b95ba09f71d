"""The ``<ros2_control>`` parser: URDF text -> one :class:`HardwareInfo` per ``<ros2_control>`` tag.

It follows ``hardware_interface::parse_control_resources_from_urdf`` of ros2_control: the same accepted
elements and attributes, the same defaults, the same rejections. Each ``<ros2_control>`` tag is read first,
then the whole URDF is checked as urdfdom does (see :mod:`.urdf_model`), then every ``<joint>`` of the tags is
matched with its URDF joint (existence, mimic rules, no fixed joints) and its limits are computed
(:mod:`.limits`). Every rejection is a :class:`~rrbot_workshop.exceptions.DescriptionError` that names the
element and attribute at fault.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from rrbot_workshop.description.info import (
    ComponentInfo,
    HardwareInfo,
    InterfaceInfo,
    MimicJoint,
    TransmissionActuatorInfo,
    TransmissionInfo,
    TransmissionJointInfo,
)
from rrbot_workshop.description.limits import compute_joint_limits, soft_limits_from_urdf
from rrbot_workshop.description.urdf_model import UrdfModel, local_name, parse_urdf_model
from rrbot_workshop.description.xml_context import XmlContext, children, label, parameters, parse_bool, text_of
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["parse_ros2_control", "parse_bool", "ROS2_CONTROL_CHILDREN"]

#: Children allowed directly under ``<ros2_control>``.
ROS2_CONTROL_CHILDREN = ("hardware", "properties", "joint", "sensor", "gpio", "transmission")

_POSITIVE_INT = re.compile(r"[1-9][0-9]*")
_STOI_PREFIX = re.compile(r"\s*[+-]?[0-9]+")
_INT32_MAX = 2**31 - 1


def _limits_enabled(element: ET.Element, ctx: XmlContext) -> bool:
    tags = children(element, "limits")
    if not tags:
        return True
    value = ctx.enter(element).required(tags[0], "enable")
    return ctx.enter(element).boolean(tags[0], "enable", value)


def _interface(element: ET.Element, ctx: XmlContext, component: str, component_limits: bool) -> InterfaceInfo:
    name = ctx.required(element, "name")
    inner = ctx.enter(element)
    params = parameters(element, ctx, component)
    size_text = element.get("size")
    if size_text is not None and not _POSITIVE_INT.fullmatch(size_text):
        raise ctx.error(f"invalid size='{size_text}' in {inner.where}: expected a positive integer", "size")
    return InterfaceInfo(
        name=name,
        min=params.get("min", ""),
        max=params.get("max", ""),
        initial_value=params.get("initial_value", ""),
        data_type=element.get("data_type", "double"),
        size=int(size_text) if size_text is not None else 1,
        enable_limits=_limits_enabled(element, ctx) and component_limits,
        parameters=params,
    )


def _component(element: ET.Element, ctx: XmlContext) -> ComponentInfo:
    kind = local_name(element)
    name = ctx.required(element, "name")
    inner = ctx.enter(element)
    component = ComponentInfo(name=name, type=kind)
    if kind == "joint" and element.get("mimic") is not None:
        component.is_mimic = "true" if ctx.boolean(element, "mimic", element.get("mimic", "")) else "false"
    # GPIOs have no joint limits: ros2_control does not read <limits> at the GPIO level.
    component.enable_limits = True if kind == "gpio" else _limits_enabled(element, ctx)
    component.command_interfaces = [
        _interface(e, inner, name, component.enable_limits) for e in children(element, "command_interface")
    ]
    component.state_interfaces = [
        _interface(e, inner, name, component.enable_limits) for e in children(element, "state_interface")
    ]
    for kind_tag, found in (("command_interface", component.command_interfaces),
                            ("state_interface", component.state_interfaces)):
        names = [i.name for i in found]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:  # the resource manager would store the same key twice: refuse it where it is written
            raise inner.error(
                f"<{kind_tag} name='{twice[0]}'> appears {names.count(twice[0])} times in {inner.where}; "
                f"declare each {kind_tag} once (this {kind} has {sorted(set(names))})", "name"
            )
    component.parameters = parameters(element, ctx, name)
    return component


def _child_float(element: ET.Element, tag: str, default: float) -> float:
    """``<tag>number</tag>`` child; the default if absent or not a number (as ros2_control)."""
    for child in children(element, tag):
        try:
            return float(text_of(child))
        except ValueError:
            return default
    return default


def _transmission(element: ET.Element, ctx: XmlContext) -> TransmissionInfo:
    name = ctx.required(element, "name")
    inner = ctx.enter(element)
    plugins = children(element, "plugin")
    if not plugins:
        raise ctx.error(f"missing <plugin> in {inner.where} (a transmission needs its plugin name)", "plugin")
    transmission = TransmissionInfo(name=name, type=text_of(plugins[0]), plugin=text_of(plugins[0]))
    for joint in children(element, "joint"):
        transmission.joints.append(TransmissionJointInfo(
            name=inner.required(joint, "name"), role=inner.required(joint, "role"),
            mechanical_reduction=_child_float(joint, "mechanical_reduction", 1.0),
            offset=_child_float(joint, "offset", 0.0),
        ))
    for actuator in children(element, "actuator"):
        transmission.actuators.append(TransmissionActuatorInfo(
            name=inner.required(actuator, "name"), role=inner.required(actuator, "role"),
            mechanical_reduction=_child_float(actuator, "mechanical_reduction", 1.0),
            offset=_child_float(actuator, "offset", 0.0),
        ))
    transmission.parameters = parameters(element, ctx, name)
    return transmission


def _fill_transmissions(hardware: HardwareInfo, ctx: XmlContext) -> None:
    joints = {joint.name: joint for joint in hardware.joints}
    for transmission in hardware.transmissions:
        for tjoint in transmission.joints:
            if tjoint.name not in joints:
                raise ctx.error(
                    f"transmission '{transmission.name}' declares joint '{tjoint.name}', which is not a joint of "
                    f"{ctx.where} (valid: {', '.join(joints) or 'none'})", "joint",
                )
            tjoint.command_interfaces = [i.name for i in joints[tjoint.name].command_interfaces]
            tjoint.state_interfaces = [i.name for i in joints[tjoint.name].state_interfaces]
        if hardware.type == "actuator":
            if len(transmission.joints) != 1:
                raise ctx.error(
                    f"transmission '{transmission.name}' of actuator {ctx.where} has "
                    f"{len(transmission.joints)} joints; an actuator's transmission needs exactly one", "joint",
                )
            only = transmission.joints[0]
            transmission.actuators.append(TransmissionActuatorInfo(
                name="actuator1", role="actuator1", state_interfaces=list(only.state_interfaces),
                command_interfaces=list(only.command_interfaces),
            ))


def _rw_rate(element: ET.Element, ctx: XmlContext) -> int:
    text = element.get("rw_rate")
    if text is None:
        return 0
    match = _STOI_PREFIX.match(text)  # std::stoi reads a leading integer and ignores what follows
    value = int(match.group()) if match else None
    if value is None or value < 0 or value > _INT32_MAX:
        raise ctx.error(f"invalid rw_rate='{text}' in {ctx.where}: expected a non-negative integer in [Hz]", "rw_rate")
    return value


def _hardware_info(element: ET.Element, source: str | None) -> HardwareInfo:
    outer = XmlContext(source)
    for attribute in ("name", "type"):
        if element.get(attribute) is None:
            raise outer.error(f"missing attribute '{attribute}' in {label(element)} (required: name, type)", attribute)
    name = element.get("name", "")
    hw_type = element.get("type", "")
    ctx = outer.enter(element)
    hardware = HardwareInfo(name=name, type=hw_type)
    hardware.rw_rate = _rw_rate(element, ctx)
    hardware.is_async = outer.boolean(element, "is_async", element.get("is_async", "false"))
    if hardware.is_async:
        priority = element.get("thread_priority")
        if priority is not None and not _POSITIVE_INT.fullmatch(priority):
            raise ctx.error(
                f"invalid thread_priority='{priority}' in {ctx.where}: expected a positive integer", "thread_priority"
            )
        hardware.thread_priority = int(priority) if priority is not None else 50
    else:
        hardware.thread_priority = _INT32_MAX
    for child in element:
        if not isinstance(child.tag, str):
            continue  # comments and processing instructions
        tag = local_name(child)
        if tag == "hardware":
            plugins = children(child, "plugin")
            if not plugins:
                raise ctx.error(f"Missing <plugin> tag of <hardware> element for '{name}'", "plugin")
            hardware.hardware_plugin_name = text_of(plugins[0])
            groups = children(child, "group")
            if groups:
                hardware.group = text_of(groups[0])
            hardware.hardware_parameters = parameters(child, ctx, name)
        elif tag == "properties":
            for async_tag in children(child, "async"):
                params = dict(async_tag.attrib)
                params["scheduling_policy"] = params.get("scheduling_policy", "synchronized").lower()
                params.setdefault("print_warnings", "true")
                hardware.async_params = params
        elif tag in ("joint", "sensor", "gpio"):
            component = _component(child, ctx)
            same = [c for c in getattr(hardware, f"{tag}s") if c.name == component.name]
            if same:
                raise ctx.enter(child).error(
                    f"<{tag} name='{component.name}'> appears twice in {ctx.where}; list each {tag} once, with all of "
                    "its command and state interfaces in that one element", "name"
                )
            getattr(hardware, f"{tag}s").append(component)
        elif tag == "transmission":
            hardware.transmissions.append(_transmission(child, ctx))
        else:
            raise ctx.error(
                f"invalid tag name '{tag}' in {ctx.where} (valid: {', '.join(ROS2_CONTROL_CHILDREN)})", tag
            )
    _fill_transmissions(hardware, ctx)
    hardware.original_xml = ET.tostring(element, encoding="unicode")
    return hardware


def _check_joints(hardware: HardwareInfo, model: UrdfModel, source: str | None) -> None:
    """Match each ``<joint>`` with the URDF: existence, mimic rules, no fixed joints; then compute limits."""
    ctx = XmlContext(source, (f"<ros2_control name='{hardware.name}'>",))
    index = {joint.name: i for i, joint in enumerate(hardware.joints)}
    for i, joint in enumerate(hardware.joints):
        urdf_joint = model.joints.get(joint.name)
        if urdf_joint is None:
            raise ctx.error(
                f"Joint '{joint.name}' of {ctx.where} not found in URDF (URDF joints: "
                f"{', '.join(model.joints) or 'none'})", "name",
            )
        if urdf_joint.mimic is None and joint.is_mimic == "true":
            raise ctx.error(
                f"Joint '{joint.name}' has mimic='true' in {ctx.where} but no <mimic> in the URDF", "mimic"
            )
        if urdf_joint.mimic is not None and joint.is_mimic != "false":
            if joint.command_interfaces:
                raise ctx.error(
                    f"Joint '{joint.name}' mimics '{urdf_joint.mimic.joint}' in the URDF, so it cannot have command "
                    f"interfaces (found: {', '.join(c.name for c in joint.command_interfaces)}); remove them or "
                    "set mimic='false'", "command_interface",
                )
            if urdf_joint.mimic.joint not in index:
                raise ctx.error(
                    f"Mimic joint '{urdf_joint.mimic.joint}' (followed by '{joint.name}') not found in {ctx.where} "
                    f"(valid: {', '.join(index)})", "mimic",
                )
            hardware.mimic_joints.append(MimicJoint(
                joint_index=i, mimicked_joint_index=index[urdf_joint.mimic.joint],
                multiplier=urdf_joint.mimic.multiplier, offset=urdf_joint.mimic.offset,
            ))
        if urdf_joint.type == "fixed":
            raise ctx.error(
                f"Joint '{joint.name}' is of type 'fixed' in the URDF: fixed joints do not make sense in ros2_control "
                "(valid types: revolute, continuous, prismatic, floating, planar)", "type",
            )
        limits = compute_joint_limits(urdf_joint, joint.command_interfaces)
        hardware.limits[joint.name] = limits
        soft = soft_limits_from_urdf(urdf_joint, limits)
        if soft is not None:
            hardware.soft_limits[joint.name] = soft


def parse_ros2_control(urdf: str, source: str | None = None) -> list[HardwareInfo]:
    """Read every ``<ros2_control>`` tag of a URDF.

    Args:
        urdf: URDF XML text (for instance the output of :func:`~rrbot_workshop.description.process_xacro`).
        source: File or description name that error messages start with.

    Returns:
        One :class:`HardwareInfo` per ``<ros2_control>`` tag, in document order.

    Raises:
        DescriptionError: If the text is empty, is not well-formed XML, is SDF (not supported), its root is not
            ``<robot>``, it has no ``<ros2_control>`` tag, a ``<ros2_control>`` tag or one of its children is
            invalid (missing or bad attribute, unknown child, missing ``<plugin>``, ``<param>`` without name,
            bad ``size``/``rw_rate``/``thread_priority``, transmission joint mismatch), the URDF itself is invalid,
            or a joint is missing from the URDF, fixed, or breaks the mimic rules.
    """
    text = urdf.lstrip() if isinstance(urdf, str) else ""
    if not text:
        raise DescriptionError("empty URDF passed to the <ros2_control> parser", source=source)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise DescriptionError(f"invalid URDF: malformed XML ({err})", source=source) from err
    root_tag = local_name(root)
    if root_tag == "sdf":
        raise DescriptionError(
            "SDF is not supported: pass a URDF whose root is <robot> (ros2_control also reads <sdf><model>, "
            "this course does not)", source=source, element="<sdf>",
        )
    if root_tag != "robot":
        raise DescriptionError(f"the root element is <{root_tag}>, expected <robot>", source=source,
                               element=f"<{root_tag}>")
    tags = children(root, "ros2_control")
    if not tags:
        raise DescriptionError(f"no 'ros2_control' tag found in {label(root)}", source=source, element="<robot>")
    hardware = [_hardware_info(tag, source) for tag in tags]
    model = parse_urdf_model(root, source)
    for info in hardware:
        _check_joints(info, model, source)
        info.robot_description = urdf
    return hardware
