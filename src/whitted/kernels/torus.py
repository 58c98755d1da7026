"""The torus: exact ray intersection (a quartic), normals and texture coordinates.

A torus row (layout.SHAPE_TORUS) holds its centre, the object's x, y, z axes in world space
and the two radii, the scale baked in; under a non-similarity transform the row is in the
object's own space and the ray arrives mapped there (``PRIM_XFORM``).

The quartic is solved robustly rather than by Ferrari's formulas, whose cancellations put
acne on grazing hits: the ray is first scaled so the torus fits in the unit ball and moved
along itself to the point nearest the centre (the coefficients stay of order one whatever
the distance of the eye); the roots can then only lie on the chord of the unit ball,
[-h, h], on its part inside the slab that holds the tube (|y| <= the minor radius). The
roots of the quartic's second derivative (a quadratic, solved in closed form) and of its
first (a cubic) split that part into pieces where the quartic is monotonic and bends one
way only; each piece holds at most one root, and Newton's method started from the piece's
end where the function and its curvature have the same sign (Fourier's condition) walks to
it monotonically without leaving the piece, in five or six steps. The cubic's own roots are
found the same way, on the pieces its derivative's roots and its inflection cut. A root
where the quartic only touches zero (a ray exactly tangent to the surface) is no crossing
and is not reported. Every root is computed from the ray alone, not from ``tmin``: asking
again from past one root gives the next one exactly (CSG walks rely on it).
"""

from __future__ import annotations

import math

from .jit import kernel
from .vec import dot, normalize, sub, vload

INF = math.inf
NEWTON_STEPS = 60  # at most, per root (monotone convergence: five or six in practice)
NEWTON_TOL = 1e-13  # a step this small (relative, on the unit-ball chord) ends the search


@kernel(inline="always")
def _poly(deg, a, b, c, e, x):
    """(f, f', f'') at x of the quartic x⁴ + a·x³ + b·x² + c·x + e (deg 4) or of its
    derivative 4x³ + 3a·x² + 2b·x + c (deg 3)."""
    if deg == 4:
        f = (((x + a) * x + b) * x + c) * x + e
        df = ((4.0 * x + 3.0 * a) * x + 2.0 * b) * x + c
        ddf = (12.0 * x + 6.0 * a) * x + 2.0 * b
    else:
        f = ((4.0 * x + 3.0 * a) * x + 2.0 * b) * x + c
        df = (12.0 * x + 6.0 * a) * x + 2.0 * b
        ddf = 24.0 * x + 6.0 * a
    return f, df, ddf


@kernel
def _piece_root(deg, a, b, c, e, lo, hi, f_lo):
    """The root in [lo, hi] of the quartic (deg 4) or its derivative (deg 3), monotonic there,
    of one curvature, and of opposite signs at the ends (``f_lo`` at ``lo``): Newton's method
    from the end where f·f'' > 0, whose steps then approach the root from one side."""
    _, _, dd_mid = _poly(deg, a, b, c, e, 0.5 * (lo + hi))
    x = lo if (f_lo > 0.0) == (dd_mid > 0.0) else hi
    for _ in range(NEWTON_STEPS):
        f, df, _ = _poly(deg, a, b, c, e, x)
        if f == 0.0 or df == 0.0:
            return x
        xn = x - f / df
        if not (lo <= xn <= hi):  # rounding at the root itself
            return min(max(xn, lo), hi)
        if abs(xn - x) <= NEWTON_TOL * (1.0 + abs(x)):
            return xn
        x = xn
    return x


@kernel(inline="always")
def _ordered(x, y):
    return (x, y) if x <= y else (y, x)


