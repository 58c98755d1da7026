"""Small geometry helpers of the compiler: unit vectors, similarity scales, bounds of point
sets and disks, and the tangent frames of planar texture mapping."""

from __future__ import annotations

import math

import numpy as np


def similarity_scale(linear: np.ndarray) -> float | None:
    """s when ``linear`` is s times a rotation (or reflection), else None."""
    gram = linear.T @ linear
    s2 = gram[0, 0]
    if np.allclose(gram, s2 * np.eye(3), rtol=1e-12, atol=1e-12 * max(s2, 1e-300)):
        return math.sqrt(s2)
    return None


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def disk_bounds(center, normal, radius):
    n = unit(normal)
    ext = radius * np.sqrt(np.clip(1.0 - n * n, 0.0, None))
    return center - ext, center + ext


def corners_bounds(points: np.ndarray, matrix: np.ndarray | None = None):
    pts = np.asarray(points, dtype=np.float64)
    if matrix is not None:
        pts = pts @ matrix[:3, :3].T + matrix[:3, 3]
    return pts.min(axis=0), pts.max(axis=0)


def box_corners(lo, hi):
    xs, ys, zs = (lo[0], hi[0]), (lo[1], hi[1]), (lo[2], hi[2])
    return np.array([[x, y, z] for x in xs for y in ys for z in zs])


def tangent(normal) -> np.ndarray:
    """The u direction of planar texture mapping on a surface with this normal: world x made
    perpendicular to it (or -z for surfaces facing along x), so that seen from the front u
    runs right and v = normal x tangent runs up."""
    n = unit(normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 0.0, -np.sign(n[0])])
    return unit(helper - np.dot(helper, n) * n)


def world_tangent(lin: np.ndarray, local_normal, world_normal) -> np.ndarray:
    """The object's own tangent carried by its transform, so a rotated shape turns its
    texture with it."""
    t = lin @ tangent(local_normal)
    n = unit(world_normal)
    return unit(t - np.dot(t, n) * n)
