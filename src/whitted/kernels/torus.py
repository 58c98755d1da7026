"""The torus: exact ray intersection (a quartic), normals and texture coordinates.

A torus row (layout.SHAPE_TORUS) holds its centre, the object's x, y, z axes in world space
and the two radii, the scale baked in; under a non-similarity transform the row is in the
object's own space and the ray arrives mapped there (``PRIM_XFORM``).

The quartic is solved robustly rather than by Ferrari's formulas, whose cancellations put
acne on grazing hits: the ray is first scaled so the torus fits in the unit ball and moved
along itself to the point nearest the centre (the coefficients stay of order one whatever
the distance of the eye); the roots can then only lie on the chord of the unit ball,
[-h, h]. The roots of the quartic's second derivative (a quadratic) split that chord where
its first derivative (a cubic) may change direction; each such piece holds at most one root
of the cubic, found by Newton's method kept inside its bracket; the cubic's roots in turn
split the chord into pieces where the quartic is monotonic, each with at most one root,
found the same way. A root where the quartic only touches zero (a ray exactly tangent to the
surface) is no crossing and is not reported. Every root is computed from the ray alone, not
from ``tmin``: asking again from past one root gives the next one exactly (CSG walks rely on
it).
"""

from __future__ import annotations

import math

from .jit import kernel
from .vec import dot, normalize, sub, vload

INF = math.inf
NEWTON_STEPS = 100  # bracketed Newton steps per root (bisection halves the bracket each)


@kernel(inline="always")
def _quartic(a, b, c, e, x):
    """(f, f') of x⁴ + a·x³ + b·x² + c·x + e."""
    f = (((x + a) * x + b) * x + c) * x + e
    df = ((4.0 * x + 3.0 * a) * x + 2.0 * b) * x + c
    return f, df


@kernel(inline="always")
def _cubic(a, b, c, x):
    """(g, g') of g = the quartic's derivative 4x³ + 3a·x² + 2b·x + c."""
    g = ((4.0 * x + 3.0 * a) * x + 2.0 * b) * x + c
    dg = (12.0 * x + 6.0 * a) * x + 2.0 * b
    return g, dg


@kernel
def _bracketed_root(deg, a, b, c, e, lo, hi, f_lo):
    """The root in [lo, hi] of the quartic (deg 4) or its derivative (deg 3), whose values at
    the two ends have opposite signs (``f_lo`` at ``lo``): Newton's method, falling back to
    bisection whenever a step would leave the bracket."""
    x = 0.5 * (lo + hi)
    for _ in range(NEWTON_STEPS):
        if deg == 4:
            f, df = _quartic(a, b, c, e, x)
        else:
            f, df = _cubic(a, b, c, x)
        if f == 0.0:
            return x
        if (f < 0.0) == (f_lo < 0.0):
            lo = x
            f_lo = f
        else:
            hi = x
        step_ok = df != 0.0
        xn = x - f / df if step_ok else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-15 * (1.0 + abs(x)) or hi - lo <= 1e-15 * (1.0 + abs(lo)):
            return xn
        x = xn
    return x


@kernel
def _quadratic_roots(p, q, r):
    """Real roots (x0 <= x1) of p·x² + q·x + r, p != 0; (inf, inf) when there are none."""
    disc = q * q - 4.0 * p * r
    if disc < 0.0:
        return INF, INF
    sq = math.sqrt(disc)
    h = -0.5 * (q + sq) if q >= 0.0 else -0.5 * (q - sq)
    if h == 0.0:
        return -q / (2.0 * p), -q / (2.0 * p)
    x0 = h / p
    x1 = r / h
    if x0 > x1:
        x0, x1 = x1, x0
    return x0, x1


@kernel
def _split_points(deg, a, b, c, e, lo, hi, s0, s1, s2):
    """Roots in (lo, hi) of the quartic (deg 4) or its derivative (deg 3), given sorted split
    points s0, s1, s2 (inf: unused) between which it is monotonic: up to four, sorted,
    inf-padded."""
    out0 = INF
    out1 = INF
    out2 = INF
    out3 = INF
    n = 0
    x0 = lo
    if deg == 4:
        f0, _ = _quartic(a, b, c, e, x0)
    else:
        f0, _ = _cubic(a, b, c, x0)
    for k in range(4):
        x1 = s0 if k == 0 else (s1 if k == 1 else (s2 if k == 2 else hi))
        x1 = min(x1, hi)
        if x1 <= x0:
            continue
        if deg == 4:
            f1, _ = _quartic(a, b, c, e, x1)
        else:
            f1, _ = _cubic(a, b, c, x1)
        if (f0 < 0.0 and f1 > 0.0) or (f0 > 0.0 and f1 < 0.0):
            root = _bracketed_root(deg, a, b, c, e, x0, x1, f0)
            if n == 0:
                out0 = root
            elif n == 1:
                out1 = root
            elif n == 2:
                out2 = root
            else:
                out3 = root
            n += 1
        x0 = x1
        f0 = f1
    return out0, out1, out2, out3


