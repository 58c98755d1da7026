"""Helpers every BVH walk shares (the scene's, the instances' and each mesh's own): the slab
test of a node box, a ray's safe inverse direction, pushing a binary node's children nearest
last, the walk of the scene BVH's eight-wide nodes (all eight boxes of a node tested in one
loop), and the test of a box against a cone of rays (shadow bundles, light buffers). The
boxes may be float64 (the instances' BVH) or float32 rounded outward (the scene's, meshes)."""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .intersect import INF
from .layout import WIDE

TINY_DIRECTION = 1e-30  # stands in for a zero direction component in the slab test


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


@kernel(inline="always")
def slab_entry(lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, o, inv, tmin, tmax):
    """Entry distance of the ray into the box (lo, hi) when it overlaps (tmin, tmax), else
    INF: the slab test every node box of every BVH level goes through."""
    t0 = (lo_x - o[0]) * inv[0]
    t1 = (hi_x - o[0]) * inv[0]
    tn = min(t0, t1)
    tf = max(t0, t1)
    t0 = (lo_y - o[1]) * inv[1]
    t1 = (hi_y - o[1]) * inv[1]
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    t0 = (lo_z - o[2]) * inv[2]
    t1 = (hi_z - o[2]) * inv[2]
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    # the relative slack keeps flat boxes (a rectangle in a plane) from being missed
    if tf * (1.0 + 1e-9) + 1e-12 < max(tn, tmin) or tn > tmax:
        return INF
    return tn


@kernel
def box_entry(box, node, o, inv, tmin, tmax):
    """Entry distance of the ray into box ``node`` when it overlaps (tmin, tmax), else INF."""
    node = np.uint64(node)  # unsigned: no negative-index wraparound code on the six loads
    return slab_entry(box[node, 0, 0], box[node, 0, 1], box[node, 0, 2], box[node, 1, 0],
                      box[node, 1, 1], box[node, 1, 2], o, inv, tmin, tmax)


@kernel(inline="always")
def push_children(box, link, node, o, inv, tmin, tmax, stack, top):
    """Push the children of interior ``node`` that the ray meets, the farther one first so
    the nearer one is visited next; returns the new stack top."""
    left = node + 1
    right = link[np.uint64(node), 0]
    t_left = box_entry(box, left, o, inv, tmin, tmax)
    t_right = box_entry(box, right, o, inv, tmin, tmax)
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
    return top


@kernel(inline="always")
def cone_meets_box(box, w, c, p, axis, radius):
    """Could the cone from apex ``p`` to the ball of ``radius`` around ``p + axis`` (an area
    light's disk seen from a shaded point, a light-buffer cell's rays) meet the box of child
    ``c`` of wide scene node ``w``? Conservative: the cone's cross-section at parameter t
    along the axis, a disk of radius t·radius, is widened to the square of that half-width,
    and the box test becomes six linear bounds on t in [0, 1]."""
    t_lo = 0.0
    t_hi = 1.0
    for k in range(3):
        lo = box[w, k, c] - p[k]
        hi = box[w, 3 + k, c] - p[k]
        a = axis[k] + radius  # the square's far edge reaches the box's low face: t·a >= lo
        if a > 0.0:
            t_lo = max(t_lo, lo / a)
        elif a < 0.0:
            t_hi = min(t_hi, lo / a)
        elif lo > 0.0:
            return False
        b = axis[k] - radius  # its near edge stays below the box's high face: t·b <= hi
        if b > 0.0:
            t_hi = min(t_hi, hi / b)
        elif b < 0.0:
            t_lo = max(t_lo, hi / b)
        elif hi < 0.0:
            return False
    # the relative slack keeps flat boxes (a rectangle in a plane) in
    return t_lo <= t_hi * (1.0 + 1e-9) + 1e-12


