"""The torus: exact ray intersection (a quartic), normals and texture coordinates.

A torus row (layout.SHAPE_TORUS) holds its centre, the object's x, y, z axes in world space
and the two radii, the scale baked in; under a non-similarity transform the row is in the
object's own space and the ray arrives mapped there (``PRIM_XFORM``).

The quartic is solved robustly rather than by Ferrari's formulas, whose cancellations put
acne on grazing hits: the ray is first scaled so the torus fits in the unit ball and moved
along itself to the point nearest the centre (the coefficients stay of order one whatever
the distance of the eye); the roots can then only lie on the chord of the unit ball,
[-h, h], on its part inside the slab that holds the tube (|y| <= the minor radius), less
a ray through the hole. The roots of the quartic's second derivative (a quadratic, solved
in closed form) split that part into at most three pieces where it bends one way only. On
such a piece a sign change between the ends is one root, and Newton's method started from
the end where the function and its curvature have the same sign (Fourier's condition) walks
to it monotonically without leaving the piece, in five or six steps; both ends on the far
side of zero from the bend are no root; both ends on its side are none unless the function
dips across zero between, which the tangents at the ends bound, and only then is the
slope's root (the cubic's, found the same way) solved and the piece cut in two with a root
each. A piece whose end is exactly a root (rays symmetric about the centre) goes the older
way: every root of the cubic first, cutting monotonic pieces. A root where the quartic only
touches zero (a ray exactly tangent to the surface) is no crossing
and is not reported. Every root is computed from the ray alone, not from ``tmin``: asking
again from past one root gives the next one exactly (CSG walks rely on it).

A spindle torus (minor radius above the major) is the solid of every point within the minor
radius of the centre circle: the lemon-shaped region around the centre, where the tube
overlaps itself, is inside it. The quartic also vanishes on that lemon's surface; those
crossings bound nothing and are dropped, so a ray meets only the outer (apple-shaped)
surface, in the renderer and in CSG alike.
"""

from __future__ import annotations

import math

from ...jit import kernel
from ..vec import dot, normalize, sub, vload
from . import INF

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
def _append(n, r, out0, out1, out2, out3):
    """(n + 1, the four slots with ``r`` in slot n) when r is finite and a slot is left,
    else (n, the slots as they were)."""
    if r == INF or n > 3:
        return n, out0, out1, out2, out3
    if n == 0:
        return 1, r, out1, out2, out3
    if n == 1:
        return 2, out0, r, out2, out3
    if n == 2:
        return 3, out0, out1, r, out3
    return 4, out0, out1, out2, r


@kernel(inline="always")
def _ordered(x, y):
    return (x, y) if x <= y else (y, x)


@kernel
def _roots_between(deg, a, b, c, e, lo, hi, s0, s1, s2, s3, s4):
    """Roots in (lo, hi) of the quartic (deg 4) or its derivative (deg 3), given sorted split
    points s0..s4 (inf: unused) cutting it into monotonic pieces of one curvature: up to four,
    sorted, inf-padded."""
    n, out0, out1, out2, out3 = 0, INF, INF, INF, INF  # the roots found so far
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
        n, out0, out1, out2, out3 = _append(n, root, out0, out1, out2, out3)
        x0 = x1
        f0 = f1
    return out0, out1, out2, out3


@kernel(inline="always")
def _least_slope(a, b, c, e, x0, x1, df0):
    """Where the quartic's slope (the cubic) crosses zero in (x0, x1), a piece where it is
    monotonic and is ``df0`` at x0: Newton on its pieces of one curvature (cut at -a/4)."""
    m = -0.25 * a
    if x0 < m < x1:
        dm, _, _ = _poly(3, a, b, c, e, m)
        if dm == 0.0:
            return m
        if (dm > 0.0) == (df0 > 0.0):  # the same sign as at x0: the zero lies past m
            return _piece_root(3, a, b, c, e, m, x1, dm)
        return _piece_root(3, a, b, c, e, x0, m, df0)
    return _piece_root(3, a, b, c, e, x0, x1, df0)


