"""Exact ray/shape intersection and surface normals, one function per shape (the sphere's,
the box's and the torus's are in their own files under ``shapes/``), and the dispatch on the
shape code.

Every ``intersect_*`` takes the parameter table ``P`` and a row ``i`` (see :mod:`.layout`), a ray
origin ``o`` and direction ``d`` (tuples; ``d`` need not be unit length) and the open interval
``(tmin, tmax)``; it returns the nearest ray parameter in that interval, or ``INF`` on a miss.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .layout import (
    SHAPE_BOX,
    SHAPE_DISK,
    SHAPE_FRUSTUM,
    SHAPE_PLANE,
    SHAPE_RECTANGLE,
    SHAPE_SPHERE,
    SHAPE_TRIANGLE,
)
from .shapes.box import box_normal, intersect_box
from .shapes.flat import EDGE_TOL
from .shapes.quadric import nearest_root, quadratic_roots
from .shapes.sphere import intersect_sphere
from .shapes.triangle import intersect_triangle
from .vec import dot, normalize, sub, vload

INF = math.inf


@kernel
def _plane_t(p0, n, o, d):
    denom = dot(n, d)
    if denom == 0.0:
        return INF
    return dot(sub(p0, o), n) / denom


@kernel
def intersect_plane(P, i, o, d, tmin, tmax):
    t = _plane_t(vload(P, i, 0), vload(P, i, 3), o, d)
    return t if tmin < t < tmax else INF


@kernel
def intersect_rectangle(P, i, o, d, tmin, tmax):
    corner = vload(P, i, 0)
    t = _plane_t(corner, vload(P, i, 9), o, d)
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


@kernel
def intersect_disk(P, i, o, d, tmin, tmax):
    c = vload(P, i, 0)
    t = _plane_t(c, vload(P, i, 3), o, d)
    if not (tmin < t < tmax):
        return INF
    q = (o[0] + t * d[0] - c[0], o[1] + t * d[1] - c[1], o[2] + t * d[2] - c[2])
    r = P[i, 6]
    return t if dot(q, q) <= r * r * (1.0 + EDGE_TOL) else INF


@kernel(inline="always")
def _sorted4(a, b, c, d):
    """(a, b, c, d) in increasing order (five compare-exchanges)."""
    a, b = (a, b) if a <= b else (b, a)
    c, d = (c, d) if c <= d else (d, c)
    a, c = (a, c) if a <= c else (c, a)
    b, d = (b, d) if b <= d else (d, b)
    b, c = (b, c) if b <= c else (c, b)
    return a, b, c, d


@kernel(inline="always")
def _frustum_quadric(P, i, o, d):
    """The ray in frustum row ``i``'s terms: (oz, dz, qp, dp, h, r0, k, a, b, c): height and
    its rate along the axis, the parts across it, the body's height, base radius and radius
    slope, and the side's quadratic a·t² + 2b·t + c."""
    base = vload(P, i, 0)
    axis = vload(P, i, 3)
    h = P[i, 6]
    r0 = P[i, 7]
    k = (P[i, 8] - r0) / h
    q = sub(o, base)
    oz = dot(q, axis)
    dz = dot(d, axis)
    qp = (q[0] - oz * axis[0], q[1] - oz * axis[1], q[2] - oz * axis[2])
    dp = (d[0] - dz * axis[0], d[1] - dz * axis[1], d[2] - dz * axis[2])
    rq = r0 + k * oz
    a = dot(dp, dp) - k * k * dz * dz
    b = dot(qp, dp) - k * rq * dz
    c = dot(qp, qp) - rq * rq
    return oz, dz, qp, dp, h, r0, k, a, b, c


@kernel(inline="always")
def _cap_t(z_cap, r_cap, oz, dz, qp, dp):
    """Where the ray crosses the cap at height ``z_cap`` of radius ``r_cap`` (INF: past its
    rim); dz != 0."""
    t = (z_cap - oz) / dz
    x = qp[0] + t * dp[0]
    y = qp[1] + t * dp[1]
    w = qp[2] + t * dp[2]
    return t if x * x + y * y + w * w <= r_cap * r_cap else INF


@kernel
def frustum_crossings(P, i, o, d):
    """Every crossing of the ray's whole line with frustum row ``i``, sorted, each once,
    inf-padded: the values :func:`intersect_frustum` gives when asked again from each one
    (the same formulas; fast-math may round a fused step differently), found in one pass."""
    oz, dz, qp, dp, h, r0, k, a, b, c = _frustum_quadric(P, i, o, d)
    if a == 0.0:
        s0 = -c / (2.0 * b) if b != 0.0 else INF
        s1 = INF
    else:
        s0, s1 = quadratic_roots(a, b, c)
    z = oz + s0 * dz
    if not (0.0 <= z <= h and r0 + k * z >= 0.0):
        s0 = INF
    z = oz + s1 * dz
    if not (0.0 <= z <= h and r0 + k * z >= 0.0):
        s1 = INF
    c0 = INF
    c1 = INF
    if P[i, 9] != 0.0 and dz != 0.0:
        if r0 > 0.0:
            c0 = _cap_t(0.0, r0, oz, dz, qp, dp)
        if P[i, 8] > 0.0:
            c1 = _cap_t(h, P[i, 8], oz, dz, qp, dp)
    t0, t1, t2, t3 = _sorted4(s0, s1, c0, c1)
    # each value once (asked again from a crossing, the next one must lie strictly past it)
    if t3 == t2:
        t3 = INF
    if t2 == t1:
        t2, t3 = t3, INF
    if t1 == t0:
        t1, t2, t3 = t2, t3, INF
    return t0, t1, t2, t3


