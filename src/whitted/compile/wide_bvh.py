"""A binary mesh BVH collapsed into the 4-wide nodes the mesh walks read.

Each wide node stands for one interior node of the binary SAH BVH (:mod:`.bvh`) and takes as
children its grandchildren, or a child itself where that child is a leaf: two to four children,
half the depth, and one row of four boxes stored as structure of arrays, so the walk tests the
four boxes in straight-line code. The binary leaves are kept as they are (same triangles, same
order), so ``mesh_leaf_corners`` and the watertight test do not change.

The walk's stack (``accel.MESH_STACK_BASE`` up to ``tiles.BVH_STACK``: 64 entries) must hold
the children it pushes: up to three more per wide level where the binary walk pushed one per
binary level (the nearest-hit walk pushes leaf children too). :func:`collapse` checks the
deepest need and, for a pathological tree that would
need more than :data:`STACK_ROOM`, keeps two children per node (the binary tree in wide rows:
at most 61 entries, as the binary walk).
"""

from __future__ import annotations

import numpy as np

from ..kernels.layout import (
    MESH_ARITY,
    MESH_NODE_CHILD,
    MESH_NODE_COUNT,
    MESH_NODE_HI_X,
    MESH_NODE_LO_X,
    MESH_NODE_WIDTH,
)

STACK_ROOM = 60  # entries of the mesh walk's 64 a tree may need (the nearest-hit walk writes
# up to three beyond its top)


def _levels(offset: np.ndarray, count: np.ndarray, grand: bool):
    """The wide nodes level by level: a list of (binary nodes, (n, 4) child binary nodes with
    -1 for an empty slot)."""
    interior = count == 0
    if not interior[0]:  # one leaf: a root with that one child
        kids = np.full((1, MESH_ARITY), -1, np.int64)
        kids[0, 0] = 0
        return [(np.zeros(1, np.int64), kids)]
    levels = []
    frontier = np.zeros(1, np.int64)
    while len(frontier):
        kids = np.full((len(frontier), MESH_ARITY), -1, np.int64)
        for side, child in enumerate((frontier + 1, offset[frontier].astype(np.int64))):
            split = interior[child] if grand else np.zeros(len(child), bool)
            kids[:, 2 * side] = np.where(split, child + 1, child)
            kids[:, 2 * side + 1] = np.where(split, offset[child], -1)
        levels.append((frontier, kids))
        flat = kids.ravel()
        frontier = flat[(flat >= 0) & interior[np.maximum(flat, 0)]]
    return levels


def stack_need(levels, interior: np.ndarray) -> int:
    """Most stack entries the walks hold at once: at a node, the children it pushes (the
    nearest-hit walk pushes leaves too) plus those its ancestors pushed and left for later
    (all but the one descended into)."""
    held = np.zeros(len(interior), np.int64)  # entries below each wide node while it runs
    need = 0
    for nodes, kids in levels:
        inner = (kids >= 0) & interior[np.maximum(kids, 0)]
        pushes = (kids >= 0).sum(axis=1)
        here = held[nodes] + pushes
        need = max(need, int(here.max()))
        held[kids[inner]] = np.broadcast_to((here - 1)[:, None], kids.shape)[inner]
    return need


def collapse(lo: np.ndarray, hi: np.ndarray, offset: np.ndarray, count: np.ndarray):
    """Wide nodes of the binary BVH (depth-first layout: left child ``i + 1``, right child
    ``offset[i]``; ``lo``/``hi`` float32 boxes). Returns (rows (W, MESH_NODE_WIDTH) float32
    data, links (W, 4) int32, counts (W, 4) int32): row 0 is the root; links of interior
    children are local rows, of leaves the first leaf entry (local)."""
    interior = count == 0
    levels = _levels(offset, count, grand=True)
    if stack_need(levels, interior) > STACK_ROOM:
        levels = _levels(offset, count, grand=False)
    nodes = np.concatenate([n for n, _ in levels])
    kids = np.concatenate([k for _, k in levels])
    row_of = np.full(len(count), -1, np.int64)
    row_of[nodes] = np.arange(len(nodes))
    empty = kids < 0
    k = np.maximum(kids, 0)
    box_lo = np.where(empty[..., None], np.float32(np.inf), lo[k])  # (W, 4, 3)
    box_hi = np.where(empty[..., None], np.float32(np.inf), hi[k])
    leaf = ~empty & ~interior[k]
    links = np.where(leaf, offset[k], np.where(empty, 0, row_of[k])).astype(np.int32)
    counts = np.where(leaf, count[k], 0).astype(np.int32)
    data = np.empty((len(nodes), MESH_NODE_WIDTH), np.float32)
    for axis in range(3):
        data[:, MESH_NODE_LO_X + 4 * axis:MESH_NODE_LO_X + 4 * axis + 4] = box_lo[:, :, axis]
        data[:, MESH_NODE_HI_X + 4 * axis:MESH_NODE_HI_X + 4 * axis + 4] = box_hi[:, :, axis]
    assert MESH_NODE_CHILD == 24 and MESH_NODE_COUNT == 28
    return data, links, counts