@kernel
def _clip(x, lo, hi):
    return x if lo < x < hi else INF


@kernel
def torus_roots(o, d, major, minor):
    """The crossings of the ray (o, d) (torus space: centre 0, axis y) with the torus: four
    ray parameters, sorted, inf-padded (a tangent touch is no crossing)."""
    scale = 1.0 / (major + minor)
    ol = (o[0] * scale, o[1] * scale, o[2] * scale)
    dl = (d[0] * scale, d[1] * scale, d[2] * scale)
    length = math.sqrt(dot(dl, dl))
    if length == 0.0:
        return INF, INF, INF, INF
    dn = (dl[0] / length, dl[1] / length, dl[2] / length)
    shift = -dot(ol, dn)  # to the point of the ray nearest the centre
    os = (ol[0] + shift * dn[0], ol[1] + shift * dn[1], ol[2] + shift * dn[2])
    h2 = 1.0 - dot(os, os)
    if h2 <= 0.0:
        return INF, INF, INF, INF
    h = math.sqrt(h2) * (1.0 + 1e-12) + 1e-12
    big = major * scale
    small = minor * scale
    r2 = big * big
    k = dot(os, os) + r2 - small * small
    bb = dot(os, dn)
    dxz = dn[0] * dn[0] + dn[2] * dn[2]
    oxz = os[0] * dn[0] + os[2] * dn[2]
    pxz = os[0] * os[0] + os[2] * os[2]
    # (s² + 2bb·s + k)² = 4R²·((ox + s·dx)² + (oz + s·dz)²)
    a = 4.0 * bb
    b = 4.0 * bb * bb + 2.0 * k - 4.0 * r2 * dxz
    c = 4.0 * bb * k - 8.0 * r2 * oxz
    e = k * k - 4.0 * r2 * pxz
    # the cubic's turning points (the quartic's second derivative 12x² + 6a·x + 2b = 0)
    q0, q1 = _quadratic_roots(12.0, 6.0 * a, 2.0 * b)
    q0 = _clip(q0, -h, h)
    q1 = _clip(q1, -h, h)
    if q0 == INF:  # split points sorted, inf-padded
        q0, q1 = q1, INF
    c0, c1, c2, _ = _split_points(3, a, b, c, e, -h, h, q0, q1, INF)
    r0, r1, r2_, r3 = _split_points(4, a, b, c, e, -h, h, c0, c1, c2)
    inv = 1.0 / length
    return ((r0 + shift) * inv, (r1 + shift) * inv, (r2_ + shift) * inv, (r3 + shift) * inv)


@kernel
def torus_local(P, i, o, d):
    """The ray in the torus's frame (centre at the origin, axis y)."""
    q = sub(o, vload(P, i, 0))
    x = vload(P, i, 3)
    y = vload(P, i, 6)
    z = vload(P, i, 9)
    return (dot(q, x), dot(q, y), dot(q, z)), (dot(d, x), dot(d, y), dot(d, z))


@kernel
def intersect_torus(P, i, o, d, tmin, tmax):
    """Nearest crossing in (tmin, tmax) of the ray with torus row ``i`` (INF on a miss)."""
    lo, ld = torus_local(P, i, o, d)
    t0, t1, t2, t3 = torus_roots(lo, ld, P[i, 12], P[i, 13])
    if tmin < t0 < tmax:
        return t0
    if tmin < t1 < tmax:
        return t1
    if tmin < t2 < tmax:
        return t2
    if tmin < t3 < tmax:
        return t3
    return INF


@kernel
def torus_normal(P, i, p):
    """Outward unit normal of torus row ``i`` at point ``p`` on it."""
    lp, _ = torus_local(P, i, p, p)
    rho = math.sqrt(lp[0] * lp[0] + lp[2] * lp[2])
    if rho == 0.0:
        n = (0.0, 1.0, 0.0)
    else:
        f = P[i, 12] / rho
        n = (lp[0] - f * lp[0], lp[1], lp[2] - f * lp[2])
    x = vload(P, i, 3)
    y = vload(P, i, 6)
    z = vload(P, i, 9)
    return normalize((n[0] * x[0] + n[1] * y[0] + n[2] * z[0],
                      n[0] * x[1] + n[1] * y[1] + n[2] * z[1],
                      n[0] * x[2] + n[1] * y[2] + n[2] * z[2]))


@kernel
def torus_uv(P, i, p):
    """(u, v) at point ``p`` on torus row ``i``: u the angle around the axis, from +x toward
    -z (counter-clockwise seen from +y), v the angle around the tube, from its outer equator
    up over the top; both in turns, in [0, 1)."""
    lp, _ = torus_local(P, i, p, p)
    rho = math.sqrt(lp[0] * lp[0] + lp[2] * lp[2])
    u = math.atan2(-lp[2], lp[0]) / (2.0 * math.pi)
    v = math.atan2(lp[1], rho - P[i, 12]) / (2.0 * math.pi)
    if u < 0.0:
        u += 1.0
    if v < 0.0:
        v += 1.0
    return u, v
