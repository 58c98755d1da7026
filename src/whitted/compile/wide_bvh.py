"""The scene BVH in eight-wide nodes, collapsed from the binary BVH the builder makes
(bvh.py): the layout of the any-hit walks (shadow rays; kernels/traverse.py).

A wide node is eight rows of ``WIDE`` float32 (layout.py): its children's boxes (``[w, 0:3,
c]`` the lower corner of child ``c``, ``[w, 3:6, c]`` the upper one, rounded outward so every
float64 box test that passes passes here too) and links (``[w, WIDE_LINK, c]``: an interior
child's wide node, or a leaf's first entry in ``node_prims``; ``[w, WIDE_COUNT, c]``: 0 for an
interior child, the leaf's primitive count, or -1 for an empty lane). The walk tests all eight
boxes of a node in one loop that the compiler turns into vector instructions, where the
binary walk tested two boxes a node and went down about three times as many nodes (the ice
benchmark's shadow rays, which gather every crossing and cannot stop early: 105 box tests in
52 binary nodes a walk, 17 wide nodes). Closest-hit walks keep the binary nodes (nearest
child first): their ordered walk through wide nodes made the analytic benchmarks 6-10 %
slower.

Collapse: a wide node starts from a binary node's two children and repeatedly opens the
interior child of largest surface area (the one a ray is likeliest to enter) until it has
eight children or only leaves. Leaves keep their primitives, so ``node_prims`` is the binary
BVH's. A wide node never lies deeper than the binary node it came from, so a walk pushes at
most ``(WIDE - 1) * MAX_DEPTH + 1`` entries (layout.MESH_STACK_BASE leaves room for that).
"""

from __future__ import annotations

import numpy as np

from ..jit import builder as _builder
from ..jit.python_twins import for_size
from ..kernels.layout import WIDE, WIDE_COUNT, WIDE_LINK, WIDE_ROWS

EXACT_FLOAT32 = 1 << 24  # whole numbers below this are exact in float32

#: the collapse allocates nothing (wide_nodes hands it every array): no Numba runtime
builder = _builder(_nrt=False)
#: binary trees of at most this many nodes are collapsed by the Python twin until the
#: builders are compiled (jit/python_twins.py)
PYTHON_LIMIT = 2048


@builder
def _half_area(lo, hi, k):
    dx = hi[k, 0] - lo[k, 0]
    dy = hi[k, 1] - lo[k, 1]
    dz = hi[k, 2] - lo[k, 2]
    return dx * dy + dy * dz + dz * dx


@builder
def _below(x):
    """The largest float32 at or below float64 ``x``."""
    y = np.float32(x)
    if np.float64(y) > x:
        y = np.nextafter(y, np.float32(-np.inf))
    return y


@builder
def _above(x):
    """The smallest float32 at or above float64 ``x``."""
    y = np.float32(x)
    if np.float64(y) < x:
        y = np.nextafter(y, np.float32(np.inf))
    return y


@builder
def _collapse(lo, hi, offset, count, box, queue, kids):
    """Fill ``box`` (room for one wide node per binary node) breadth first from
    the binary BVH (lo, hi, offset, count: left child i + 1, right child offset[i]). Returns
    the number of wide nodes. ``queue`` (one int64 per binary node: the binary node each wide
    node comes from) and ``kids`` (WIDE int64) are the caller's scratch."""
    queue[0] = 0
    made = 1
    for w in range(len(count)):
        if w == made:
            break
        b = queue[w]
        n = 1
        kids[0] = b
        if count[b] == 0:
            kids[0] = b + 1
            kids[1] = offset[b]
            n = 2
            while n < WIDE:
                best = -1
                best_area = -1.0
                for c in range(n):
                    if count[kids[c]] == 0:
                        a = _half_area(lo, hi, kids[c])
                        if a > best_area:
                            best_area = a
                            best = c
                if best < 0:
                    break
                k = kids[best]
                kids[best] = k + 1
                kids[n] = offset[k]
                n += 1
        for c in range(WIDE):
            if c >= n:
                for a in range(6):
                    box[w, a, c] = 0.0
                box[w, WIDE_LINK, c] = 0.0
                box[w, WIDE_COUNT, c] = -1.0
                continue
            k = kids[c]
            for a in range(3):
                box[w, a, c] = _below(lo[k, a])
                box[w, 3 + a, c] = _above(hi[k, a])
            if count[k] > 0:
                box[w, WIDE_LINK, c] = offset[k]
                box[w, WIDE_COUNT, c] = count[k]
            else:
                queue[made] = k
                box[w, WIDE_LINK, c] = made
                box[w, WIDE_COUNT, c] = 0.0
                made += 1
    return made


def wide_nodes(bvh) -> np.ndarray:
    """The wide nodes of binary ``bvh`` (compile/bvh.py's BVH), (W, WIDE_ROWS, WIDE) float32;
    none for an empty BVH, and none for one of EXACT_FLOAT32 primitives or more (its links
    would not be exact: its any-hit walks take the binary nodes). A lone leaf becomes a wide
    node with one child."""
    m = len(bvh.node_count)
    if m == 0 or len(bvh.prim_order) >= EXACT_FLOAT32:
        return np.zeros((0, WIDE_ROWS, WIDE), np.float32)
    box = np.empty((m, WIDE_ROWS, WIDE), np.float32)
    collapse = for_size(_collapse, m, PYTHON_LIMIT)
    made = collapse(np.ascontiguousarray(bvh.node_min, np.float64),
                     np.ascontiguousarray(bvh.node_max, np.float64),
                     np.ascontiguousarray(bvh.node_offset, np.int64),
                     np.ascontiguousarray(bvh.node_count, np.int64), box,
                     np.empty(m, np.int64), np.empty(WIDE, np.int64))
    return np.ascontiguousarray(box[:made])
