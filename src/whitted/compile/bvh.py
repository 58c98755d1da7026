"""Bounding volume hierarchy over axis-aligned primitive bounds, built with the binned SAH.

The whole build runs in one Numba function with an explicit work stack and preallocated node
arrays (at most ``2N - 1`` nodes), so a million primitives take about a second on one core.

Layout (depth-first): node 0 is the root; the left child of interior node ``i`` is ``i + 1`` and
its right child is ``node_offset[i]``. A leaf's primitives are
``prim_order[node_offset[i] : node_offset[i] + node_count[i]]``.

Split rule at a node of ``n`` primitives: centroids are binned on the axis of largest centroid
extent only (one axis keeps the build inside its time budget; ``all_axes`` bins all three
and keeps the cheapest), and the SAH cost
``1 + (A_L * N_L + A_R * N_R) / A`` of the best bin boundary is compared with the leaf cost
``n``. The node becomes a leaf when ``n <= 1``, or when no split is cheaper than the leaf and
``n`` is at most the leaf cap (16). When every centroid coincides the index range is halved.
``traversal_cost`` (default 1, relative to one primitive test) scales the ``1``: meshes use 2,
which makes leaves of a few triangles and a third fewer nodes at the same speed.

The tree depth never exceeds :data:`MAX_DEPTH`: a node that could otherwise end up deeper
switches to exact median splits on its widest centroid axis, so a traversal stack of
``MAX_DEPTH + 1`` entries (64 is plenty) is always enough, whatever the input.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..jit import builder as _builder
from ..jit.python_twins import for_size

#: the builders here allocate nothing (build_bvh hands them every array), so they run without
#: Numba's runtime: loading them needs neither the runtime's functions nor NumPy's array code
builder = _builder(_nrt=False)
#: until the builders are compiled, trees of at most this many primitives are built by the
#: same routines run as Python (jit/python_twins.py): about 0.04 s for the default scene
PYTHON_LIMIT = 1024

LEAF_HARD_CAP = 16  # a node with more primitives than this is always split
MAX_DEPTH = 60  # root has depth 0; no leaf is deeper than this
TRAVERSAL_COST = 1.0
INTERSECTION_COST = 1.0
_BIN_SCALE_SHRINK = 1.0 - 1e-9  # keeps the largest centroid inside the last bin

# working rows: columns 0-2 lower corner, 3-5 upper corner, 6-8 centroid
_NCOL = 9


class BVH(NamedTuple):
    node_min: np.ndarray  # (M, 3) float64 box lower corner per node
    node_max: np.ndarray  # (M, 3) float64 box upper corner per node
    node_offset: np.ndarray  # (M,) int32 leaf: first entry in prim_order; interior: right child
    node_count: np.ndarray  # (M,) int32 leaf: number of primitives (>= 1); interior: 0
    node_axis: np.ndarray  # (M,) int8 interior: split axis 0/1/2; leaf: -1
    prim_order: np.ndarray  # (N,) int32 primitive indices in leaf order


@builder
def _ceil_log2(n):
    k = 0
    v = 1
    while v < n:
        v *= 2
        k += 1
    return k


@builder
def _half_area(lx, ly, lz, hx, hy, hz):
    dx = hx - lx
    dy = hy - ly
    dz = hz - lz
    return dx * dy + dy * dz + dz * dx


@builder
def _range_bounds(rows, start, end, out):
    """Box bounds (out[0:6]) and centroid bounds (out[6:12]) of rows[start:end]."""
    for k in range(3):
        out[k] = np.inf
        out[3 + k] = -np.inf
        out[6 + k] = np.inf
        out[9 + k] = -np.inf
    for j in range(start, end):
        for k in range(3):
            lo = rows[j, k]
            hi = rows[j, 3 + k]
            c = rows[j, 6 + k]
            if lo < out[k]:
                out[k] = lo
            if hi > out[3 + k]:
                out[3 + k] = hi
            if c < out[6 + k]:
                out[6 + k] = c
            if c > out[9 + k]:
                out[9 + k] = c


@builder
def _centroid(rows, j, k):
    return rows[j, 6 + k]


@builder
def _bin_of(rows, j, axis, cmin, scale, nb):
    x = (_centroid(rows, j, axis) - cmin) * scale
    if not x >= 0.0:  # NaN: an infinite spread of centroids (coordinates near 1e308)
        return 0
    return nb - 1 if x >= nb else int(x)


@builder
def _grow_centroids(f, rows, j):
    """Grow the centroid bounds f[6:12] by the centroid of row j."""
    cx = _centroid(rows, j, 0)
    cy = _centroid(rows, j, 1)
    cz = _centroid(rows, j, 2)
    f[6] = min(f[6], cx)
    f[7] = min(f[7], cy)
    f[8] = min(f[8], cz)
    f[9] = max(f[9], cx)
    f[10] = max(f[10], cy)
    f[11] = max(f[11], cz)


@builder
def _pack(bmin, bmax, rows, idx):
    """Fill the working rows (caller-allocated: NumPy's large allocations fault in faster)."""
    for i in range(bmin.shape[0]):
        idx[i] = i
        for k in range(3):
            lo = bmin[i, k]
            hi = bmax[i, k]
            rows[i, k] = lo
            rows[i, 3 + k] = hi
            # halves first, so huge finite bounds cannot overflow
            rows[i, 6 + k] = 0.5 * lo + 0.5 * hi


@builder
def _swap(rows, idx, a, b):
    for k in range(_NCOL):
        t = rows[a, k]
        rows[a, k] = rows[b, k]
        rows[b, k] = t
    t2 = idx[a]
    idx[a] = idx[b]
    idx[b] = t2


@builder
def _sort_range(rows, idx, start, end, axis, keys, order, spare, row):
    """Sort rows[start:end] (and idx) by centroid on ``axis``; stable, hence deterministic.
    A bottom-up merge sort of the positions, then the rows moved along the permutation's
    cycles: ``keys`` (float64), ``order``, ``spare`` (int64, each at least end - start long)
    and ``row`` (_NCOL + 1 float64) are the caller's scratch."""
    n = end - start
    for j in range(n):
        keys[j] = _centroid(rows, start + j, axis)
        order[j] = j
    src = order
    dst = spare
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i = lo
            j = mid
            k = lo
            while i < mid and j < hi:
                if keys[src[j]] < keys[src[i]]:  # ties keep the left run first: stable
                    dst[k] = src[j]
                    j += 1
                else:
                    dst[k] = src[i]
                    i += 1
                k += 1
            while i < mid:
                dst[k] = src[i]
                i += 1
                k += 1
            while j < hi:
                dst[k] = src[j]
                j += 1
                k += 1
        t = src
        src = dst
        dst = t
        width *= 2
    # position p takes the row at src[p]; dst marks the positions already filled
    for p in range(n):
        dst[p] = 0
    for p in range(n):
        if dst[p] != 0 or src[p] == p:
            continue
        for c in range(_NCOL):
            row[c] = rows[start + p, c]
        row[_NCOL] = idx[start + p]
        q = p
        while True:
            dst[q] = 1
            s = src[q]
            if s == p:
                for c in range(_NCOL):
                    rows[start + q, c] = row[c]
                idx[start + q] = np.int32(row[_NCOL])
                break
            for c in range(_NCOL):
                rows[start + q, c] = rows[start + s, c]
            idx[start + q] = idx[start + s]
            q = s


@builder
def _sah_axis(rows, start, end, axis, cmin, scale, nb, bin_cnt, bin_box, r_area, r_cnt):
    """Bin rows[start:end] by centroid on ``axis`` into nb bins (filling bin_cnt and bin_box)
    and score every bin boundary. Returns (s, cost, imbalance) of the cheapest boundary, where
    boundary s puts bins < s on the left and cost is A_L * N_L + A_R * N_R (unnormalised);
    s is -1 when no boundary has primitives on both sides."""
    for b in range(nb):
        bin_cnt[b] = 0
        for k in range(3):
            bin_box[b, k] = np.inf
            bin_box[b, 3 + k] = -np.inf
    for j in range(start, end):
        b = _bin_of(rows, j, axis, cmin, scale, nb)
        bin_cnt[b] += 1
        bb = bin_box[b]
        bb[0] = min(bb[0], rows[j, 0])
        bb[1] = min(bb[1], rows[j, 1])
        bb[2] = min(bb[2], rows[j, 2])
        bb[3] = max(bb[3], rows[j, 3])
        bb[4] = max(bb[4], rows[j, 4])
        bb[5] = max(bb[5], rows[j, 5])
    # sweep from the right: r_area[s], r_cnt[s] describe bins s..nb-1
    lx = np.inf
    ly = np.inf
    lz = np.inf
    hx = -np.inf
    hy = -np.inf
    hz = -np.inf
    rc = 0
    for s in range(nb - 1, 0, -1):
        lx = min(lx, bin_box[s, 0])
        ly = min(ly, bin_box[s, 1])
        lz = min(lz, bin_box[s, 2])
        hx = max(hx, bin_box[s, 3])
        hy = max(hy, bin_box[s, 4])
        hz = max(hz, bin_box[s, 5])
        rc += bin_cnt[s]
        r_cnt[s] = rc
        r_area[s] = _half_area(lx, ly, lz, hx, hy, hz) if rc > 0 else 0.0
    # sweep from the left, scoring the boundary before bin s
    lx = np.inf
    ly = np.inf
    lz = np.inf
    hx = -np.inf
    hy = -np.inf
    hz = -np.inf
    lc = 0
    count = end - start
    best_s = -1
    best_cost = np.inf
    best_imb = count + 1
    for s in range(1, nb):
        lx = min(lx, bin_box[s - 1, 0])
        ly = min(ly, bin_box[s - 1, 1])
        lz = min(lz, bin_box[s - 1, 2])
        hx = max(hx, bin_box[s - 1, 3])
        hy = max(hy, bin_box[s - 1, 4])
        hz = max(hz, bin_box[s - 1, 5])
        lc += bin_cnt[s - 1]
        rc = r_cnt[s]
        if lc == 0 or rc == 0:
            continue
        cost = (_half_area(lx, ly, lz, hx, hy, hz) * lc + r_area[s] * rc) * INTERSECTION_COST
        imb = abs(lc - rc)
        if cost < best_cost or (cost == best_cost and imb < best_imb):
            best_cost = cost
            best_s = s
            best_imb = imb
    return best_s, best_cost, best_imb


@builder
def _build(rows, idx, n_bins, leaf_cap, node_min, node_max, node_offset, node_count, node_axis,
           traversal_cost, all_axes, bin_cnt, bin_box, r_area, r_cnt, st_i, st_f, bounds,
           sort_keys, sort_order, sort_spare):
    """Build the tree in place; returns the number of nodes written. The scratch arrays
    (:func:`_scratch`) come from the caller: this builder allocates nothing."""
    n = rows.shape[0]
    if n == 0:
        return 0

    # pending right children: (start, end, parent, depth) and their box + centroid bounds.
    # Pending entries have distinct depths in 1..MAX_DEPTH, so this never overflows.
    cur = bounds[0]  # bounds of the node being processed
    left_f = bounds[1]
    right_f = bounds[2]
    row = bounds[3]  # one working row and its index, for the sort

    _range_bounds(rows, 0, n, cur)
    st_i[0, 0] = 0
    st_i[0, 1] = n
    st_i[0, 2] = -1
    st_i[0, 3] = 0
    for k in range(12):  # a loop: a slice copy compiles Numba's shape-error machinery (1.3 s)
        st_f[0, k] = cur[k]
    sp = 1
    n_nodes = 0

    while sp > 0:
        sp -= 1
        start = st_i[sp, 0]
        end = st_i[sp, 1]
        parent = st_i[sp, 2]
        depth = st_i[sp, 3]
        for k in range(12):
            cur[k] = st_f[sp, k]

        # walk down the left spine; right children go on the stack
        while True:
            node = n_nodes
            n_nodes += 1
            if parent >= 0:
                node_offset[parent] = node
            for k in range(3):
                node_min[node, k] = cur[k]
                node_max[node, k] = cur[3 + k]
            count = end - start

            make_leaf = count <= 1
            halve = False
            mid = -1
            axis = 0
            if not make_leaf:
                ex = cur[9] - cur[6]
                ey = cur[10] - cur[7]
                ez = cur[11] - cur[8]
                ext = ex
                if ey > ext:
                    axis = 1
                    ext = ey
                if ez > ext:
                    axis = 2
                    ext = ez
                nb = n_bins if count > n_bins else count
                scale = 0.0
                if ext > 0.0:
                    scale = nb * _BIN_SCALE_SHRINK / ext
                binnable = ext > 0.0 and np.isfinite(scale)
                balanced = depth + _ceil_log2(count) >= MAX_DEPTH

                if binnable and not balanced:
                    best_axis = -1
                    best_s = -1
                    best_cost = np.inf
                    best_imb = count + 1
                    for a in range(3):
                        if not all_axes and a != axis:
                            continue
                        ea = cur[9 + a] - cur[6 + a]
                        if not ea > 0.0:
                            continue
                        sc = nb * _BIN_SCALE_SHRINK / ea
                        if not np.isfinite(sc):
                            continue
                        s_a, c_a, i_a = _sah_axis(
                            rows,
                            start,
                            end,
                            a,
                            cur[6 + a],
                            sc,
                            nb,
                            bin_cnt[a],
                            bin_box[a],
                            r_area,
                            r_cnt,
                        )
                        if s_a >= 0 and (c_a < best_cost or (c_a == best_cost and i_a < best_imb)):
                            best_axis = a
                            best_s = s_a
                            best_cost = c_a
                            best_imb = i_a
                    if best_axis >= 0:
                        axis = best_axis
                    cmin = cur[6 + axis]
                    scale = nb * _BIN_SCALE_SHRINK / (cur[9 + axis] - cur[6 + axis])
                    area = _half_area(cur[0], cur[1], cur[2], cur[3], cur[4], cur[5])
                    split_cost = area * traversal_cost + best_cost
                    leaf_cost = area * INTERSECTION_COST * count
                    if split_cost >= leaf_cost and count <= leaf_cap:
                        make_leaf = True
                    elif best_s < 0:
                        halve = True  # cannot happen for exact centroid bounds; kept as a guard
                    else:
                        # child boxes from the bins
                        for k in range(3):
                            left_f[k] = np.inf
                            left_f[3 + k] = -np.inf
                            right_f[k] = np.inf
                            right_f[3 + k] = -np.inf
                            left_f[6 + k] = np.inf
                            left_f[9 + k] = -np.inf
                            right_f[6 + k] = np.inf
                            right_f[9 + k] = -np.inf
                        for b in range(nb):
                            side = left_f if b < best_s else right_f
                            for k in range(3):
                                if bin_box[axis, b, k] < side[k]:
                                    side[k] = bin_box[axis, b, k]
                                if bin_box[axis, b, 3 + k] > side[3 + k]:
                                    side[3 + k] = bin_box[axis, b, 3 + k]
                        # partition (same bin formula as above), gathering centroid bounds
                        i = start
                        jr = end - 1
                        while True:
                            while i <= jr:
                                if _bin_of(rows, i, axis, cmin, scale, nb) >= best_s:
                                    break
                                _grow_centroids(left_f, rows, i)
                                i += 1
                            while i <= jr:
                                if _bin_of(rows, jr, axis, cmin, scale, nb) < best_s:
                                    break
                                _grow_centroids(right_f, rows, jr)
                                jr -= 1
                            if i >= jr:
                                break
                            _swap(rows, idx, i, jr)
                            _grow_centroids(left_f, rows, i)
                            _grow_centroids(right_f, rows, jr)
                            i += 1
                            jr -= 1
                        mid = i
                else:
                    halve = True
                if halve:
                    # all centroids coincide (or depth guard): leaf if small enough, else halve
                    if count <= leaf_cap:
                        make_leaf = True
                    else:
                        if ext > 0.0:
                            _sort_range(rows, idx, start, end, axis, sort_keys,
                                        sort_order, sort_spare, row)
                        mid = start + count // 2
                        _range_bounds(rows, start, mid, left_f)
                        _range_bounds(rows, mid, end, right_f)

            if make_leaf:
                node_offset[node] = start
                node_count[node] = count
                node_axis[node] = -1
                break

            node_offset[node] = -1  # set when the right child is taken off the stack
            node_count[node] = 0
            node_axis[node] = axis
            st_i[sp, 0] = mid
            st_i[sp, 1] = end
            st_i[sp, 2] = node
            st_i[sp, 3] = depth + 1
            for k in range(12):
                st_f[sp, k] = right_f[k]
            sp += 1
            end = mid
            parent = -1
            depth += 1
            for k in range(12):
                cur[k] = left_f[k]

    return n_nodes


def _empty_bvh() -> BVH:
    return BVH(
        node_min=np.zeros((0, 3), np.float64),
        node_max=np.zeros((0, 3), np.float64),
        node_offset=np.zeros(0, np.int32),
        node_count=np.zeros(0, np.int32),
        node_axis=np.zeros(0, np.int8),
        prim_order=np.zeros(0, np.int32),
    )


def build_bvh(
    bounds_min: np.ndarray,
    bounds_max: np.ndarray,
    max_leaf_size: int = 4,
    n_bins: int = 16,
    traversal_cost: float = TRAVERSAL_COST,
    all_axes: bool = False,
) -> BVH:
    """BVH over N primitives with bounds ``bounds_min[i] .. bounds_max[i]`` ((N, 3) arrays).

    Bounds must be finite with ``min <= max`` (flat boxes are fine). Leaves hold at most
    ``max(max_leaf_size, 16)`` primitives; within that cap the SAH decides leaf sizes.
    ``n_bins`` (>= 2) is the number of SAH bins per node. ``all_axes`` bins all three axes
    at each node and keeps the cheapest split (three times the binning; the scene BVH of a
    big flattened scene uses it), instead of the axis of largest centroid extent only. The
    result is deterministic.
    """
    bmin = np.ascontiguousarray(bounds_min, dtype=np.float64)
    bmax = np.ascontiguousarray(bounds_max, dtype=np.float64)
    if bmin.ndim == 1 and bmin.size == 0:
        bmin = bmin.reshape(0, 3)
    if bmax.ndim == 1 and bmax.size == 0:
        bmax = bmax.reshape(0, 3)
    if bmin.ndim != 2 or bmin.shape[1] != 3 or bmin.shape != bmax.shape:
        raise ValueError(
            f"bounds must be two (N, 3) arrays of the same shape, got {bmin.shape} and {bmax.shape}"
        )
    if int(max_leaf_size) < 1:
        raise ValueError(f"max_leaf_size must be >= 1, got {max_leaf_size}")
    if int(n_bins) < 2:
        raise ValueError(f"n_bins must be >= 2, got {n_bins}")
    n = bmin.shape[0]
    if n == 0:
        return _empty_bvh()
    if n >= 2**30:
        raise ValueError(f"too many primitives for int32 node indices: {n}")
    if not (np.isfinite(bmin).all() and np.isfinite(bmax).all()):
        raise ValueError("primitive bounds must be finite (keep unbounded primitives apart)")
    if not (bmin <= bmax).all():
        raise ValueError("primitive bounds must have bounds_min <= bounds_max on every axis")

    rows = np.empty((n, _NCOL), np.float64)
    prim_order = np.empty(n, np.int32)
    _pack_ = for_size(_pack, n, PYTHON_LIMIT)
    _pack_(bmin, bmax, rows, prim_order)
    m_cap = 2 * n - 1
    node_min = np.empty((m_cap, 3), np.float64)
    node_max = np.empty((m_cap, 3), np.float64)
    node_offset = np.empty(m_cap, np.int32)
    node_count = np.empty(m_cap, np.int32)
    node_axis = np.empty(m_cap, np.int8)
    leaf_cap = max(int(max_leaf_size), LEAF_HARD_CAP)
    m = for_size(_build, n, PYTHON_LIMIT)(
        rows,
        prim_order,
        int(n_bins),
        leaf_cap,
        node_min,
        node_max,
        node_offset,
        node_count,
        node_axis,
        float(traversal_cost),
        bool(all_axes),
        *_scratch(n, int(n_bins)),
    )
    del rows
    return BVH(
        node_min=_trim(node_min, m),
        node_max=_trim(node_max, m),
        node_offset=_trim(node_offset, m),
        node_count=_trim(node_count, m),
        node_axis=_trim(node_axis, m),
        prim_order=prim_order,
    )


def _scratch(n: int, n_bins: int) -> tuple:
    """The working arrays of :func:`_build`: the SAH bins, the stack of pending right children
    (entries have distinct depths in 1..MAX_DEPTH), the node bounds and the sort's buffers
    (pages are touched only if a range is ever sorted)."""
    cap = MAX_DEPTH + 4
    return (np.zeros((3, n_bins), np.int64), np.empty((3, n_bins, 6), np.float64),
            np.empty(n_bins, np.float64), np.empty(n_bins, np.int64),
            np.empty((cap, 4), np.int64), np.empty((cap, 12), np.float64),
            np.empty((4, 12), np.float64), np.empty(n, np.float64), np.empty(n, np.int64),
            np.empty(n, np.int64))


def _trim(a: np.ndarray, m: int) -> np.ndarray:
    """The first m rows: a view when that is most of the array (no copy), else a compact copy."""
    if 4 * m >= 3 * a.shape[0]:
        return a[:m]
    return a[:m].copy()


def bvh_stats(bvh: BVH) -> dict:
    """Node count, leaf count, max depth (root = 0), mean and max leaf size, in NumPy."""
    m = int(bvh.node_count.shape[0])
    if m == 0:
        return {
            "nodes": 0,
            "leaves": 0,
            "max_depth": 0,
            "mean_leaf_size": 0.0,
            "max_leaf_size": 0,
        }
    is_leaf = bvh.node_count > 0
    leaf_sizes = bvh.node_count[is_leaf]
    # walk the tree level by level (vectorised over each level's nodes)
    max_depth = 0
    level = np.zeros(1, np.int64)
    while True:
        inner = level[~is_leaf[level]]
        if inner.size == 0:
            break
        level = np.concatenate([inner + 1, bvh.node_offset[inner].astype(np.int64)])
        max_depth += 1
    return {
        "nodes": m,
        "leaves": int(is_leaf.sum()),
        "max_depth": max_depth,
        "mean_leaf_size": float(leaf_sizes.mean()),
        "max_leaf_size": int(leaf_sizes.max()),
    }