@kernel
def intersect_frustum(P, i, o, d, tmin, tmax):
    """A finite cone/cylinder about ``axis``: radius r(z) = r0 + k·z for z in [0, h], plus caps."""
    oz, dz, qp, dp, h, r0, k, a, b, c = _frustum_quadric(P, i, o, d)
    best = INF
    # side: up to two roots, keep the nearest whose height lies on the body
    lo = tmin
    for _ in range(2):
        t = nearest_root(a, b, c, lo, tmax)
        if t == INF:
            break
        z = oz + t * dz
        if 0.0 <= z <= h and r0 + k * z >= 0.0:
            best = t
            break
        lo = t
    if P[i, 9] != 0.0 and dz != 0.0:
        for z_cap, r_cap in ((0.0, r0), (h, P[i, 8])):
            if r_cap <= 0.0:
                continue
            t = _cap_t(z_cap, r_cap, oz, dz, qp, dp)
            if tmin < t < min(best, tmax):
                best = t
    return best


@kernel(inline="always")
def intersect_local(typ, P, i, o, d, tmin, tmax):
    """Dispatch on the shape code; ``o`` and ``d`` in the primitive's own space."""
    i = np.uint64(i)  # unsigned: no negative-index wraparound code on the parameter loads
    if typ == SHAPE_SPHERE:
        return intersect_sphere(P, i, o, d, tmin, tmax)
    if typ == SHAPE_TRIANGLE:
        return intersect_triangle(P, i, o, d, tmin, tmax)
    if typ == SHAPE_RECTANGLE:
        return intersect_rectangle(P, i, o, d, tmin, tmax)
    if typ == SHAPE_BOX:
        return intersect_box(P, i, o, d, tmin, tmax)
    if typ == SHAPE_PLANE:
        return intersect_plane(P, i, o, d, tmin, tmax)
    if typ == SHAPE_DISK:
        return intersect_disk(P, i, o, d, tmin, tmax)
    if typ == SHAPE_FRUSTUM:
        return intersect_frustum(P, i, o, d, tmin, tmax)
    return INF


@kernel(inline="always")
def normal_local(typ, P, i, p):
    """Outward unit normal at point ``p`` (in the primitive's own space): the flat shapes'
    and the sphere's written in place, a box's or frustum's through a call (inlining those
    too slowed the analytic benchmark by a tenth)."""
    if typ == SHAPE_SPHERE:  # p lies on it: |p - c| is the radius (no square root)
        q = sub(p, vload(P, i, 0))
        s = 1.0 / P[i, 3]
        return (q[0] * s, q[1] * s, q[2] * s)
    if typ == SHAPE_TRIANGLE or typ == SHAPE_RECTANGLE:
        return vload(P, i, 9)
    if typ == SHAPE_PLANE or typ == SHAPE_DISK:
        return vload(P, i, 3)
    return _solid_normal(typ, P, i, p)


@kernel
def _solid_normal(typ, P, i, p):
    """:func:`normal_local` of a box or a frustum."""
    if typ == SHAPE_BOX:
        return box_normal(P, i, p)
    if typ == SHAPE_FRUSTUM:
        base = vload(P, i, 0)
        axis = vload(P, i, 3)
        h = P[i, 6]
        r0 = P[i, 7]
        r1 = P[i, 8]
        k = (r1 - r0) / h
        q = sub(p, base)
        z = dot(q, axis)
        qp = (q[0] - z * axis[0], q[1] - z * axis[1], q[2] - z * axis[2])
        rho = math.sqrt(dot(qp, qp))
        tol = 1e-7 * max(h, max(r0, r1))
        if P[i, 9] != 0.0:
            r_here = r0 + k * z
            side_gap = abs(rho - r_here)
            if abs(z) < tol and abs(z) <= side_gap:
                return (-axis[0], -axis[1], -axis[2])
            if abs(z - h) < tol and abs(z - h) <= side_gap and r1 > 0.0:
                return axis
        if rho == 0.0:
            return axis
        inv = 1.0 / rho
        return normalize(
            (qp[0] * inv - k * axis[0], qp[1] * inv - k * axis[1], qp[2] * inv - k * axis[2])
        )
    return (0.0, 1.0, 0.0)
