"""A robot's visual geometry and forward kinematics, read from URDF with yourdfpy.

This is the part of RViz's robot model display that the viewer needs: for each link, the shapes
of its ``<visual>`` elements (box, cylinder, sphere, mesh) with their origins, scales and colours, and
for a joint configuration the pose of every link in the root frame. ``<ros2_control>`` and
``<gazebo>`` tags are ignored here (yourdfpy skips them).
"""

from __future__ import annotations

import io
import logging
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rrbot_workshop.exceptions import DescriptionError

__all__ = ["RobotModel", "VisualShape", "JointRange", "load_urdf_text"]

_log = logging.getLogger(__name__)

#: Colour of visuals that carry no material (RViz's default grey), as RGBA in [0, 1].
DEFAULT_RGBA = (0.7, 0.7, 0.7, 1.0)


@dataclass(frozen=True)
class VisualShape:
    """One ``<visual>`` of a link.

    Attributes:
        link: Link name.
        index: Position of the visual among the link's visuals.
        kind: ``"box"``, ``"cylinder"``, ``"sphere"`` or ``"mesh"``.
        size: Box edge lengths [m]; ``(radius, length)`` of a cylinder [m]; ``(radius,)`` of a sphere [m];
            mesh scale factors.
        origin: 4x4 pose of the visual in its link frame.
        rgba: Colour, each channel in [0, 1].
        mesh_path: Resolved file of a mesh, else None.
    """

    link: str
    index: int
    kind: str
    size: tuple[float, ...]
    origin: np.ndarray = field(compare=False)
    rgba: tuple[float, float, float, float] = DEFAULT_RGBA
    mesh_path: str | None = None


@dataclass(frozen=True)
class JointRange:
    """Range of a movable joint, for sliders.

    Attributes:
        name: Joint name.
        type: URDF joint type (``revolute``, ``continuous``, ``prismatic``).
        lower: Lower limit in [rad] or [m] (continuous joints get -pi).
        upper: Upper limit in [rad] or [m] (continuous joints get +pi).
    """

    name: str
    type: str
    lower: float
    upper: float


def load_urdf_text(source: str | os.PathLike[str]) -> tuple[str, str | None]:
    """Return ``(urdf_text, directory)`` for URDF text or a path to a URDF (or xacro) file.

    Raises:
        DescriptionError: If ``source`` looks like a path but no such file exists.
    """
    if isinstance(source, os.PathLike) or (isinstance(source, str) and "<" not in source):
        path = Path(source)
        if not path.is_file():
            raise DescriptionError(
                "no such URDF file; pass URDF text, a path to a .urdf/.xacro file, or a running System",
                source=str(path),
            )
        if path.suffix == ".xacro":
            from rrbot_workshop.description import process_xacro

            return process_xacro(path), str(path.parent)
        return path.read_text(encoding="utf-8"), str(path.parent)
    return str(source), None


def _default_uri_resolver(base_dir: str | None) -> Callable[[str], str | None]:
    resolve_package_uri: Any
    try:  # the description layer's resolver (package:// -> descriptions/<pkg>/...)
        from rrbot_workshop.description import resolve_package_uri
    except ImportError:
        resolve_package_uri = None

    def resolve(uri: str) -> str | None:
        candidates: list[str] = []
        if resolve_package_uri is not None:
            try:
                candidates.append(str(resolve_package_uri(uri, base_dir)))
            except Exception:  # noqa: BLE001 - fall back to the guesses below
                pass
        rest = uri
        for scheme in ("package://", "file://"):
            if rest.startswith(scheme):
                rest = rest[len(scheme):]
        if uri.startswith("file://") or os.path.isabs(rest):
            candidates.append(rest)
        if base_dir:
            candidates.append(os.path.join(base_dir, rest))
            if uri.startswith("package://"):  # package://pkg/meshes/x.stl next to the URDF's package
                candidates.append(os.path.join(base_dir, rest.split("/", 1)[-1]))
        try:
            from rrbot_workshop.description import descriptions_root

            root = descriptions_root()
            candidates.append(os.path.join(str(root), rest))
        except Exception:  # noqa: BLE001 - the description layer may not be ready
            pass
        return next((c for c in candidates if os.path.isfile(c)), None)

    return resolve