@kernel
def _roots_between(deg, a, b, c, e, lo, hi, s0, s1, s2, s3, s4):
    """Roots in (lo, hi) of the quartic (deg 4) or its derivative (deg 3), given sorted split
    points s0..s4 (inf: unused) cutting it into monotonic pieces of one curvature: up to four,
    sorted, inf-padded."""
    out0 = INF
    out1 = INF
    out2 = INF
    out3 = INF
    n = 0
    x0 = lo
    f0, _, _ = _poly(deg, a, b, c, e, x0)
    zero = INF  # a split point where the function is exactly 0 (pending)
    for k in range(6):
        if k == 0:
            x1 = s0
        elif k == 1:
            x1 = s1
        elif k == 2:
            x1 = s2
        elif k == 3:
            x1 = s3
        elif k == 4:
            x1 = s4
        else:
            x1 = hi
        x1 = min(x1, hi)
        if x1 <= x0:
            continue
        f1, _, _ = _poly(deg, a, b, c, e, x1)
        root = INF
        if f1 == 0.0:  # a root on a split point (a symmetric ray): a crossing only if the
            zero = x1  # sign differs on the two sides, decided at the next piece's end
            continue
        if (f0 < 0.0 and f1 > 0.0) or (f0 > 0.0 and f1 < 0.0):
            root = zero if zero < INF else _piece_root(deg, a, b, c, e, x0, x1, f0)
        zero = INF
        if root < INF:
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
def _quadratic_roots(p, q, r):
    """Real roots (x0 <= x1) of p·x² + q·x + r, p != 0; (inf, inf) when there are none."""
    disc = q * q - 4.0 * p * r
    if disc < 0.0:
        return INF, INF
    sq = math.sqrt(disc)
    h = -0.5 * (q + sq) if q >= 0.0 else -0.5 * (q - sq)
    if h == 0.0:
        return -q / (2.0 * p), -q / (2.0 * p)
    return _ordered(h / p, r / h)


@kernel
def _clip(x, lo, hi):
    return x if lo < x < hi else INF


@kernel(inline="always")
def _axis_distance2(o, d, s):
    """Squared distance from the torus's axis (y) of the point o + s·d."""
    x = o[0] + s * d[0]
    z = o[2] + s * d[2]
    return x * x + z * z


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
    # the tube lies in the slab |y| <= small: the roots lie on the part of the chord in it
    lo = -h
    hi = h
    pad = 1e-9 * small  # past the slab's faces the quartic is positive: clear ends
    if dn[1] != 0.0:
        y0 = (-small - pad - os[1]) / dn[1]
        y1 = (small + pad - os[1]) / dn[1]
        y0, y1 = _ordered(y0, y1)
        lo = max(lo, y0)
        hi = min(hi, y1)
        if lo >= hi:
            return INF, INF, INF, INF
    elif abs(os[1]) > small:
        return INF, INF, INF, INF
    # through the hole: the tube has no point nearer the axis than big - small, and the
    # squared distance from the axis is convex along the ray, so below that at both ends of
    # the part in the slab it is below it all along (a face-on torus: a fifth of the rays
    # that reach the solve, none of them a crossing)
    inner2 = (big - small) * (big - small) * (1.0 - 1e-12)
    if (big > small and _axis_distance2(os, dn, lo) < inner2
            and _axis_distance2(os, dn, hi) < inner2):
        return INF, INF, INF, INF
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
    # the quartic's inflections (the roots of 12x² + 6a·x + 2b) and the cubic's (x = -a/4)
    q0, q1 = _quadratic_roots(12.0, 6.0 * a, 2.0 * b)
    q0, q1 = _ordered(_clip(q0, lo, hi), _clip(q1, lo, hi))
    m = _clip(-0.25 * a, lo, hi)
    # the cubic's pieces: cut at q0, m, q1 (sorted)
    p0, p1 = _ordered(q0, m)
    p1, p2 = _ordered(p1, q1)
    p0, p1 = _ordered(p0, p1)
    c0, c1, c2, _ = _roots_between(3, a, b, c, e, lo, hi, p0, p1, p2, INF, INF)
    # the quartic's pieces: cut at c0, c1, c2, q0, q1, sorted by a five-input network
    v0, v1 = _ordered(c0, c1)
    v3, v4 = _ordered(q0, q1)
    v2, v4 = _ordered(c2, v4)
    v2, v3 = _ordered(v2, v3)
    v0, v3 = _ordered(v0, v3)
    v0, v2 = _ordered(v0, v2)
    v1, v4 = _ordered(v1, v4)
    v1, v3 = _ordered(v1, v3)
    v1, v2 = _ordered(v1, v2)
    r0, r1, r2_, r3 = _roots_between(4, a, b, c, e, lo, hi, v0, v1, v2, v3, v4)
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
def torus_crossings(P, i, o, d):
    """The four crossings (sorted, inf-padded) of the ray's line with torus row ``i``."""
    lo, ld = torus_local(P, i, o, d)
    return torus_roots(lo, ld, P[i, 12], P[i, 13])


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
