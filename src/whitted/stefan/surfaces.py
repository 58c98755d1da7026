"""From fields to surfaces: marching cubes (scikit-image), Taubin smoothing (trimesh,
volume-preserving) and optional decimation; written as PLY.

Two surfaces per saved time: the outer ice/air surface and the inner ice/water surface (the
cavity). The fields they are cut from at 0.5:

* outer: 0 in air, 1 in the cavity's cells, the ice fraction (1 - liquid fraction) in every
  other body cell (its meltwater has drained or will);
* inner: the liquid fraction in the cavity's cells, 0 elsewhere.

The cavity's cells are :func:`whitted.stefan.measures.regions`' (the time series measures the
same surfaces).

Both are padded with a layer of zeros so the surfaces close.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh
from skimage.measure import marching_cubes

from .geometry import GridFrame
from .measures import regions
from .properties import Properties


def surface_fields(H: np.ndarray, kind: np.ndarray, props: Properties):
    f, cavity = regions(H, kind, props)
    body = kind == 1
    outer_field = np.where(body, np.where(cavity, 1.0, 1.0 - f), 0.0)
    inner_field = np.where(cavity, f, 0.0)
    return outer_field, inner_field


def _cut(field: np.ndarray, frame: GridFrame, smoothing: int, keep: float,
         close_bottom: bool) -> trimesh.Trimesh | None:
    padded = np.pad(field, 1, constant_values=0.0)
    if close_bottom:  # the table: the block stands on y = 0, close it there
        padded[:, 0, :] = 0.0
    if padded.max() <= 0.5:
        return None
    verts, faces, _, _ = marching_cubes(padded.astype(np.float32), level=0.5,
                                        allow_degenerate=False)
    verts = frame.to_world(verts.astype(np.float64) - 1.0)
    # scikit-image's faces wind towards lower values (outward); keep that orientation
    mesh = trimesh.Trimesh(vertices=verts, faces=faces[:, ::-1], process=True)
    if smoothing > 0:
        trimesh.smoothing.filter_taubin(mesh, lamb=0.5, nu=0.53, iterations=smoothing)
    if keep < 1.0 and len(mesh.faces) > 100:
        mesh = decimate(mesh, keep)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def decimate(mesh: trimesh.Trimesh, keep: float) -> trimesh.Trimesh:
    """Keep about ``keep`` of the faces by quadric decimation (trimesh, with the optional
    fast_simplification package); without that package the mesh is returned as it is."""
    try:
        return mesh.simplify_quadric_decimation(percent=1.0 - keep)
    except (ImportError, ModuleNotFoundError):
        return mesh


def extract_surfaces(H: np.ndarray, kind: np.ndarray, props: Properties, frame: GridFrame,
                     smoothing: int = 10, keep: float = 1.0):
    """(outer, inner) trimesh surfaces in world metres; None where a surface is empty."""
    outer_field, inner_field = surface_fields(H, kind, props)
    outer = _cut(outer_field, frame, smoothing, keep, close_bottom=True)
    inner = _cut(inner_field, frame, smoothing, keep, close_bottom=False)
    return outer, inner


def write_ply(mesh: trimesh.Trimesh, path: Path) -> None:
    """Binary PLY, written atomically (a temporary file renamed into place)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    tmp.write_bytes(mesh.export(file_type="ply"))
    tmp.replace(path)
