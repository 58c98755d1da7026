"""The sphere: its crossings, its nearest hit, its normal and its texture coordinates.

A sphere row (layout.SHAPE_SPHERE) holds its centre 0:3 and radius 3, then the object's x, y,
z axes in world space (``SPHERE_FRAME``) for its spherical uv: the transform baked in under a
similarity, else the row is in the object's own space (``PRIM_XFORM``).
"""

from __future__ import annotations

import math

from ...jit import kernel
from ..layout import SPHERE_FRAME
from ..vec import dot, sub, vload
from .quadric import nearest_root, quadratic_roots

INV_TWO_PI = 0.5 / math.pi


@kernel
def sphere_span(P, i, o, d):
    """(enter, leave): where the ray's line crosses sphere row ``i`` ((inf, inf): nowhere)."""
    c = vload(P, i, 0)
    r = P[i, 3]
    oc = sub(o, c)
    return quadratic_roots(dot(d, d), dot(oc, d), dot(oc, oc) - r * r)


@kernel
def intersect_sphere(P, i, o, d, tmin, tmax):
    c = vload(P, i, 0)
    r = P[i, 3]
    oc = sub(o, c)
    return nearest_root(dot(d, d), dot(oc, d), dot(oc, oc) - r * r, tmin, tmax)


@kernel(inline="always")
def sphere_normal(P, i, p):
    """(p - c) / r: ``p`` lies on it, so |p - c| is the radius (no square root). Inlined
    where the normals are dispatched (the hottest path: no call)."""
    q = sub(p, vload(P, i, 0))
    s = 1.0 / P[i, 3]
    return (q[0] * s, q[1] * s, q[2] * s)


@kernel
def sphere_uv(P, i, p):
    """Spherical, in the sphere's own frame: u = 0.5 + atan2(x, z)/2π (u = 0.5 faces +z, and
    grows to the right seen from there), v = 0.5 + asin(y)/π (v = 1 at the +y pole)."""
    r = P[i, 3]
    q = sub(p, vload(P, i, 0))
    x = dot(q, vload(P, i, SPHERE_FRAME)) / r
    y = dot(q, vload(P, i, SPHERE_FRAME + 3)) / r
    z = dot(q, vload(P, i, SPHERE_FRAME + 6)) / r
    y = min(1.0, max(-1.0, y))
    return 0.5 + math.atan2(x, z) * INV_TWO_PI, 0.5 + math.asin(y) / math.pi


@kernel(inline="always")
def sphere_ball(P, i):
    """(centre, radius): sphere row ``i`` is its own bounding ball."""
    return vload(P, i, 0), P[i, 3]
