"""Roots of the quadratics the quadric shapes (sphere, cylinder, cone) are solved by."""

from __future__ import annotations

import math

from ...jit import kernel
from . import INF


@kernel
def quadratic_roots(a, b, c):
    """Both roots (t0 <= t1) of a·t² + 2b·t + c = 0, a != 0 (numerically stable form);
    (inf, inf) when there are none."""
    disc = b * b - a * c
    if disc < 0.0:
        return INF, INF
    sq = math.sqrt(disc)
    q = -(b + sq) if b >= 0.0 else -(b - sq)
    if q == 0.0:
        return -b / a, -b / a
    t0 = q / a
    t1 = c / q
    return (t0, t1) if t0 <= t1 else (t1, t0)


@kernel
def nearest_root(a, b, c, tmin, tmax):
    """Nearest root in (tmin, tmax) of a·t² + 2b·t + c = 0."""
    if a == 0.0:
        if b == 0.0:
            return INF
        t = -c / (2.0 * b)
        return t if tmin < t < tmax else INF
    t0, t1 = quadratic_roots(a, b, c)
    if tmin < t0 < tmax:
        return t0
    if tmin < t1 < tmax:
        return t1
    return INF
