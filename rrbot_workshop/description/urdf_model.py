"""A small URDF model with the checks ``urdf::Model::initString`` (urdfdom) makes.

ros2_control reads the URDF through urdfdom to find each ``<ros2_control>`` joint, its type, limits,
safety controller and mimic tag. This module keeps exactly that, and rejects what urdfdom rejects:
no robot name, no links, duplicate names, unknown joint types, missing parent/child links, revolute or
prismatic joints without ``<limit>``, ``<limit>`` without ``effort`` or ``velocity``, a link with two parents,
and more than one root link. It also rejects what urdfdom lets through but breaks every consumer later (a
physics engine, a mesh library, a limiter): numbers that are NaN or infinite, ``<limit lower>`` above ``upper``,
``<origin>`` with other than three finite numbers, and ``<inertial>`` with a mass or an inertia that is not
positive (definite).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

from rrbot_workshop.exceptions import DescriptionError

__all__ = [
    "JOINT_TYPES",
    "UrdfLimit",
    "UrdfSafety",
    "UrdfMimic",
    "UrdfJoint",
    "UrdfModel",
    "local_name",
    "parse_urdf_model",
]

#: Joint types urdfdom knows.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass(frozen=True)
class UrdfLimit:
    """``<limit>`` of a joint: positions in [rad] or [m], velocity in [rad/s] or [m/s], effort in [N m] or [N]."""

    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    velocity: float = 0.0


@dataclass(frozen=True)
class UrdfSafety:
    """``<safety_controller>`` of a joint (soft limits)."""

    soft_lower_limit: float = 0.0
    soft_upper_limit: float = 0.0
    k_position: float = 0.0
    k_velocity: float = 0.0


@dataclass(frozen=True)
class UrdfMimic:
    """``<mimic>``: ``position = multiplier * position(joint) + offset``."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class UrdfJoint:
    """The parts of a URDF ``<joint>`` that ros2_control reads."""

    name: str
    type: str
    parent: str
    child: str
    limit: UrdfLimit | None = None
    safety: UrdfSafety | None = None
    mimic: UrdfMimic | None = None


@dataclass
class UrdfModel:
    """Robot name, link names, joints by name, and the root link."""

    name: str
    links: list[str] = field(default_factory=list)
    joints: dict[str, UrdfJoint] = field(default_factory=dict)
    root_link: str = ""


def local_name(element: ET.Element) -> str:
    """Tag name without an XML namespace (tinyxml2, which ros2_control uses, ignores namespaces)."""
    tag = element.tag
    if not isinstance(tag, str):
        return ""
    return tag.rsplit("}", 1)[-1]


def _children(element: ET.Element, name: str) -> list[ET.Element]:
    return [child for child in element if local_name(child) == name]


def _fail(reason: str, source: str | None) -> DescriptionError:
    return DescriptionError(f"Failed to parse URDF: {reason}", source=source)


def _float(element: ET.Element, attribute: str, default: float | None, where: str, source: str | None) -> float:
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise _fail(f"<{local_name(element)}> of {where} has no '{attribute}' attribute (it is required)", source)
        return default
    try:
        value = float(text)
    except ValueError:
        raise _fail(
            f"<{local_name(element)} {attribute}='{text}'> of {where} is not a number", source
        ) from None
    if not math.isfinite(value):
        raise _fail(f"<{local_name(element)} {attribute}='{text}'> of {where} must be a finite number", source)
    return value


def _check_origin(element: ET.Element, where: str, source: str | None) -> None:
    """``<origin xyz rpy>``: each attribute, when present, holds three finite numbers."""
    for origin in _children(element, "origin"):
        for attribute in ("xyz", "rpy"):
            text = origin.get(attribute)
            if text is None:
                continue
            parts = text.split()
            try:
                values = [float(part) for part in parts]
            except ValueError:
                values = []
            if len(values) != 3 or not all(math.isfinite(v) for v in values):
                raise _fail(
                    f"<origin {attribute}='{text}'> of {where} must be three finite numbers (e.g. '0 0 0.1')", source
                )


