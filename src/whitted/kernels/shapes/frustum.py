"""The frustum: the cylinder (equal radii) and the cone (a top radius of its own, 0 for a
point): its crossings, its nearest hit, its normal and its uv.

A frustum row (layout.SHAPE_FRUSTUM) holds its base centre 0:3, the unit axis 3:6, its height
6, base radius 7, top radius 8, capped 9 (1: closed by two disks, a solid; 0: an open tube,
which CSG refuses) and the unit vector across the axis where u = 0, 10:13
(``FRUSTUM_TANGENT``): the transform baked in under a similarity, else the row is in the
object's own space (``PRIM_XFORM``). The radius at height z is r0 + k·z, k = (r1 - r0) / h.
"""

from __future__ import annotations

import math

from ...jit import kernel
from ..layout import FRUSTUM_TANGENT
from ..vec import cross, dot, normalize, sub, vload
from . import INF
from .quadric import nearest_root, quadratic_roots

INV_TWO_PI = 0.5 / math.pi


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
def frustum_solid_crossings(P, i, o, d):
    """What a CSG walk takes of :func:`frustum_crossings`: (count, t0, t1, inf, inf). The
    frustum is convex, so the line enters at its first crossing and leaves at its last; those
    between are a rim met twice (cap and side, a rounding apart). One crossing alone (a
    touch, or one lost to rounding) goes to the walk by normals (count 1)."""
    t0, t1, t2, t3 = frustum_crossings(P, i, o, d)
    if t1 == INF:
        return (0 if t0 == INF else 1), t0, INF, INF, INF
    return 2, t0, (t1 if t2 == INF else (t2 if t3 == INF else t3)), INF, INF


@kernel(inline="always")
def frustum_normal(P, i, p):
    """Outward unit normal at ``p``: a cap's where ``p`` is nearer the cap than the side."""
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


@kernel
def frustum_uv(P, i, p):
    """u = angle about the axis / 2π from the tangent (0.5 there), v = height / length."""
    q = sub(p, vload(P, i, 0))
    axis = vload(P, i, 3)
    z = dot(q, axis)
    qp = (q[0] - z * axis[0], q[1] - z * axis[1], q[2] - z * axis[2])
    t = vload(P, i, FRUSTUM_TANGENT)
    b = cross(axis, t)
    angle = math.atan2(dot(qp, b), dot(qp, t))
    return angle * INV_TWO_PI + 0.5, z / P[i, 6]