@kernel
def _curved_piece_roots(a, b, c, e, x0, x1, f0, df0, f1, df1, convex):
    """The quartic's roots in (x0, x1), a piece where it bends one way (``convex``: f'' >
    0), neither end a root: up to two, sorted, inf-padded. With g = ±f convex: below zero at
    both ends, g is below all along; one sign change is one root, found by Newton from the
    end where g > 0 (Fourier's); above zero at both ends there are none unless g falls below
    zero between, which the tangents at the ends bound from below, and then the least value's
    place (the cubic's root) splits the piece in two with a root each."""
    s = 1.0 if convex else -1.0
    g0 = s * f0
    g1 = s * f1
    if g0 < 0.0 and g1 < 0.0:
        return INF, INF
    if g0 < 0.0 or g1 < 0.0:
        return _piece_root(4, a, b, c, e, x0, x1, f0), INF
    dg0 = s * df0
    dg1 = s * df1
    if dg0 >= 0.0 or dg1 <= 0.0:  # monotonic: its least value is at an end
        return INF, INF
    xc = (g1 - g0 + dg0 * x0 - dg1 * x1) / (dg0 - dg1)
    if g0 + dg0 * (xc - x0) > 0.0:  # the tangents meet above zero: so does g
        return INF, INF
    xm = _least_slope(a, b, c, e, x0, x1, df0)
    fm, _, _ = _poly(4, a, b, c, e, xm)
    if s * fm >= 0.0:  # above zero, or a touch: no crossing
        return INF, INF
    return _piece_root(4, a, b, c, e, x0, xm, f0), _piece_root(4, a, b, c, e, xm, x1, fm)


