"""The plane: its nearest hit, its normal and its uv.

A plane row (layout.SHAPE_PLANE) holds a point on it 0:3, its unit normal 3:6 and the unit
tangent its u runs along 6:9 (``PLANE_TANGENT``), the transform baked in. It is unbounded:
the BVH holds no box of it, the walks test it first (``unbounded``). It bounds no volume, so
it has no crossings and CSG refuses it.
"""

from __future__ import annotations

from ...jit import kernel
from ..layout import PLANE_TANGENT
from ..vec import cross, dot, sub, vload
from . import INF
from .flat import plane_t


@kernel
def intersect_plane(P, i, o, d, tmin, tmax):
    t = plane_t(vload(P, i, 0), vload(P, i, 3), o, d)
    return t if tmin < t < tmax else INF


@kernel(inline="always")
def plane_normal(P, i, p):
    return vload(P, i, 3)


@kernel(inline="always")
def plane_uv(P, i, p):
    """Planar, in scene units from the plane's point: u along its tangent, v along
    normal × tangent."""
    q = sub(p, vload(P, i, 0))
    t = vload(P, i, PLANE_TANGENT)
    return dot(q, t), dot(q, cross(vload(P, i, 3), t))
