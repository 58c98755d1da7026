"""Helpers every BVH walk shares (the scene's, the instances' and each mesh's own): the slab
test of a node box, a ray's safe inverse direction, pushing a node's children nearest
last, the any-hit walk of the scene BVH's eight-wide nodes (all eight boxes of a node tested
in one loop), and the test of a node box against a cone of rays (shadow bundles, light
buffers). The boxes may be float64 (scene level), float32 rounded outward (meshes, the scene's
wide nodes)."""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .layout import WIDE, WIDE_COUNT, WIDE_LINK
from .shapes import INF

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
def bvh_frame_ray(geo, o, d, inv):
    """The ray (o, d) of inverse direction ``inv`` as the scene BVH's boxes see it: (origin,
    inverse direction) turned by ``geo.bvh_frame`` (compile/bvh_frame.py), or unchanged when
    the BVH is in world space. Only box tests use it; primitives are tested in world space."""
    f = geo.bvh_frame
    if f.shape[0] == 0:
        return o, inv
    fo = (f[0, 0] * o[0] + f[0, 1] * o[1] + f[0, 2] * o[2],
          f[1, 0] * o[0] + f[1, 1] * o[1] + f[1, 2] * o[2],
          f[2, 0] * o[0] + f[2, 1] * o[1] + f[2, 2] * o[2])
    fd = (f[0, 0] * d[0] + f[0, 1] * d[1] + f[0, 2] * d[2],
          f[1, 0] * d[0] + f[1, 1] * d[1] + f[1, 2] * d[2],
          f[2, 0] * d[0] + f[2, 1] * d[1] + f[2, 2] * d[2])
    return fo, inverse_direction(fd)


@kernel(inline="always")
def bvh_frame_point(geo, p):
    """Point or vector ``p`` turned into the scene BVH's frame (unchanged in world space):
    the cone tests' apex and axis."""
    f = geo.bvh_frame
    if f.shape[0] == 0:
        return p
    return (f[0, 0] * p[0] + f[0, 1] * p[1] + f[0, 2] * p[2],
            f[1, 0] * p[0] + f[1, 1] * p[1] + f[1, 2] * p[2],
            f[2, 0] * p[0] + f[2, 1] * p[1] + f[2, 2] * p[2])


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
def order_children(box, link, node, o, inv, tmin, tmax):
    """The children of interior ``node`` nearer first, with the ray's entry distances:
    (near, t_near, far, t_far); INF where the ray misses a child's box. Ties go to the
    left child."""
    near = node + 1
    far = link[np.uint64(node), 0]
    t_near = box_entry(box, near, o, inv, tmin, tmax)
    t_far = box_entry(box, far, o, inv, tmin, tmax)
    if t_far < t_near:
        return far, t_far, near, t_near
    return near, t_near, far, t_far


@kernel(inline="always")
def push_children(box, link, node, o, inv, tmin, tmax, stack, top):
    """Push the children of interior ``node`` that the ray meets, the farther one first so
    the nearer one is visited next; returns the new stack top. (Written out rather than on
    top of :func:`order_children`: through that the mesh walk ran 20 % slower.)"""
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
def cone_meets_box(box, node, p, axis, radius):
    """Could the cone from apex ``p`` to the ball of ``radius`` around ``p + axis`` (an area
    light's disk seen from a shaded point, a light-buffer cell's rays) meet box ``node``?
    Conservative: the cone's cross-section at parameter t along the axis, a disk of radius
    t·radius, is widened to the square of that half-width, and the box test becomes six
    linear bounds on t in [0, 1]."""
    t_lo = 0.0
    t_hi = 1.0
    for k in range(3):
        lo = box[node, 0, k] - p[k]
        hi = box[node, 1, k] - p[k]
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


# an ordered walk's waiting node carries floor(entry distance · ENTRY_SCALE) - 1, clamped to
# int32: never above the true distance (so it only skips boxes a nearer hit has closed off)
ENTRY_SCALE = 65536.0
_ENTRY_MAX = 2147483647.0
_ENTRY_NONE = -2147483648  # entered before the segment's start, or no bound (NaN)


@kernel(inline="always")
def entry_bound(t):
    """An int32 lower bound on ``t`` · ENTRY_SCALE for ``t`` >= 0 (clamped at the int32
    maximum), and the int32 minimum for a negative or NaN ``t`` (the walks' ``tmax`` is
    never negative, so such a box is never skipped)."""
    x = t * ENTRY_SCALE
    if x > 0.0:
        if x < _ENTRY_MAX:
            return np.int32(np.floor(x) - 1.0)
        return np.int32(_ENTRY_MAX)
    return np.int32(_ENTRY_NONE)


@kernel
def start_scene_walk(geo, stack, ordered):
    """Begin a walk of the scene BVH: its root on the stack (an ordered walk's entries are
    (node, entry bound) pairs, the root's bound the lowest). Returns the cursor
    (j, leaf, leaf_end, top) that :func:`next_scene_candidate` takes."""
    if geo.node_box.shape[0] == 0:
        return 0, 0, 0, -1
    stack[0] = 0
    if ordered:
        stack[1] = _ENTRY_NONE
        return 0, 0, 0, 1
    return 0, 0, 0, 0


