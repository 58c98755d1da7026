"""The rectangle (a parallelogram): its nearest hit, its normal and its uv.

A rectangle row (layout.SHAPE_RECTANGLE) holds its corner 0:3, edge1 3:6, edge2 6:9, the unit
normal 9:12 (edge1 × edge2) and the dual vectors 12:15 and 15:18 whose dot products with
``p - corner`` are its coordinates along the edges (0..1 on it), the transform baked in. It
bounds no volume: no crossings, and CSG refuses it.
"""

from __future__ import annotations

from ...jit import kernel
from ..vec import dot, sub, vload
from . import INF
from .flat import EDGE_TOL, plane_t


@kernel
def intersect_rectangle(P, i, o, d, tmin, tmax):
    corner = vload(P, i, 0)
    t = plane_t(corner, vload(P, i, 9), o, d)
    if not (tmin < t < tmax):
        return INF
    q = (o[0] + t * d[0] - corner[0], o[1] + t * d[1] - corner[1], o[2] + t * d[2] - corner[2])
    u = dot(q, vload(P, i, 12))
    if u < -EDGE_TOL or u > 1.0 + EDGE_TOL:
        return INF
    v = dot(q, vload(P, i, 15))
    if v < -EDGE_TOL or v > 1.0 + EDGE_TOL:
        return INF
    return t


@kernel(inline="always")
def rectangle_normal(P, i, p):
    return vload(P, i, 9)


@kernel(inline="always")
def rectangle_uv(P, i, p):
    """u, v in 0..1 along edge1 and edge2."""
    q = sub(p, vload(P, i, 0))
    return dot(q, vload(P, i, 12)), dot(q, vload(P, i, 15))
