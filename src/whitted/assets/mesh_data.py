"""What a model file holds, as read: :class:`MeshData` (the conventions are in
:mod:`whitted.assets.mesh`, whose readers make it)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..scene.materials import Material


@dataclass(frozen=True, eq=False)
class MeshData:
    """A triangle mesh read from a file (see the module docstring for the conventions)."""

    vertices: np.ndarray  # (V, 3) float64 positions
    faces: np.ndarray  # (T, 3) int32, 0-based, fan-triangulated in file order
    normals: np.ndarray | None  # (V, 3) float64 per-vertex normals from the file, or None
    uvs: np.ndarray | None  # (V, 2) float64 per-vertex texture coordinates, or None
    face_material: np.ndarray  # (T,) int32 index into materials
    materials: list[Material]  # at least one
    warnings: list[str]  # "path:line: problem"
    vertex_records: int  # vertices as written in the file (OBJ: `v` records)
    triangle_records: int  # triangles after fan triangulation, degenerate ones included
    source: str  # the path
    texture_files: list[str]  # the existing texture images the materials use
    library_files: list[str] = field(default_factory=list)  # the MTL files read (OBJ)
