"""URDF text prepared for MuJoCo's importer, and the URDF facts MuJoCo's model does not keep.

MuJoCo reads URDF directly, with three catches this module handles: ``package://`` mesh URIs mean nothing to
it, unsupported mesh formats (``.dae``) stop the load, and by default it merges links joined by fixed joints
(so ``tool0`` would vanish) and drops visual geometry. It also keeps no record of URDF effort limits or of
merged frames, which :func:`effort_limits` and :func:`frame_in_body` recover from the XML.
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from rrbot_workshop.description.xacro import resolve_package_uri
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["prepare_urdf", "urdf_origin", "frame_in_body", "effort_limits"]

logger = logging.getLogger(__name__)

#: Mesh formats MuJoCo can load; other meshes (e.g. ``.dae``) are dropped with a warning.
_MESH_FORMATS = (".stl", ".obj", ".msh")

#: Elements of a URDF that mean nothing to MuJoCo.
_FOREIGN_ELEMENTS = ("ros2_control", "gazebo", "transmission")


def prepare_urdf(urdf: str, base_dir: str | Path | None = None) -> tuple[str, ET.Element]:
    """Make URDF text loadable by MuJoCo's importer.

    Resolves ``package://`` and ``file://`` mesh URIs to absolute paths, drops meshes MuJoCo cannot read, removes
    ``<ros2_control>``, ``<gazebo>`` and ``<transmission>``, and adds
    ``<mujoco><compiler discardvisual="false" fusestatic="false"/></mujoco>`` so visuals and empty frames
    (``tool0``) survive as bodies.

    Args:
        urdf: URDF text.
        base_dir: Folder for relative mesh paths (default: the current directory).

    Returns:
        The rewritten URDF text and the parsed ``<robot>`` element (of the original text).

    Raises:
        DescriptionError: If the text is not XML, the root is not ``<robot>``, or a ``package://`` URI names an
            unknown package.
    """
    try:
        root = ET.fromstring(urdf.lstrip())
    except ET.ParseError as exc:
        raise DescriptionError(f"URDF is not well-formed XML: {exc}", element="<robot>") from exc
    if root.tag != "robot":
        raise DescriptionError(f"URDF root element is <{root.tag}>; expected <robot>", element=f"<{root.tag}>")
    original = ET.fromstring(ET.tostring(root))
    for tag in _FOREIGN_ELEMENTS:
        for element in root.findall(tag):
            root.remove(element)
    for link in root.findall("link"):
        for kind in ("visual", "collision"):
            for element in link.findall(kind):
                mesh = element.find("geometry/mesh")
                if mesh is None:
                    continue
                path = _resolve_uri(mesh.get("filename", ""), base_dir)
                if path.suffix.lower() not in _MESH_FORMATS:
                    logger.warning(
                        "link '%s': dropping %s mesh '%s', MuJoCo reads only %s",
                        link.get("name"), kind, path.name, ", ".join(_MESH_FORMATS),
                    )
                    link.remove(element)
                    continue
                mesh.set("filename", str(path))
    mujoco_element = root.find("mujoco")
    if mujoco_element is None:
        mujoco_element = ET.SubElement(root, "mujoco")
    compiler = mujoco_element.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(mujoco_element, "compiler")
    compiler.set("discardvisual", "false")
    compiler.set("fusestatic", "false")
    compiler.set("strippath", "false")
    return ET.tostring(root, encoding="unicode"), original


def _resolve_uri(uri: str, base_dir: str | Path | None) -> Path:
    path = Path(resolve_package_uri(uri, base_dir))
    return path if path.is_absolute() else path.resolve()


# --------------------------------------------------------------------------- poses
def urdf_origin(element: ET.Element | None) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and rotation matrix of a URDF ``<origin xyz rpy>`` (identity when absent).

    Args:
        element: The ``<origin>`` element, or None.
    """
    if element is None:
        return np.zeros(3), np.eye(3)
    xyz = np.array([float(v) for v in element.get("xyz", "0 0 0").split()])
    roll, pitch, yaw = (float(v) for v in element.get("rpy", "0 0 0").split())
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return xyz, rz @ ry @ rx


def frame_in_body(
    frame: str, urdf_root: ET.Element, body_names: set[str]
) -> tuple[str, np.ndarray, np.ndarray]:
    """The body that carries URDF link ``frame`` and the frame's pose in it.

    MuJoCo keeps each URDF link as a body when ``fusestatic`` is off; when a link was merged into its parent
    through fixed joints, the fixed-joint offsets are composed up to the first link that still is a body.

    Raises:
        DescriptionError: If ``frame`` is not a link of the URDF, or only reachable through a moving joint.
    """
    links = sorted(link.get("name", "") for link in urdf_root.findall("link"))
    if frame not in links:
        raise DescriptionError(
            f"force-torque frame_id '{frame}' is not a link of the URDF (valid: {', '.join(links)})",
            element="<sensor>",
            attribute="frame_id",
        )
    parent_joint: dict[str, ET.Element] = {}
    for joint in urdf_root.findall("joint"):
        child = joint.find("child")
        if child is not None:
            parent_joint[child.get("link", "")] = joint
    pos, rot = np.zeros(3), np.eye(3)
    link = frame
    while link not in body_names:
        fixed = parent_joint.get(link)
        if fixed is None or fixed.get("type") != "fixed":
            raise DescriptionError(
                f"force-torque frame '{frame}' was merged into a moving body; keep it a separate body "
                "(compiler fusestatic=\"false\")",
                element="<sensor>",
                attribute="frame_id",
            )
        joint_pos, joint_rot = urdf_origin(fixed.find("origin"))
        pos, rot = joint_pos + joint_rot @ pos, joint_rot @ rot
        parent = fixed.find("parent")
        link = parent.get("link", "") if parent is not None else ""
    return link, pos, rot


def effort_limits(urdf_root: ET.Element) -> dict[str, float]:
    """Joint name -> ``<limit effort>`` in [N m] or [N], for joints that give one."""
    out: dict[str, float] = {}
    for joint in urdf_root.findall("joint"):
        limit = joint.find("limit")
        if limit is not None and limit.get("effort") is not None:
            out[joint.get("name", "")] = abs(float(limit.get("effort", "0")))
    return out
