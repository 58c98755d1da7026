"""The scene BVH in the layout its walks read: eight-wide nodes, collapsed from the binary
BVH the builder makes (bvh.py).

A wide node holds up to ``WIDE`` children side by side: their boxes as six rows of eight
float32 (``box[w, 0:3, c]`` the lower corner of child ``c``, ``box[w, 3:6, c]`` the upper one,
rounded outward so every float64 box test that passes passes here too) and their links
(``link[w, 0, c]``: an interior child's wide node, or a leaf's first entry in ``node_prims``;
``link[w, 1, c]``: 0 for an interior child, the leaf's primitive count, or -1 for an empty
lane). One pass of the walk tests all eight boxes of a node in one loop that the compiler
turns into vector instructions, where the binary walk tested two boxes a node and went down
about three times as many nodes (the ice benchmark's shadow rays: 105 box tests in 52 binary
nodes a walk, 17 wide nodes).

Collapse: a wide node starts from a binary node's two children and repeatedly opens the
interior child of largest surface area (the one a ray is likeliest to enter) until it has
eight children or only leaves. Leaves keep their primitives, so ``node_prims`` is the binary
BVH's. A wide node never lies deeper than the binary node it came from, so a walk pushes at
most ``(WIDE - 1) * MAX_DEPTH + 1`` entries (kernels/tiles.py's stack holds that).
"""

from __future__ import annotations

import numpy as np

from ..jit import builder
from ..kernels.layout import WIDE


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
def _collapse(lo, hi, offset, count, box, link):
    """Fill ``box`` and ``link`` (room for one wide node per binary node) breadth first from
    the binary BVH (lo, hi, offset, count: left child i + 1, right child offset[i]). Returns
    the number of wide nodes."""
    queue = np.empty(len(count), np.int64)  # the binary node each wide node comes from
    queue[0] = 0
    made = 1
    kids = np.empty(WIDE, np.int64)
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
                link[w, 0, c] = 0
                link[w, 1, c] = -1
                continue
            k = kids[c]
            for a in range(3):
                box[w, a, c] = _below(lo[k, a])
                box[w, 3 + a, c] = _above(hi[k, a])
            if count[k] > 0:
                link[w, 0, c] = offset[k]
                link[w, 1, c] = count[k]
            else:
                queue[made] = k
                link[w, 0, c] = made
                link[w, 1, c] = 0
                made += 1
    return made


def wide_nodes(bvh) -> tuple[np.ndarray, np.ndarray]:
    """The wide nodes of binary ``bvh`` (compile/bvh.py's BVH): (box (W, 6, WIDE) float32,
    link (W, 2, WIDE) int32); no nodes for an empty BVH. A lone leaf becomes a wide node with
    one child."""
    m = len(bvh.node_count)
    box = np.empty((max(m, 1), 6, WIDE), np.float32)
    link = np.empty((max(m, 1), 2, WIDE), np.int32)
    if m == 0:
        return box[:0], link[:0]
    made = _collapse(np.ascontiguousarray(bvh.node_min, np.float64),
                     np.ascontiguousarray(bvh.node_max, np.float64),
                     np.ascontiguousarray(bvh.node_offset, np.int64),
                     np.ascontiguousarray(bvh.node_count, np.int64), box, link)
    return np.ascontiguousarray(box[:made]), np.ascontiguousarray(link[:made])


def wide_bounds(box: np.ndarray, link: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) corner of everything under wide node 0 (float64; the root's box)."""
    lanes = box[0][:, link[0, 1] >= 0]  # (6, children)
    return (lanes[0:3].min(axis=1).astype(np.float64),
            lanes[3:6].max(axis=1).astype(np.float64))
