"""Tests of rrbot_workshop.viz.meshcat_geometry: URDF visual shapes as meshcat geometry and material."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rrbot_workshop.viz.meshcat_geometry import shape_geometry, shape_material
from rrbot_workshop.viz.robot_model import VisualShape


def _shape(kind: str, size: tuple[float, ...], mesh_path: str | None = None) -> VisualShape:
    return VisualShape("link", 0, kind, size, np.eye(4), (1.0, 0.5, 0.0, 0.25), mesh_path)


def test_cylinder_gets_a_quarter_turn_from_z_to_y():
    geometry, local = shape_geometry(_shape("cylinder", (0.1, 2.0)))
    assert geometry.radiusTop == 0.1 and geometry.height == 2.0
    assert np.allclose(local[:3, 1], [0.0, 0.0, 1.0])  # three.js y axis along the URDF z axis


def test_mesh_scale_is_part_of_the_pose(tmp_path: Path):
    stl = tmp_path / "tri.stl"
    stl.write_text("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                   "endloop\nendfacet\nendsolid t\n")
    _, local = shape_geometry(_shape("mesh", (2.0, 3.0, 4.0), str(stl)))
    assert np.allclose(np.diag(local), [2.0, 3.0, 4.0, 1.0])


def test_unsupported_mesh_format_raises_value_error_naming_the_valid_ones():
    with pytest.raises(ValueError, match=r"\.stl, \.obj, \.dae"):
        shape_geometry(_shape("mesh", (1.0, 1.0, 1.0), "/models/part.ply"))


def test_unreadable_mesh_raises_os_error(tmp_path: Path):
    with pytest.raises(OSError):
        shape_geometry(_shape("mesh", (1.0, 1.0, 1.0), str(tmp_path / "absent.stl")))


def test_material_takes_the_colour_and_opacity():
    material = shape_material(_shape("sphere", (0.1,)))
    assert material.color == 0xFF8000 and material.opacity == 0.25