#: Geometry attributes and how many positive numbers each holds.
_GEOMETRY = {"box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)), "sphere": (("radius", 1),)}


def _check_geometry(part: ET.Element, where: str, source: str | None) -> None:
    """``<geometry>``: box sizes, cylinder and sphere dimensions are positive finite numbers [m]; a mesh names a file
    and its scale, if given, is three finite numbers (a viewer or MuJoCo would fail on anything else, later)."""
    for geometry in _children(part, "geometry"):
        for shape in geometry:
            if not isinstance(shape.tag, str):
                continue
            kind = local_name(shape)
            if kind == "mesh":
                if not shape.get("filename"):
                    raise _fail(f"<mesh> of {where} has no 'filename' attribute (it is required)", source)
                checks: tuple[tuple[str, int], ...] = (("scale", 3),) if shape.get("scale") is not None else ()
                positive = False
            else:
                checks = _GEOMETRY.get(kind, ())
                positive = True
            for attribute, count in checks:
                text = shape.get(attribute)
                if text is None:
                    raise _fail(f"<{kind}> of {where} has no '{attribute}' attribute (it is required)", source)
                try:
                    values = [float(v) for v in text.split()]
                except ValueError:
                    values = []
                if len(values) != count or not all(math.isfinite(v) and (v > 0 or not positive) for v in values):
                    what = "positive" if positive else "finite"
                    raise _fail(
                        f"<{kind} {attribute}='{text}'> of {where} must be {count} {what} number"
                        f"{'s' if count > 1 else ''} [m]", source
                    )


def _check_link(link: ET.Element, name: str, source: str | None) -> None:
    """Origins of a link's inertial, visuals and collisions; their geometry; a positive mass and a positive-definite
    inertia."""
    where = f"link '{name}'"
    for part in ("inertial", "visual", "collision"):
        for element in _children(link, part):
            _check_origin(element, f"<{part}> of {where}", source)
            if part != "inertial":
                _check_geometry(element, f"<{part}> of {where}", source)
    for inertial in _children(link, "inertial"):
        for mass in _children(inertial, "mass"):
            value = _float(mass, "value", None, where, source)
            if value <= 0.0:
                raise _fail(f"<mass value='{mass.get('value')}'> of {where} must be positive [kg]", source)
        for inertia in _children(inertial, "inertia"):
            names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            ixx, ixy, ixz, iyy, iyz, izz = (_float(inertia, n, 0.0, where, source) for n in names)
            matrix = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            if float(np.linalg.eigvalsh(matrix).min()) <= 0.0:
                given = " ".join(f"{n}='{inertia.get(n, '0')}'" for n in names)
                raise _fail(
                    f"<inertia {given}> of {where} is not positive definite: the diagonal terms must be positive and "
                    "large enough for the products (e.g. a solid box: ixx = m (y^2 + z^2) / 12, ...) [kg m^2]",
                    source,
                )


def _parse_joint(element: ET.Element, links: set[str], source: str | None) -> UrdfJoint:
    name = element.get("name")
    if not name:
        raise _fail("a <joint> has no 'name' attribute", source)
    where = f"joint '{name}'"
    jtype = element.get("type")
    if jtype not in JOINT_TYPES:
        raise _fail(f"{where} has type '{jtype}' (valid: {', '.join(JOINT_TYPES)})", source)
    ends = {}
    for end in ("parent", "child"):
        tags = _children(element, end)
        link = tags[0].get("link") if tags else None
        if not link:
            raise _fail(f"{where} has no <{end} link='...'/>", source)
        if link not in links:
            raise _fail(f"{where} names {end} link '{link}', which is not a <link> of the robot", source)
        ends[end] = link
    _check_origin(element, where, source)
    limit = None
    limit_tags = _children(element, "limit")
    if limit_tags:
        tag = limit_tags[0]
        limit = UrdfLimit(
            lower=_float(tag, "lower", 0.0, where, source),
            upper=_float(tag, "upper", 0.0, where, source),
            effort=_float(tag, "effort", None, where, source),
            velocity=_float(tag, "velocity", None, where, source),
        )
        if limit.lower > limit.upper:
            raise _fail(
                f"<limit lower='{tag.get('lower')}' upper='{tag.get('upper')}'> of {where} has lower above upper "
                "(valid: lower <= upper)",
                source,
            )
    elif jtype in ("revolute", "prismatic"):
        raise _fail(f"{where} is {jtype} but has no <limit> (required for revolute and prismatic joints)", source)
    safety = None
    safety_tags = _children(element, "safety_controller")
    if safety_tags:
        tag = safety_tags[0]
        safety = UrdfSafety(
            soft_lower_limit=_float(tag, "soft_lower_limit", 0.0, where, source),
            soft_upper_limit=_float(tag, "soft_upper_limit", 0.0, where, source),
            k_position=_float(tag, "k_position", 0.0, where, source),
            k_velocity=_float(tag, "k_velocity", None, where, source),
        )
    mimic = None
    mimic_tags = _children(element, "mimic")
    if mimic_tags:
        tag = mimic_tags[0]
        followed = tag.get("joint")
        if not followed:
            raise _fail(f"<mimic> of {where} has no 'joint' attribute", source)
        mimic = UrdfMimic(
            joint=followed,
            multiplier=_float(tag, "multiplier", 1.0, where, source),
            offset=_float(tag, "offset", 0.0, where, source),
        )
    return UrdfJoint(name, jtype, ends["parent"], ends["child"], limit, safety, mimic)


def parse_urdf_model(robot: ET.Element, source: str | None = None) -> UrdfModel:
    """Build the model of a parsed ``<robot>`` element and check it as urdfdom does.

    Args:
        robot: The ``<robot>`` root element.
        source: File or description name, for error messages.

    Returns:
        The model.

    Raises:
        DescriptionError: ``"Failed to parse URDF: <reason>"`` for any of the faults listed in the module doc.
    """
    name = robot.get("name")
    if not name:
        raise _fail("<robot> has no 'name' attribute", source)
    model = UrdfModel(name=name)
    for link in _children(robot, "link"):
        link_name = link.get("name")
        if not link_name:
            raise _fail("a <link> has no 'name' attribute", source)
        if link_name in model.links:
            raise _fail(f"link '{link_name}' is declared twice", source)
        _check_link(link, link_name, source)
        model.links.append(link_name)
    if not model.links:
        raise _fail(f"robot '{name}' has no <link>", source)
    link_set = set(model.links)
    parent_of: dict[str, str] = {}
    for element in _children(robot, "joint"):
        joint = _parse_joint(element, link_set, source)
        if joint.name in model.joints:
            raise _fail(f"joint '{joint.name}' is declared twice", source)
        if joint.child in parent_of:
            raise _fail(
                f"link '{joint.child}' is the child of two joints ('{parent_of[joint.child]}' and '{joint.name}')",
                source,
            )
        parent_of[joint.child] = joint.name
        model.joints[joint.name] = joint
    roots = [link for link in model.links if link not in parent_of]
    if len(roots) != 1:
        found = ", ".join(roots) if roots else "none (the joints form a loop)"
        raise _fail(f"a robot needs exactly one root link; found: {found}", source)
    model.root_link = roots[0]
    return model