@kernel(inline="always")
def wide_hits(box, link, w, o, inv, tmin, tmax):
    """Bit c set for each child c of wide scene node ``w`` whose box the ray meets on
    (tmin, tmax): :func:`slab_entry`'s test on all eight lanes in one loop (vector
    instructions), the lanes without a child left out."""
    w = np.uint64(w)
    mask = np.int64(0)
    for c in range(WIDE):
        t0 = (box[w, 0, c] - o[0]) * inv[0]
        t1 = (box[w, 3, c] - o[0]) * inv[0]
        tn = min(t0, t1)
        tf = max(t0, t1)
        t0 = (box[w, 1, c] - o[1]) * inv[1]
        t1 = (box[w, 4, c] - o[1]) * inv[1]
        tn = max(tn, min(t0, t1))
        tf = min(tf, max(t0, t1))
        t0 = (box[w, 2, c] - o[2]) * inv[2]
        t1 = (box[w, 5, c] - o[2]) * inv[2]
        tn = max(tn, min(t0, t1))
        tf = min(tf, max(t0, t1))
        miss = (tf * (1.0 + 1e-9) + 1e-12 < max(tn, tmin)) | (tn > tmax)
        hit = (link[w, 1, c] >= 0) & ~miss
        mask |= np.int64(hit) << np.int64(c)
    return mask


@kernel(inline="always")
def lane_entry(box, w, c, o, inv, tmin, tmax):
    """:func:`slab_entry` of child ``c`` of wide scene node ``w``."""
    w = np.uint64(w)
    c = np.uint64(c)
    return slab_entry(box[w, 0, c], box[w, 1, c], box[w, 2, c], box[w, 3, c], box[w, 4, c],
                      box[w, 5, c], o, inv, tmin, tmax)


@kernel(inline="always")
def lowest_bit(mask):
    """Index of the lowest set bit of ``mask`` (nonzero)."""
    c = 0
    while (mask >> np.int64(c)) & np.int64(1) == 0:
        c += 1
    return c


@kernel
def start_scene_walk(geo, stack):
    """Begin a walk of the scene BVH: its root on the stack. Returns the cursor
    (j, leaf, leaf_end, top) that :func:`next_scene_candidate` takes."""
    if geo.node_box.shape[0] == 0:
        return 0, 0, 0, -1
    stack[0] = 0
    return 0, 0, 0, 0


@kernel(inline="always")
def next_scene_candidate(geo, o, inv, tmin, tmax, stack, j, leaf, leaf_end, top, ordered):
    """The next analytic primitive a ray on (tmin, tmax) may hit: first the unbounded ones,
    then those of the scene BVH's leaves whose boxes it meets. The walk's state is the cursor
    (j, leaf, leaf_end, top), passed in and returned with the primitive (-1 when the walk is
    over). A stack entry is a wide node (>= 0) or a leaf, -1 - (8·node + lane) (its box
    tested again when popped by a closest-hit walk). ``ordered`` goes down the nearest child
    first (closest-hit walks, which pass the nearest hit so far as ``tmax``); any-hit walks
    take the children as they come."""
    box = geo.node_box
    link = geo.node_link
    while True:
        if j < geo.unbounded.shape[0]:
            return geo.unbounded[np.uint64(j)], j + 1, leaf, leaf_end, top
        if leaf < leaf_end:
            return geo.node_prims[np.uint64(leaf)], j, leaf + 1, leaf_end, top
        if top < 0:
            return -1, j, leaf, leaf_end, top
        w = stack[top]
        top -= 1
        if w < 0:  # a leaf
            g = -1 - w
            c = g & (WIDE - 1)
            w = g // WIDE
            if ordered and lane_entry(box, w, c, o, inv, tmin, tmax) == INF:
                continue
            leaf = link[np.uint64(w), 0, np.uint64(c)]
            leaf_end = leaf + link[np.uint64(w), 1, np.uint64(c)]
            continue
        while True:
            mask = wide_hits(box, link, w, o, inv, tmin, tmax)
            if mask == 0:
                break
            near = -1
            if ordered:
                # down the nearest child directly; the others wait on the stack
                t_near = INF
                rest = mask
                while rest != 0:
                    c = lowest_bit(rest)
                    rest &= rest - 1
                    t = lane_entry(box, w, c, o, inv, tmin, tmax)
                    if t < t_near or near < 0:
                        t_near = t
                        near = c
                mask &= ~(np.int64(1) << np.int64(near))
            while mask != 0:
                c = lowest_bit(mask)
                mask &= mask - 1
                top += 1
                if link[np.uint64(w), 1, np.uint64(c)] == 0:
                    stack[top] = link[np.uint64(w), 0, np.uint64(c)]
                else:
                    stack[top] = -1 - (WIDE * w + c)
            if near < 0:
                break
            if link[np.uint64(w), 1, np.uint64(near)] > 0:
                leaf = link[np.uint64(w), 0, np.uint64(near)]
                leaf_end = leaf + link[np.uint64(w), 1, np.uint64(near)]
                break
            w = link[np.uint64(w), 0, np.uint64(near)]
