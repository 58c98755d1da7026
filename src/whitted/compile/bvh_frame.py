"""The frame the scene BVH is built in.

A mesh flattened into the scene BVH keeps its triangles in world space; turned by its
transform (an ice block rotated 30 degrees about y), the axis-aligned box of each of its
flat faces' triangles becomes a slab as thick as the triangle is wide, and a ray travelling
inside the body passes through many of them. Built in the mesh's own orientation instead,
the same boxes are flat again. The scene BVH may therefore be built in a rotated frame: its
boxes bound the primitives turned by a rotation ``F`` (``GeometryArrays.bvh_frame``), and the
walks turn the ray by ``F`` for the box tests only. Every primitive is still tested with the
world ray against its world-space row, so every hit (its t, its primitive) is the one the
world-frame tree gives: only which boxes a ray enters changes.

The frame is the rotation of the flattened mesh object with the most triangles, when the
primitives' boxes turned into it are smaller (summed surface area) by
:data:`MIN_GAIN`; otherwise the world frame (``bvh_frame`` empty, and the walks turn
nothing). Each box in the frame is widened by :data:`FRAME_PAD` of the scene's size, far
more than the rounding of the turned ray and far less than any geometry. (The rounding of a
turned ray origin grows with its distance: about 3e-16 of it, which reaches the pad only for
an origin some 10^6-10^7 scene sizes away, where the band of rays it could misclassify is
far narrower than a pixel's footprint.)
"""

from __future__ import annotations

import numpy as np

from ..kernels.layout import SHAPE_SPHERE, SHAPE_TRIANGLE

MIN_GAIN = 0.8  # a frame is taken when its boxes' summed area is at most this of the world's
FRAME_PAD = 1e-9  # each turned box is widened by this times the scene's largest coordinate
CANDIDATES = 4  # rotations tried: the flattened mesh objects with the most triangles
WORLD_FRAME = np.zeros((0, 3), np.float64)


def rotation_of(m: np.ndarray) -> np.ndarray | None:
    """The rotation part of affine ``m`` (4x4 or 3x3; its scale taken off by a polar
    decomposition), or None when its linear part is singular or a reflection."""
    lin = np.asarray(m, np.float64)[:3, :3]
    if not np.all(np.isfinite(lin)):
        return None
    u, s, vt = np.linalg.svd(lin)
    if s[-1] <= 0.0:
        return None
    r = u @ vt
    if np.linalg.det(r) <= 0.0:
        return None
    return r


def axis_aligned(r: np.ndarray, tol: float = 1e-12) -> bool:
    """Whether rotation ``r`` maps the axes onto the axes (turns no box into a fatter one)."""
    return bool(np.all((np.abs(r) < tol) | (np.abs(np.abs(r) - 1.0) < tol)))


def frame_bounds(frame: np.ndarray, prim_type: np.ndarray, params: np.ndarray,
                 prim_xform: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 pad: float) -> tuple[np.ndarray, np.ndarray]:
    """Boxes in the frame turned by ``frame`` (3x3) of the primitives whose world boxes are
    ``lo``, ``hi`` (rows of finite bounds): a world-space triangle's from its three corners,
    a world-space ball's around its turned centre, any other primitive's from the eight
    corners of its world box (which holds it); each widened by ``pad``."""
    corners = np.empty((len(lo), 8, 3))
    for k in range(8):
        corners[:, k, 0] = np.where(k & 1, hi[:, 0], lo[:, 0])
        corners[:, k, 1] = np.where(k & 2, hi[:, 1], lo[:, 1])
        corners[:, k, 2] = np.where(k & 4, hi[:, 2], lo[:, 2])
    tri = np.flatnonzero((prim_type == SHAPE_TRIANGLE) & (prim_xform < 0))
    if len(tri):
        v0 = params[tri, 0:3]
        tri_corners = np.stack([v0, v0 + params[tri, 3:6], v0 + params[tri, 6:9]], axis=1)
        corners[tri] = np.concatenate(
            [tri_corners, np.repeat(tri_corners[:, :1], 5, axis=1)], axis=1)
    turned = corners @ frame.T
    f_lo = turned.min(axis=1) - pad
    f_hi = turned.max(axis=1) + pad
    ball = np.flatnonzero((prim_type == SHAPE_SPHERE) & (prim_xform < 0))
    if len(ball):  # a ball's box turns with its centre
        centre = params[ball, 0:3] @ frame.T
        radius = params[ball, 3:4]
        f_lo[ball] = centre - radius - pad
        f_hi[ball] = centre + radius + pad
    return f_lo, f_hi


def _area(lo: np.ndarray, hi: np.ndarray) -> float:
    e = np.maximum(hi - lo, 0.0)
    return float(np.sum(e[:, 0] * e[:, 1] + e[:, 1] * e[:, 2] + e[:, 2] * e[:, 0]))


def choose_frame(rotations: list[tuple[int, np.ndarray]], prim_type: np.ndarray,
                 params: np.ndarray, prim_xform: np.ndarray, lo: np.ndarray,
                 hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(bvh_frame, box lower corners, upper corners) for the scene BVH over the primitives
    of world boxes ``lo``, ``hi`` (finite rows). ``rotations``: (triangle count, rotation)
    of each flattened mesh object. The world frame (``WORLD_FRAME``, the boxes unchanged)
    unless a rotation's boxes are smaller by MIN_GAIN."""
    if len(lo) == 0:
        return WORLD_FRAME, lo, hi
    best = (MIN_GAIN * _area(lo, hi), WORLD_FRAME, lo, hi)
    scale = float(np.max(np.abs(np.concatenate([lo, hi]))))
    pad = FRAME_PAD * max(scale, 1e-300)
    seen: list[np.ndarray] = []
    for _, r in sorted(rotations, key=lambda x: -x[0])[:CANDIDATES]:
        frame = np.ascontiguousarray(r.T)  # world to the mesh's orientation
        if axis_aligned(frame) or any(np.allclose(frame, f, atol=1e-12) for f in seen):
            continue
        seen.append(frame)
        f_lo, f_hi = frame_bounds(frame, prim_type, params, prim_xform, lo, hi, pad)
        area = _area(f_lo, f_hi)
        if area < best[0]:
            best = (area, frame, f_lo, f_hi)
    return best[1], best[2], best[3]