@kernel(inline="always")
def wide_hits(wide, w, o, inv, tmin, tmax):
    """Bit c set for each child c of wide scene node ``w`` (``GeometryArrays.node_wide``)
    whose box the ray meets on (tmin, tmax): :func:`slab_entry`'s test on all eight lanes in
    one loop (vector instructions), the lanes without a child left out."""
    w = np.uint64(w)
    mask = np.int64(0)
    for c in range(WIDE):
        t0 = (wide[w, 0, c] - o[0]) * inv[0]
        t1 = (wide[w, 3, c] - o[0]) * inv[0]
        tn = min(t0, t1)
        tf = max(t0, t1)
        t0 = (wide[w, 1, c] - o[1]) * inv[1]
        t1 = (wide[w, 4, c] - o[1]) * inv[1]
        tn = max(tn, min(t0, t1))
        tf = min(tf, max(t0, t1))
        t0 = (wide[w, 2, c] - o[2]) * inv[2]
        t1 = (wide[w, 5, c] - o[2]) * inv[2]
        tn = max(tn, min(t0, t1))
        tf = min(tf, max(t0, t1))
        miss = (tf * (1.0 + 1e-9) + 1e-12 < max(tn, tmin)) | (tn > tmax)
        hit = (wide[w, WIDE_COUNT, c] >= 0.0) & ~miss
        mask |= np.int64(hit) << np.int64(c)
    return mask


@kernel(inline="always")
def lowest_bit(mask):
    """Index of the lowest set bit of ``mask`` (nonzero)."""
    c = 0
    while (mask >> np.int64(c)) & np.int64(1) == 0:
        c += 1
    return c


@kernel(inline="always")
def _next_wide_candidate(geo, o, inv, tmin, tmax, stack, j, leaf, leaf_end, top):
    """:func:`next_scene_candidate` of an any-hit walk, through the wide nodes."""
    wide = geo.node_wide
    while True:
        if j < geo.unbounded.shape[0]:
            return geo.unbounded[np.uint64(j)], j + 1, leaf, leaf_end, top
        if leaf < leaf_end:
            return geo.node_prims[np.uint64(leaf)], j, leaf + 1, leaf_end, top
        if top < 0:
            return -1, j, leaf, leaf_end, top
        w = stack[top]
        top -= 1
        if w < 0:  # a leaf (its box was tested in its parent)
            g = np.uint64(-1 - w)
            lw = g // np.uint64(WIDE)
            lc = g % np.uint64(WIDE)
            leaf = int(wide[lw, WIDE_LINK, lc])
            leaf_end = leaf + int(wide[lw, WIDE_COUNT, lc])
            continue
        mask = wide_hits(wide, w, o, inv, tmin, tmax)
        while mask != 0:
            c = lowest_bit(mask)
            mask &= mask - 1
            top += 1
            if wide[np.uint64(w), WIDE_COUNT, np.uint64(c)] == 0.0:
                stack[top] = int(wide[np.uint64(w), WIDE_LINK, np.uint64(c)])
            else:
                stack[top] = -1 - (WIDE * w + c)


@kernel(inline="always")
def next_scene_candidate(geo, o, inv, tmin, tmax, stack, j, leaf, leaf_end, top, ordered):
    """The next analytic primitive a ray on (tmin, tmax) may hit: first the unbounded ones,
    then those of the scene BVH's leaves whose boxes it meets. The walk's state is the cursor
    (j, leaf, leaf_end, top), passed in and returned with the primitive (-1 when the walk is
    over). ``ordered`` goes down the nearer child first (closest-hit walks, which pass the
    nearest hit so far as ``tmax``) in the binary BVH, the farther one waiting on the stack
    as (node, :func:`entry_bound` of its entry distance) so that it is dropped without a
    second box test once a hit is nearer (start the walk with ``ordered`` too); any-hit
    walks skip the ordering and go through the eight-wide nodes (``node_wide``), where a
    stack entry is a wide node (>= 0) or a leaf, -1 - (8·node + lane)."""
    if not ordered and geo.node_wide.shape[0] > 0:
        return _next_wide_candidate(geo, o, inv, tmin, tmax, stack, j, leaf, leaf_end, top)
    box = geo.node_box
    while True:
        if j < geo.unbounded.shape[0]:
            return geo.unbounded[np.uint64(j)], j + 1, leaf, leaf_end, top
        if leaf < leaf_end:
            return geo.node_prims[np.uint64(leaf)], j, leaf + 1, leaf_end, top
        if top < 0:
            return -1, j, leaf, leaf_end, top
        if ordered:
            # a farther child waiting with a lower bound on its entry distance (its box was
            # tested when its parent was entered): skipped once a nearer hit is closer,
            # entered without a second box test otherwise
            node = stack[top - 1]
            entry = stack[top]
            top -= 2
            if entry > tmax * ENTRY_SCALE:
                continue
        else:
            node = stack[top]
            top -= 1
            if box_entry(box, node, o, inv, tmin, tmax) == INF:
                continue
        count = geo.node_link[np.uint64(node), 1]
        if count == 0 and not ordered:
            top += 1
            stack[top] = node + 1
            top += 1
            stack[top] = geo.node_link[node, 0]
            continue
        # down the nearer child directly (its box was just tested against this tmax); the
        # farther one waits on the stack with its entry distance (two entries)
        while count == 0:
            near, t_near, far, t_far = order_children(box, geo.node_link, node, o, inv, tmin,
                                                      tmax)
            if t_far != INF:
                stack[top + 1] = far
                stack[top + 2] = entry_bound(t_far)
                top += 2
            if t_near == INF:
                break
            node = near
            count = geo.node_link[np.uint64(node), 1]
        if count > 0:
            leaf = geo.node_link[np.uint64(node), 0]
            leaf_end = leaf + count
