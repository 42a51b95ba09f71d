"""URDF visuals as meshcat objects: geometry, its pose in the link frame, and material.

A :class:`~rrbot_workshop.viz.robot_model.VisualShape` says what URDF says (a box, cylinder, sphere or
mesh with an origin, a scale and a colour); meshcat wants three.js objects. The two differ in one
convention: URDF cylinders run along their z axis, three.js cylinders along y, so a cylinder's pose gets a
quarter turn about x. Meshes are loaded from ``.stl``, ``.obj`` or ``.dae`` files and scaled in their pose.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rrbot_workshop.viz.robot_model import VisualShape

__all__ = ["shape_geometry", "shape_material"]

# URDF cylinders run along z, three.js cylinders along y.
_CYLINDER_Z_TO_Y = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]], dtype=float)


def _rgba_to_hex(rgba: tuple[float, float, float, float]) -> int:
    r, g, b = (max(0, min(255, round(c * 255))) for c in rgba[:3])
    return (r << 16) | (g << 8) | b


def shape_geometry(shape: VisualShape) -> tuple[Any, np.ndarray]:
    """The meshcat geometry of ``shape`` and its 4x4 pose in the link frame.

    Raises:
        ValueError: If a mesh file is not ``.stl``, ``.obj`` or ``.dae``.
        OSError: If a mesh file cannot be read.
    """
    import meshcat.geometry as g

    local = shape.origin
    if shape.kind == "box":
        return g.Box(list(shape.size)), local
    if shape.kind == "cylinder":
        radius, length = shape.size
        return g.Cylinder(length, radius), local @ _CYLINDER_Z_TO_Y
    if shape.kind == "sphere":
        return g.Sphere(shape.size[0]), local
    assert shape.mesh_path is not None
    suffix = Path(shape.mesh_path).suffix.lower()
    loaders = {".stl": g.StlMeshGeometry, ".obj": g.ObjMeshGeometry, ".dae": g.DaeMeshGeometry}
    if suffix not in loaders:
        raise ValueError(f"mesh '{shape.mesh_path}' has an unsupported format (valid: .stl, .obj, .dae)")
    geometry = loaders[suffix].from_file(shape.mesh_path)
    return geometry, local @ np.diag([*shape.size, 1.0])


def shape_material(shape: VisualShape) -> Any:
    """A Phong material in the colour and opacity of ``shape``."""
    import meshcat.geometry as g

    return g.MeshPhongMaterial(color=_rgba_to_hex(shape.rgba), opacity=float(shape.rgba[3]))
