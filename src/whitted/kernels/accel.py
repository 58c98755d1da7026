"""Scene-level ray queries: nearest hit through the BVH (plus the unbounded planes), and the
surface normal of a hit in world space."""

from __future__ import annotations

import math

from .intersect import INF, intersect_local, normal_local
from .jit import kernel
from .vec import normalize

TINY_DIRECTION = 1e-30  # stands in for a zero direction component in the slab test


@kernel
def to_object(xforms, xf, o, d):
    """Ray (o, d) mapped by the world-to-object matrix ``xforms[xf]``; t is unchanged."""
    lo = (
        xforms[xf, 0, 0] * o[0]
        + xforms[xf, 0, 1] * o[1]
        + xforms[xf, 0, 2] * o[2]
        + xforms[xf, 0, 3],
        xforms[xf, 1, 0] * o[0]
        + xforms[xf, 1, 1] * o[1]
        + xforms[xf, 1, 2] * o[2]
        + xforms[xf, 1, 3],
        xforms[xf, 2, 0] * o[0]
        + xforms[xf, 2, 1] * o[1]
        + xforms[xf, 2, 2] * o[2]
        + xforms[xf, 2, 3],
    )
    ld = (
        xforms[xf, 0, 0] * d[0] + xforms[xf, 0, 1] * d[1] + xforms[xf, 0, 2] * d[2],
        xforms[xf, 1, 0] * d[0] + xforms[xf, 1, 1] * d[1] + xforms[xf, 1, 2] * d[2],
        xforms[xf, 2, 0] * d[0] + xforms[xf, 2, 1] * d[1] + xforms[xf, 2, 2] * d[2],
    )
    return lo, ld


@kernel
def hit_primitive(geo, i, o, d, tmin, tmax):
    xf = geo.prim_xform[i]
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
    return intersect_local(geo.prim_type[i], geo.prim_params, i, o, d, tmin, tmax)


@kernel
def world_normal(geo, i, p):
    """Outward unit geometric normal of primitive ``i`` at world point ``p``. Under an affine
    transform normals map by the transpose of the world-to-object matrix, which keeps them
    perpendicular to the surface even under non-uniform scale."""
    xf = geo.prim_xform[i]
    if xf < 0:
        return normal_local(geo.prim_type[i], geo.prim_params, i, p)
    m = geo.xforms
    lp, _ = to_object(m, xf, p, p)
    n = normal_local(geo.prim_type[i], geo.prim_params, i, lp)
    return normalize(
        (
            m[xf, 0, 0] * n[0] + m[xf, 1, 0] * n[1] + m[xf, 2, 0] * n[2],
            m[xf, 0, 1] * n[0] + m[xf, 1, 1] * n[1] + m[xf, 2, 1] * n[2],
            m[xf, 0, 2] * n[0] + m[xf, 1, 2] * n[1] + m[xf, 2, 2] * n[2],
        )
    )


@kernel
def _safe_inverse(x):
    if abs(x) < TINY_DIRECTION:
        return 1.0 / math.copysign(TINY_DIRECTION, x)
    return 1.0 / x


@kernel
def inverse_direction(d):
    """1/d per component, with zero components replaced by a huge finite value so the slab
    test never computes 0·inf."""
    return (_safe_inverse(d[0]), _safe_inverse(d[1]), _safe_inverse(d[2]))


@kernel
def box_entry(bmin, bmax, node, o, inv, tmin, tmax):
    """Entry distance of the ray into box ``node`` when it overlaps (tmin, tmax), else INF."""
    t0 = (bmin[node, 0] - o[0]) * inv[0]
    t1 = (bmax[node, 0] - o[0]) * inv[0]
    tn = min(t0, t1)
    tf = max(t0, t1)
    t0 = (bmin[node, 1] - o[1]) * inv[1]
    t1 = (bmax[node, 1] - o[1]) * inv[1]
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    t0 = (bmin[node, 2] - o[2]) * inv[2]
    t1 = (bmax[node, 2] - o[2]) * inv[2]
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    # the relative slack keeps flat boxes (a rectangle in a plane) from being missed
    if tf * (1.0 + 1e-9) + 1e-12 < max(tn, tmin) or tn > tmax:
        return INF
    return tn


@kernel
def closest_hit(geo, o, d, tmin, tmax, stack):
    """Nearest primitive hit by the ray in (tmin, tmax): returns (t, primitive) or (tmax, -1).
    ``stack`` is caller-owned int32 scratch space (64 entries suffice for any SAH tree)."""
    best_t = tmax
    best = -1
    for j in range(geo.unbounded.shape[0]):
        i = geo.unbounded[j]
        t = hit_primitive(geo, i, o, d, tmin, best_t)
        if t < best_t:
            best_t = t
            best = i
    if geo.node_min.shape[0] == 0:
        return best_t, best
    bmin = geo.node_min
    bmax = geo.node_max
    inv = inverse_direction(d)
    if box_entry(bmin, bmax, 0, o, inv, tmin, best_t) == INF:
        return best_t, best
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        count = geo.node_count[node]
        if count > 0:
            first = geo.node_offset[node]
            for j in range(first, first + count):
                i = geo.node_prims[j]
                t = hit_primitive(geo, i, o, d, tmin, best_t)
                if t < best_t:
                    best_t = t
                    best = i
            continue
        left = node + 1
        right = geo.node_offset[node]
        t_left = box_entry(bmin, bmax, left, o, inv, tmin, best_t)
        t_right = box_entry(bmin, bmax, right, o, inv, tmin, best_t)
        # push the farther child first so the nearer one is visited next
        if t_left <= t_right:
            if t_right != INF:
                top += 1
                stack[top] = right
            if t_left != INF:
                top += 1
                stack[top] = left
        else:
            if t_left != INF:
                top += 1
                stack[top] = left
            if t_right != INF:
                top += 1
                stack[top] = right
    return best_t, best
