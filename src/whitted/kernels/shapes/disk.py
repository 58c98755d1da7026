"""The disk: its nearest hit, its normal and its uv.

A disk row (layout.SHAPE_DISK) holds its centre 0:3, its unit normal 3:6, its radius 6 and
the unit tangent its u runs along 7:10 (``DISK_TANGENT``): the transform baked in under a
similarity, else the row is in the object's own space (``PRIM_XFORM``). It bounds no volume:
no crossings, and CSG refuses it.
"""

from __future__ import annotations

from ...jit import kernel
from ..layout import DISK_TANGENT
from ..vec import cross, dot, sub, vload
from . import INF
from .flat import EDGE_TOL, plane_t


@kernel
def intersect_disk(P, i, o, d, tmin, tmax):
    c = vload(P, i, 0)
    t = plane_t(c, vload(P, i, 3), o, d)
    if not (tmin < t < tmax):
        return INF
    q = (o[0] + t * d[0] - c[0], o[1] + t * d[1] - c[1], o[2] + t * d[2] - c[2])
    r = P[i, 6]
    return t if dot(q, q) <= r * r * (1.0 + EDGE_TOL) else INF


@kernel(inline="always")
def disk_normal(P, i, p):
    return vload(P, i, 3)


@kernel(inline="always")
def disk_uv(P, i, p):
    """Planar, the disk inscribed in the unit square (its centre at (0.5, 0.5))."""
    q = sub(p, vload(P, i, 0))
    t = vload(P, i, DISK_TANGENT)
    s = 0.5 / P[i, 6]
    return 0.5 + dot(q, t) * s, 0.5 + dot(q, cross(vload(P, i, 3), t)) * s