class RobotModel:
    """Visual shapes and forward kinematics of a URDF.

    Args:
        urdf: URDF text.
        base_dir: Directory to resolve relative mesh file names against.
        uri_resolver: Maps a mesh ``filename`` (``package://...``) to a file, or None if not found.

    Raises:
        DescriptionError: If yourdfpy cannot read the URDF.
    """

    def __init__(
        self, urdf: str, base_dir: str | None = None, uri_resolver: Callable[[str], str | None] | None = None
    ) -> None:
        import yourdfpy

        try:
            self._urdf = yourdfpy.URDF.load(
                io.BytesIO(urdf.encode("utf-8")), build_scene_graph=True, load_meshes=False
            )
        except Exception as exc:  # noqa: BLE001 - yourdfpy raises assorted errors for bad XML
            raise DescriptionError(f"yourdfpy could not read the URDF: {exc}", source="URDF") from exc
        if self._urdf.robot is None or not self._urdf.robot.links:
            raise DescriptionError("the URDF has no <link>", source="URDF", element="<robot>")
        self.name: str = self._urdf.robot.name or "robot"
        self._resolve = uri_resolver or _default_uri_resolver(base_dir)
        self.base_link: str = self._urdf.base_link
        self.link_names: list[str] = [link.name for link in self._urdf.robot.links]
        self.visuals: list[VisualShape] = self._read_visuals()
        self.joint_ranges: list[JointRange] = self._read_joint_ranges()
        self._positions: dict[str, float] = {j.name: 0.0 for j in self.joint_ranges}
        self._stale = True  # the model's poses are computed from _positions at the next link_poses()

    # ------------------------------------------------------------------------------------- reading
    def _material_rgba(self, material: object | None) -> tuple[float, float, float, float]:
        if material is None:
            return DEFAULT_RGBA
        color = getattr(material, "color", None)
        name = getattr(material, "name", None)
        if color is None and name:  # a reference to a material declared under <robot>
            for declared in self._urdf.robot.materials:
                if declared.name == name and declared.color is not None:
                    color = declared.color
                    break
        if color is None:
            return DEFAULT_RGBA
        r, g, b, a = (float(c) for c in np.asarray(color.rgba, dtype=float).ravel()[:4])
        return (r, g, b, a)

    def _read_visuals(self) -> list[VisualShape]:
        shapes: list[VisualShape] = []
        for link in self._urdf.robot.links:
            for index, visual in enumerate(link.visuals):
                geometry = visual.geometry
                if geometry is None:
                    continue
                origin = np.array(visual.origin if visual.origin is not None else np.eye(4), dtype=float)
                rgba = self._material_rgba(visual.material)
                common = {"link": link.name, "index": index, "origin": origin, "rgba": rgba}
                if geometry.box is not None:
                    size = tuple(float(v) for v in np.asarray(geometry.box.size).ravel())
                    shapes.append(VisualShape(kind="box", size=size, **common))
                elif geometry.cylinder is not None:
                    size = (float(geometry.cylinder.radius), float(geometry.cylinder.length))
                    shapes.append(VisualShape(kind="cylinder", size=size, **common))
                elif geometry.sphere is not None:
                    shapes.append(VisualShape(kind="sphere", size=(float(geometry.sphere.radius),), **common))
                elif geometry.mesh is not None:
                    path = self._resolve(geometry.mesh.filename)
                    if path is None:
                        _log.warning(
                            "link '%s': mesh '%s' not found; the visual is left out", link.name, geometry.mesh.filename
                        )
                        continue
                    scale = geometry.mesh.scale
                    if scale is None:
                        size = (1.0, 1.0, 1.0)
                    else:
                        arr = np.atleast_1d(np.asarray(scale, dtype=float)).ravel()
                        size = tuple(float(v) for v in (arr if arr.size == 3 else np.repeat(arr[0], 3)))
                    shapes.append(VisualShape(kind="mesh", size=size, mesh_path=path, **common))
        return shapes

    def _read_joint_ranges(self) -> list[JointRange]:
        ranges: list[JointRange] = []
        for joint in self._urdf.robot.joints:
            if joint.type not in ("revolute", "continuous", "prismatic") or joint.mimic is not None:
                continue
            limit = joint.limit
            if joint.type == "continuous" or limit is None or limit.lower is None or limit.upper is None:
                lower, upper = (-math.pi, math.pi) if joint.type != "prismatic" else (-1.0, 1.0)
            else:
                lower, upper = float(limit.lower), float(limit.upper)
            ranges.append(JointRange(joint.name, joint.type, lower, upper))
        return ranges

    # ------------------------------------------------------------------------------------- kinematics
    @property
    def joint_names(self) -> list[str]:
        """Movable, non-mimic joints in URDF order."""
        return [j.name for j in self.joint_ranges]

    @property
    def positions(self) -> dict[str, float]:
        """Current joint positions in [rad] or [m] (a copy)."""
        return dict(self._positions)

    def set_positions(self, positions: Mapping[str, float]) -> None:
        """Set some joint positions; names that are not movable joints of this URDF are ignored."""
        known = {k: float(v) for k, v in positions.items() if k in self._positions and math.isfinite(float(v))}
        if not known:
            return
        self._positions.update(known)
        self._stale = True  # forward kinematics when the poses are asked for (a 100 Hz loop sets them every cycle)

    def link_poses(self) -> dict[str, np.ndarray]:
        """4x4 pose of every link in the root link's frame, at the current joint positions."""
        if self._stale:
            self._urdf.update_cfg(dict(self._positions))
            self._stale = False
        return {name: np.array(self._urdf.get_transform(name, self.base_link)) for name in self.link_names}

    def _visual_points(self, poses: Mapping[str, np.ndarray]) -> dict[str, list[np.ndarray]]:
        """Points on (or around) each link's visuals in the root frame, per link."""
        points: dict[str, list[np.ndarray]] = {}
        for shape in self.visuals:
            pose = poses[shape.link] @ shape.origin
            out = points.setdefault(shape.link, [])
            if shape.kind == "box":
                half = np.asarray(shape.size) / 2.0
                for sx in (-1, 1):
                    for sy in (-1, 1):
                        for sz in (-1, 1):
                            out.append((pose @ np.array([sx * half[0], sy * half[1], sz * half[2], 1.0]))[:3])
                continue
            if shape.kind == "cylinder":
                reach = math.hypot(shape.size[0], shape.size[1] / 2.0)
            elif shape.kind == "sphere":
                reach = shape.size[0]
            else:
                reach = self._mesh_radius(shape)
            centre = pose[:3, 3]
            out.extend(centre + reach * np.array(d) for d in np.vstack([np.eye(3), -np.eye(3)]))
        return points

    @staticmethod
    def _mesh_radius(shape: VisualShape) -> float:
        try:
            import trimesh

            mesh = trimesh.load(shape.mesh_path, force="mesh")
            return float(np.max(np.linalg.norm(mesh.bounds, axis=1)) * max(shape.size))
        except Exception:  # noqa: BLE001 - any loader problem: a modest guess
            return 0.1 * max(shape.size)

    def bounds(self, workspace: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box around the visuals: ``(lower, upper)`` in [m], in the root frame.

        Args:
            workspace: Cover every pose the joints can reach (each moving chain swept as a sphere around its
                first joint), rather than the current pose only.
        """
        poses = self.link_poses()
        per_link = self._visual_points(poses)
        points = [p for pts in per_link.values() for p in pts]
        if workspace:
            children: dict[str, list[Any]] = {}
            for joint in self._urdf.robot.joints:
                children.setdefault(joint.parent, []).append(joint)

            def subtree(link: str) -> list[str]:
                return [link, *(x for j in children.get(link, []) for x in subtree(j.child))]

            stack = [self.base_link]
            while stack:  # walk fixed joints from the root; stop at the first moving joint of each chain
                for joint in children.get(stack.pop(), []):
                    if joint.type == "fixed":
                        stack.append(joint.child)
                        continue
                    origin = joint.origin if joint.origin is not None else np.eye(4)
                    centre = (poses[joint.parent] @ origin)[:3, 3]
                    swept = [p for link in subtree(joint.child) for p in per_link.get(link, [])]
                    if swept:
                        radius = max(float(np.linalg.norm(p - centre)) for p in swept)
                        points.extend([centre - radius, centre + radius])
        if not points:
            points = [p[:3, 3] for p in poses.values()]
        stacked = np.array(points)
        return stacked.min(axis=0), stacked.max(axis=0)