@kernel(inline="always")
def _roots_by_curvature(a, b, c, e, lo, hi, q0, q1):
    """(ok, r0, r1, r2, r3): the quartic's roots in (lo, hi), piece by piece between its
    inflections q0 <= q1 (inf: none there), where it bends one way
    (:func:`_curved_piece_roots`); not ok when a piece's end is itself a root or a piece has
    no curvature at its middle (the general path decides those)."""
    n, out0, out1, out2, out3 = 0, INF, INF, INF, INF  # the roots found so far
    x0 = lo
    f0, df0, _ = _poly(4, a, b, c, e, x0)
    if f0 == 0.0:
        return False, INF, INF, INF, INF
    for k in range(3):
        x1 = min(q0 if k == 0 else (q1 if k == 1 else hi), hi)
        if x1 <= x0:
            continue
        f1, df1, _ = _poly(4, a, b, c, e, x1)
        _, _, dd_mid = _poly(4, a, b, c, e, 0.5 * (x0 + x1))
        if f1 == 0.0 or dd_mid == 0.0:
            return False, INF, INF, INF, INF
        ra, rb = _curved_piece_roots(a, b, c, e, x0, x1, f0, df0, f1, df1, dd_mid > 0.0)
        n, out0, out1, out2, out3 = _append(n, ra, out0, out1, out2, out3)
        n, out0, out1, out2, out3 = _append(n, rb, out0, out1, out2, out3)
        x0 = x1
        f0 = f1
        df0 = df1
    return True, out0, out1, out2, out3


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
    ray parameters, sorted, inf-padded (a tangent touch is no crossing). A spindle torus's
    (minor > major) inner lemon is inside the solid: its crossings are left out
    (:func:`_outer_only`)."""
    near, shift, inv, a, b, c, e, lo, hi, q0, q1 = torus_quartic(o, d, major, minor)
    if not near:
        return INF, INF, INF, INF
    ok, r0, r1, r2, r3 = _roots_by_curvature(a, b, c, e, lo, hi, q0, q1)
    if not ok:
        r0, r1, r2, r3 = _roots_by_cubic(a, b, c, e, lo, hi, q0, q1)
    r0, r1, r2, r3 = ((r0 + shift) * inv, (r1 + shift) * inv, (r2 + shift) * inv,
                      (r3 + shift) * inv)
    if minor > major:
        return _outer_only(o, d, major, minor, r0, r1, r2, r3)
    return r0, r1, r2, r3


@kernel(inline="always")
def _on_lemon(o, d, major, minor, t):
    """Is the crossing at ray parameter ``t`` on a spindle torus's inner lemon? The quartic
    is the surface swept by the whole tube circle: a point at distance rho from the axis
    lies on the outer surface where (rho - R)^2 + y^2 = r^2, on the lemon (the circle's part
    across the axis, swept) where (rho + R)^2 + y^2 = r^2, i.e. (rho - R)^2 + y^2 =
    r^2 - 4 rho R: inside the tube. The test splits the difference."""
    if t == INF:
        return False
    x = o[0] + t * d[0]
    y = o[1] + t * d[1]
    z = o[2] + t * d[2]
    rho = math.sqrt(x * x + z * z)
    return (rho - major) * (rho - major) + y * y < minor * minor - 2.0 * rho * major


@kernel
def _outer_only(o, d, major, minor, r0, r1, r2, r3):
    """The crossings r0..r3 (sorted, inf-padded) without those on a spindle torus's inner
    lemon: the solid is every point within the minor radius of the centre circle, the lemon
    included (as POV-Ray 3.7's inside test has it), so the lemon's surface bounds nothing
    and the solid's inside is where an odd number of the crossings left lie behind."""
    n, out0, out1, out2, out3 = 0, INF, INF, INF, INF
    if not _on_lemon(o, d, major, minor, r0):
        n, out0, out1, out2, out3 = _append(n, r0, out0, out1, out2, out3)
    if not _on_lemon(o, d, major, minor, r1):
        n, out0, out1, out2, out3 = _append(n, r1, out0, out1, out2, out3)
    if not _on_lemon(o, d, major, minor, r2):
        n, out0, out1, out2, out3 = _append(n, r2, out0, out1, out2, out3)
    if not _on_lemon(o, d, major, minor, r3):
        n, out0, out1, out2, out3 = _append(n, r3, out0, out1, out2, out3)
    return out0, out1, out2, out3


@kernel(inline="always")
def torus_quartic(o, d, major, minor):
    """The ray (o, d) as the torus's quartic x⁴ + a·x³ + b·x² + c·x + e in x, the distance
    along the unit ray (scaled so the torus fits the unit ball) from the point nearest the
    centre: (near, shift, inv, a, b, c, e, lo, hi, q0, q1), where the roots can only lie in
    (lo, hi), q0 <= q1 are the quartic's inflections there (inf: none), and a root x is the
    ray parameter (x + shift)·inv. ``near`` is False when the ray cannot meet the torus."""
    none = (False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, INF, INF)
    scale = 1.0 / (major + minor)
    ol = (o[0] * scale, o[1] * scale, o[2] * scale)
    dl = (d[0] * scale, d[1] * scale, d[2] * scale)
    length = math.sqrt(dot(dl, dl))
    if length == 0.0:
        return none
    dn = (dl[0] / length, dl[1] / length, dl[2] / length)
    shift = -dot(ol, dn)  # to the point of the ray nearest the centre
    os = (ol[0] + shift * dn[0], ol[1] + shift * dn[1], ol[2] + shift * dn[2])
    h2 = 1.0 - dot(os, os)
    if h2 <= 0.0:
        return none
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
            return none
    elif abs(os[1]) > small:
        return none
    # through the hole: the tube has no point nearer the axis than big - small, and the
    # squared distance from the axis is convex along the ray, so below that at both ends of
    # the part in the slab it is below it all along (a face-on torus: a fifth of the rays
    # that reach the solve, none of them a crossing)
    inner2 = (big - small) * (big - small) * (1.0 - 1e-12)
    if (big > small and _axis_distance2(os, dn, lo) < inner2
            and _axis_distance2(os, dn, hi) < inner2):
        return none
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
    # the quartic's inflections (the roots of 12x² + 6a·x + 2b)
    q0, q1 = _quadratic_roots(12.0, 6.0 * a, 2.0 * b)
    q0, q1 = _ordered(_clip(q0, lo, hi), _clip(q1, lo, hi))
    return True, shift, 1.0 / length, a, b, c, e, lo, hi, q0, q1


@kernel
def _roots_by_cubic(a, b, c, e, lo, hi, q0, q1):
    """The quartic's roots in (lo, hi), sorted, inf-padded, with every root of its slope (the
    cubic) found first: they and the inflections q0 <= q1 cut it into monotonic pieces of one
    curvature. Slower than :func:`_roots_by_curvature`, and it decides the rays that one
    leaves (a root exactly on an inflection, as on rays symmetric about the centre)."""
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
    return _roots_between(4, a, b, c, e, lo, hi, v0, v1, v2, v3, v4)


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
