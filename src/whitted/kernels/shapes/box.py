"""The box (a parallelepiped): its crossings, its nearest hit, its normal and its uv.

A box row (layout.SHAPE_BOX) holds its corner 0:3 and the inverse of its edge matrix, rows
3:12: in the box's own coordinates, ``local = M^-1 (p - corner)``, it is the unit cube.
"""

from __future__ import annotations

import math

from ...jit import kernel
from ..vec import normalize, sub, vload
from . import INF


@kernel
def box_local(P, i, x):
    """Row-vector product M^-1 x with the inverse edge matrix stored row-major at 3:12."""
    return (
        P[i, 3] * x[0] + P[i, 4] * x[1] + P[i, 5] * x[2],
        P[i, 6] * x[0] + P[i, 7] * x[1] + P[i, 8] * x[2],
        P[i, 9] * x[0] + P[i, 10] * x[1] + P[i, 11] * x[2],
    )


@kernel
def box_span(P, i, o, d):
    """(enter, leave): where the ray's line crosses box row ``i`` ((inf, inf): nowhere)."""
    lo = box_local(P, i, sub(o, vload(P, i, 0)))
    ld = box_local(P, i, d)
    t_near = -INF
    t_far = INF
    for k in range(3):
        if ld[k] == 0.0:
            if lo[k] < 0.0 or lo[k] > 1.0:
                return INF, INF
            continue
        inv = 1.0 / ld[k]
        t0 = -lo[k] * inv
        t1 = (1.0 - lo[k]) * inv
        if t0 > t1:
            t0, t1 = t1, t0
        t_near = max(t_near, t0)
        t_far = min(t_far, t1)
        if t_near > t_far:
            return INF, INF
    return t_near, t_far


@kernel
def intersect_box(P, i, o, d, tmin, tmax):
    """Slab test in the box's own coordinates, where it is the unit cube [0, 1]^3."""
    t_near, t_far = box_span(P, i, o, d)
    if tmin < t_near < tmax:
        return t_near
    if tmin < t_far < tmax:
        return t_far
    return INF


@kernel(inline="always")
def box_normal(P, i, p):
    """Outward unit normal at ``p``: of the face nearest it in the box's own coordinates."""
    lp = box_local(P, i, sub(p, vload(P, i, 0)))
    best_k = 0
    best_side = -1.0
    best_dist = math.inf
    for k in range(3):
        if abs(lp[k]) < best_dist:
            best_dist = abs(lp[k])
            best_k = k
            best_side = -1.0
        if abs(1.0 - lp[k]) < best_dist:
            best_dist = abs(1.0 - lp[k])
            best_k = k
            best_side = 1.0
    row = 3 + 3 * best_k
    return normalize(
        (best_side * P[i, row], best_side * P[i, row + 1], best_side * P[i, row + 2])
    )


@kernel
def box_uv(P, i, p):
    """Per face, the two in-face box coordinates in 0..1 (faces across x: u along z, v along
    y; across y: u along x, v along z; across z: u along x, v along y)."""
    lp = box_local(P, i, sub(p, vload(P, i, 0)))
    best_k = 0
    best_dist = math.inf
    for k in range(3):
        gap = min(abs(lp[k]), abs(1.0 - lp[k]))
        if gap < best_dist:
            best_dist = gap
            best_k = k
    if best_k == 0:  # faces across x: u along z, v along y
        return lp[2], lp[1]
    if best_k == 1:  # faces across y: u along x, v along z
        return lp[0], lp[2]
    return lp[0], lp[1]
