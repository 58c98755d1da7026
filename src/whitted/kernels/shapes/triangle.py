"""The triangle (a lone one, or one of a small mesh flattened into rows): its nearest hit,
its normals and its uv.

A triangle row (layout.SHAPE_TRIANGLE) holds v0 0:3, edge1 3:6, edge2 6:9, the unit normal
9:12 (the winding's: edge1 x edge2), the corners' uvs 12:18 (``TRIANGLE_UV``) and the row of
``tri_normals`` holding its corner normals (``TRIANGLE_NORMALS``; -1: flat shaded). A flat
shape bounds no volume: it has no crossings and CSG refuses it (a mesh's triangles in a CSG
tree are walked by csg.py's mesh leaf). The triangles of a mesh kept whole (an instance) are
in mesh.py.
"""

from __future__ import annotations

import math

from ...jit import kernel
from ..layout import TRIANGLE_NORMALS, TRIANGLE_UV
from ..vec import cross, dot, madd, normalize, sub, vload
from . import INF
from .flat import EDGE_TOL


@kernel
def intersect_triangle(P, i, o, d, tmin, tmax):
    """Möller–Trumbore with the edges precomputed."""
    e1 = vload(P, i, 3)
    e2 = vload(P, i, 6)
    pv = cross(d, e2)
    det = dot(e1, pv)
    if det == 0.0:
        return INF
    inv = 1.0 / det
    tv = sub(o, vload(P, i, 0))
    u = dot(tv, pv) * inv
    if u < -EDGE_TOL or u > 1.0 + EDGE_TOL:
        return INF
    qv = cross(tv, e1)
    v = dot(d, qv) * inv
    if v < -EDGE_TOL or u + v > 1.0 + EDGE_TOL:
        return INF
    t = dot(e2, qv) * inv
    return t if tmin < t < tmax else INF


@kernel
def triangle_barycentric(P, i, p):
    """(b1, b2) of point ``p`` on triangle primitive ``i``: p = v0 + b1·edge1 + b2·edge2."""
    q = sub(p, vload(P, i, 0))
    e1 = vload(P, i, 3)
    e2 = vload(P, i, 6)
    d00 = dot(e1, e1)
    d01 = dot(e1, e2)
    d11 = dot(e2, e2)
    d20 = dot(q, e1)
    d21 = dot(q, e2)
    denom = d00 * d11 - d01 * d01
    return (d11 * d20 - d01 * d21) / denom, (d00 * d21 - d01 * d20) / denom


@kernel(inline="always")
def triangle_normal(P, i, p):
    """The geometric normal (the winding's); a smooth-shaded one's shading normal is
    :func:`triangle_shading_normal`."""
    return vload(P, i, 9)


@kernel
def triangle_uv(P, i, p):
    """The corners' uvs (default (0,0), (1,0), (0,1)) blended by barycentric weight."""
    b1, b2 = triangle_barycentric(P, i, p)
    b0 = 1.0 - b1 - b2
    c = TRIANGLE_UV
    return (
        b0 * P[i, c] + b1 * P[i, c + 2] + b2 * P[i, c + 4],
        b0 * P[i, c + 1] + b1 * P[i, c + 3] + b2 * P[i, c + 5],
    )


@kernel
def triangle_shading_normal(geo, i, p, fallback):
    """The corner normals of a smooth-shaded triangle primitive blended at ``p``
    (``fallback``, its geometric normal, where they cancel)."""
    P = geo.prim_params
    b1, b2 = triangle_barycentric(P, i, p)
    b0 = 1.0 - b1 - b2
    r = int(P[i, TRIANGLE_NORMALS])
    n = geo.tri_normals
    ns = (
        b0 * n[r, 0, 0] + b1 * n[r, 1, 0] + b2 * n[r, 2, 0],
        b0 * n[r, 0, 1] + b1 * n[r, 1, 1] + b2 * n[r, 2, 1],
        b0 * n[r, 0, 2] + b1 * n[r, 1, 2] + b2 * n[r, 2, 2],
    )
    if ns[0] == 0.0 and ns[1] == 0.0 and ns[2] == 0.0:
        return fallback
    return normalize(ns)


@kernel
def triangle_ball(P, i):
    """(centre, radius) of a ball holding triangle row ``i`` and every point its hit test
    can find (:func:`intersect_triangle` allows EDGE_TOL past its edges)."""
    v0 = vload(P, i, 0)
    e1 = vload(P, i, 3)
    e2 = vload(P, i, 6)
    c = madd(v0, (e1[0] + e2[0], e1[1] + e2[1], e1[2] + e2[2]), 1.0 / 3.0)
    a = sub(v0, c)
    b = sub(madd(v0, e1, 1.0), c)
    d = sub(madd(v0, e2, 1.0), c)
    far = math.sqrt(max(dot(a, a), max(dot(b, b), dot(d, d))))  # the farthest corner
    return c, far + 4.0 * EDGE_TOL * (math.sqrt(dot(e1, e1)) + math.sqrt(dot(e2, e2)))
