"""Tests of the binned-SAH BVH builder (whitted.compile.bvh)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from whitted.compile.bvh import BVH, LEAF_HARD_CAP, MAX_DEPTH, build_bvh, bvh_stats

# ---------------------------------------------------------------- helpers


def random_boxes(n, seed=0, size=0.05):
    rng = np.random.default_rng(seed)
    c = rng.random((n, 3))
    h = rng.random((n, 3)) * size
    return c - h, c + h


def walk(bvh):
    """Pre-order walk (left before right) with an explicit stack: yields (node, start, end, depth)
    where prim_order[start:end] are the primitives under the node."""
    if bvh.node_count.shape[0] == 0:
        return
    # leaf ranges are contiguous and in order, so a node covers [first leaf start, last leaf end)
    stack = [(0, 0)]
    spans = {}
    order = []
    while stack:
        node, depth = stack.pop()
        order.append((node, depth))
        if bvh.node_count[node] == 0:
            stack.append((int(bvh.node_offset[node]), depth + 1))
            stack.append((node + 1, depth + 1))
    # compute spans bottom-up (children have larger indices than their parent)
    for node, _ in reversed(order):
        if bvh.node_count[node] > 0:
            s = int(bvh.node_offset[node])
            spans[node] = (s, s + int(bvh.node_count[node]))
        else:
            left = spans[node + 1]
            right = spans[int(bvh.node_offset[node])]
            assert left[1] == right[0], "left and right subtrees must be adjacent in prim_order"
            spans[node] = (left[0], right[1])
    for node, depth in order:
        yield node, spans[node][0], spans[node][1], depth


def check_bvh(bvh, lo, hi, leaf_cap=LEAF_HARD_CAP):
    """All structural invariants; returns the list of (node, start, end, depth)."""
    lo = np.asarray(lo, np.float64).reshape(-1, 3)
    hi = np.asarray(hi, np.float64).reshape(-1, 3)
    n = lo.shape[0]
    m = bvh.node_count.shape[0]
    assert isinstance(bvh, BVH)
    assert bvh.node_min.shape == (m, 3) and bvh.node_min.dtype == np.float64
    assert bvh.node_max.shape == (m, 3) and bvh.node_max.dtype == np.float64
    assert bvh.node_offset.shape == (m,) and bvh.node_offset.dtype == np.int32
    assert bvh.node_count.shape == (m,) and bvh.node_count.dtype == np.int32
    assert bvh.node_axis.shape == (m,) and bvh.node_axis.dtype == np.int8
    assert bvh.prim_order.shape == (n,) and bvh.prim_order.dtype == np.int32
    # every primitive exactly once
    assert np.array_equal(np.sort(bvh.prim_order), np.arange(n))
    if n == 0:
        assert m == 0
        return []
    assert 1 <= m <= 2 * n - 1

    nodes = list(walk(bvh))
    # depth-first layout: the pre-order walk visits nodes 0, 1, ..., M-1 (so left child = i + 1)
    assert [v[0] for v in nodes] == list(range(m))
    leaf = bvh.node_count > 0
    assert (bvh.node_count >= 0).all()
    assert np.all(bvh.node_axis[leaf] == -1)
    assert np.all(np.isin(bvh.node_axis[~leaf], [0, 1, 2]))
    assert np.all(bvh.node_offset[~leaf] > np.flatnonzero(~leaf) + 1)  # right child after left
    assert bvh.node_count.max() <= leaf_cap
    # leaves tile prim_order in order, without gaps or overlaps
    leaf_nodes = np.flatnonzero(leaf)
    starts = bvh.node_offset[leaf_nodes]
    counts = bvh.node_count[leaf_nodes]
    assert starts[0] == 0
    assert np.array_equal(starts[1:], starts[:-1] + counts[:-1])
    assert starts[-1] + counts[-1] == n

    for node, start, end, depth in nodes:
        assert depth <= MAX_DEPTH
        prims = bvh.prim_order[start:end]
        # the node box contains (and here exactly equals) the union of its primitives' boxes
        assert np.all(bvh.node_min[node] <= lo[prims].min(axis=0))
        assert np.all(bvh.node_max[node] >= hi[prims].max(axis=0))
        assert np.array_equal(bvh.node_min[node], lo[prims].min(axis=0))
        assert np.array_equal(bvh.node_max[node], hi[prims].max(axis=0))
        if bvh.node_count[node] == 0:
            for child in (node + 1, int(bvh.node_offset[node])):
                assert np.all(bvh.node_min[node] <= bvh.node_min[child])
                assert np.all(bvh.node_max[node] >= bvh.node_max[child])
    return nodes


def slab_hits(lo, hi, o, d):
    """Boolean mask of the boxes (rows of lo/hi) that the ray o + t d, t >= 0, touches."""
    tn = np.zeros(lo.shape[0])
    tf = np.full(lo.shape[0], np.inf)
    inside = np.ones(lo.shape[0], bool)
    for k in range(3):
        if d[k] == 0.0:
            inside &= (lo[:, k] <= o[k]) & (o[k] <= hi[:, k])
            continue
        t0 = (lo[:, k] - o[k]) / d[k]
        t1 = (hi[:, k] - o[k]) / d[k]
        tn = np.maximum(tn, np.minimum(t0, t1))
        tf = np.minimum(tf, np.maximum(t0, t1))
    return inside & (tn <= tf)


def traverse(bvh, lo, hi, o, d):
    """Reference traversal: primitives whose boxes the ray touches, found through the tree."""
    found = set()
    if bvh.node_count.shape[0] == 0:
        return found
    node_hit = slab_hits(bvh.node_min, bvh.node_max, o, d)
    stack = [0]
    while stack:
        node = stack.pop()
        if not node_hit[node]:
            continue
        count = int(bvh.node_count[node])
        if count > 0:
            first = int(bvh.node_offset[node])
            prims = bvh.prim_order[first : first + count]
            mask = slab_hits(lo[prims], hi[prims], o, d)
            found.update(int(p) for p in prims[mask])
        else:
            stack.append(int(bvh.node_offset[node]))
            stack.append(node + 1)
    return found


def check_rays(bvh, lo, hi, n_rays=150, seed=1):
    rng = np.random.default_rng(seed)
    scene_lo = lo.min(axis=0)
    scene_hi = hi.max(axis=0)
    span = np.maximum(scene_hi - scene_lo, 1e-3)
    total = 0
    for r in range(n_rays):
        o = scene_lo - 0.2 * span + rng.random(3) * 1.4 * span
        if r % 3 == 0:
            # aim at a primitive so that many rays hit something
            target = rng.integers(lo.shape[0])
            d = 0.5 * (lo[target] + hi[target]) - o
        else:
            d = rng.normal(size=3)
        if r % 10 == 0:
            d[rng.integers(3)] = 0.0  # axis-parallel component
        if not np.any(d):
            d = np.array([1.0, 0.0, 0.0])
        expected = set(np.flatnonzero(slab_hits(lo, hi, o, d)).tolist())
        assert traverse(bvh, lo, hi, o, d) == expected
        total += len(expected)
    return total


# ---------------------------------------------------------------- tests


def test_empty():
    bvh = build_bvh(np.zeros((0, 3)), np.zeros((0, 3)))
    assert bvh.node_min.shape == (0, 3)
    assert bvh.node_max.shape == (0, 3)
    for a in (bvh.node_offset, bvh.node_count, bvh.node_axis, bvh.prim_order):
        assert a.shape == (0,)
    check_bvh(bvh, np.zeros((0, 3)), np.zeros((0, 3)))
    assert bvh_stats(bvh)["nodes"] == 0


def test_single():
    lo = np.array([[1.0, 2.0, 3.0]])
    hi = np.array([[2.0, 2.0, 5.0]])
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    assert bvh.node_count.tolist() == [1]
    assert bvh.node_offset.tolist() == [0]
    assert bvh.node_axis.tolist() == [-1]
    assert bvh.prim_order.tolist() == [0]
    assert np.array_equal(bvh.node_min[0], lo[0]) and np.array_equal(bvh.node_max[0], hi[0])
    stats = bvh_stats(bvh)
    assert stats == {
        "nodes": 1,
        "leaves": 1,
        "max_depth": 0,
        "mean_leaf_size": 1.0,
        "max_leaf_size": 1,
    }


def test_two_far_apart():
    lo = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    hi = lo + 0.5
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    assert bvh.node_count.tolist() == [0, 1, 1]
    assert bvh.node_axis[0] == 0
    assert bvh.node_offset[0] == 2
    check_rays(bvh, lo, hi, n_rays=40)


def test_two_overlapping():
    lo = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    hi = lo + 1.0
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    check_rays(bvh, lo, hi, n_rays=40)


def test_random_boxes_structure_and_rays():
    lo, hi = random_boxes(3000, seed=3)
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    assert check_rays(bvh, lo, hi, n_rays=200) > 0
    stats = bvh_stats(bvh)
    assert stats["nodes"] == bvh.node_count.shape[0]
    assert stats["leaves"] == int((bvh.node_count > 0).sum())
    assert stats["max_leaf_size"] <= LEAF_HARD_CAP
    assert 10 <= stats["max_depth"] <= 40
    assert stats["mean_leaf_size"] * stats["leaves"] == pytest.approx(3000)


def test_coincident_centroids():
    lo = np.tile([[1.0, 2.0, 3.0]], (1000, 1))
    hi = lo + 0.25
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    stats = bvh_stats(bvh)
    assert stats["max_leaf_size"] <= LEAF_HARD_CAP
    assert stats["max_depth"] <= 10  # halving the index range keeps it balanced
    check_rays(bvh, lo, hi, n_rays=30)


def test_coincident_points():
    # zero-size boxes at one point: no extent and no area at all
    lo = np.zeros((100, 3))
    bvh = build_bvh(lo, lo)
    check_bvh(bvh, lo, lo)
    assert bvh_stats(bvh)["max_leaf_size"] <= LEAF_HARD_CAP


def test_flat_boxes():
    # rectangles in the plane z = 0.5 (zero thickness on z)
    rng = np.random.default_rng(5)
    c = rng.random((800, 2))
    h = rng.random((800, 2)) * 0.03
    lo = np.column_stack([c - h, np.full(800, 0.5)])
    hi = np.column_stack([c + h, np.full(800, 0.5)])
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    assert np.all(bvh.node_min[:, 2] == 0.5) and np.all(bvh.node_max[:, 2] == 0.5)
    assert check_rays(bvh, lo, hi, n_rays=150) > 0


def test_points_on_a_line():
    # zero-area boxes everywhere: every SAH cost ties, the builder must still balance
    x = np.linspace(0.0, 1.0, 2000)
    lo = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    bvh = build_bvh(lo, lo)
    check_bvh(bvh, lo, lo)
    assert bvh_stats(bvh)["max_depth"] <= 20


def test_depth_guard_on_exponential_spacing():
    # centroids 1.5**k: plain binned SAH would peel a few boxes off per level (depth ~ 150)
    n = 1000
    x = 1.5 ** np.arange(n)
    lo = np.column_stack([x, np.zeros(n), np.zeros(n)])
    hi = lo + np.array([1.0, 1.0, 1.0])
    bvh = build_bvh(lo, hi)
    check_bvh(bvh, lo, hi)
    assert bvh_stats(bvh)["max_depth"] <= MAX_DEPTH
    check_rays(bvh, lo, hi, n_rays=30)


def test_two_clusters_root_split_separates_them():
    rng = np.random.default_rng(7)
    n = 10_000
    c = rng.random((n, 3))
    c[n // 2 :, 0] += 100.0  # second cluster far away on x
    h = rng.random((n, 3)) * 0.01
    perm = rng.permutation(n)  # interleave the clusters in the input
    lo, hi = (c - h)[perm], (c + h)[perm]
    in_second = (lo[:, 0] > 50.0).astype(int)
    bvh = build_bvh(lo, hi)
    assert bvh.node_count[0] == 0
    assert bvh.node_axis[0] == 0
    right = int(bvh.node_offset[0])
    # the left subtree's primitives come first in prim_order; count them via its leaves
    n_left = int(bvh.node_count[1:right].sum())
    left_side = in_second[bvh.prim_order[:n_left]]
    right_side = in_second[bvh.prim_order[n_left:]]
    assert n_left == n // 2
    assert len(set(left_side.tolist())) == 1
    assert len(set(right_side.tolist())) == 1
    assert left_side[0] != right_side[0]
    assert bvh.node_max[1, 0] < 50.0 or bvh.node_min[1, 0] > 50.0


def test_deterministic():
    lo, hi = random_boxes(5000, seed=11)
    a = build_bvh(lo, hi)
    b = build_bvh(lo.copy(), hi.copy())
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x, y)


def test_options_and_input_conversion():
    lo, hi = random_boxes(500, seed=2)
    for leaf, bins in ((1, 2), (4, 8), (32, 32)):
        bvh = build_bvh(lo, hi, max_leaf_size=leaf, n_bins=bins)
        check_bvh(bvh, lo, hi, leaf_cap=max(leaf, LEAF_HARD_CAP))
    # float32, Fortran order and nested lists are converted
    bvh = build_bvh(np.asfortranarray(lo.astype(np.float32)), hi.astype(np.float32))
    assert np.array_equal(np.sort(bvh.prim_order), np.arange(500))
    bvh = build_bvh([[0, 0, 0], [1, 1, 1]], [[1, 1, 1], [2, 2, 2]])
    assert np.array_equal(np.sort(bvh.prim_order), [0, 1])


@pytest.mark.parametrize(
    ("lo", "hi"),
    [
        (np.zeros((3, 2)), np.zeros((3, 2))),
        (np.zeros((3, 3)), np.zeros((4, 3))),
        (np.array([[0.0, 0.0, np.nan]]), np.ones((1, 3))),
        (np.zeros((1, 3)), np.array([[1.0, np.inf, 1.0]])),
        (np.ones((1, 3)), np.zeros((1, 3))),
    ],
)
def test_bad_input(lo, hi):
    with pytest.raises(ValueError):
        build_bvh(lo, hi)


def test_bad_options():
    lo, hi = random_boxes(10)
    with pytest.raises(ValueError):
        build_bvh(lo, hi, max_leaf_size=0)
    with pytest.raises(ValueError):
        build_bvh(lo, hi, n_bins=1)


def test_large_build_is_a_permutation():
    lo, hi = random_boxes(100_000, seed=4, size=0.002)
    bvh = build_bvh(lo, hi)
    assert np.array_equal(np.sort(bvh.prim_order), np.arange(100_000))
    leaf = bvh.node_count > 0
    assert int(bvh.node_count[leaf].sum()) == 100_000
    assert np.array_equal(bvh.node_min[0], lo.min(axis=0))
    assert np.array_equal(bvh.node_max[0], hi.max(axis=0))
    stats = bvh_stats(bvh)
    assert stats["max_depth"] <= 40
    assert stats["nodes"] <= 2 * 100_000 - 1


# small integer grids give many ties, coincident centroids and flat boxes
_coord = st.integers(min_value=-3, max_value=3)
_box = st.tuples(_coord, _coord, _coord, st.integers(0, 2), st.integers(0, 2), st.integers(0, 2))


@settings(max_examples=60, deadline=None)
@given(st.lists(_box, min_size=0, max_size=60), st.integers(2, 16), st.booleans())
def test_property_small_inputs(boxes, n_bins, all_axes):
    arr = np.array(boxes, dtype=np.float64).reshape(-1, 6)
    lo = arr[:, :3]
    hi = arr[:, :3] + arr[:, 3:]
    bvh = build_bvh(lo, hi, n_bins=n_bins, all_axes=all_axes)
    check_bvh(bvh, lo, hi)
    if lo.shape[0]:
        check_rays(bvh, lo, hi, n_rays=12, seed=len(boxes))


@pytest.mark.parametrize("n, start, end, axis", [(1, 0, 1, 0), (2, 0, 2, 1), (37, 5, 30, 2),
                                                 (256, 0, 256, 0), (301, 17, 300, 1)])
def test_sort_range_is_numpys_stable_sort(n, start, end, axis):
    """The depth guard's in-place sort (merge sort, rows moved along the permutation's cycles,
    every buffer the caller's) orders a range exactly as NumPy's stable argsort does: ties
    (only 7 distinct keys here) keep their order, rows outside the range are untouched."""
    from whitted.compile.bvh import _NCOL, _sort_range

    rng = np.random.default_rng(n)
    rows = rng.integers(0, 7, (n, _NCOL)).astype(np.float64) + rng.random((n, _NCOL)) * [
        1, 1, 1, 1, 1, 1, 0, 0, 0]
    idx = rng.permutation(n).astype(np.int32)
    order = np.argsort(rows[start:end, 6 + axis], kind="stable")
    want_rows = rows.copy()
    want_idx = idx.copy()
    want_rows[start:end] = rows[start:end][order]
    want_idx[start:end] = idx[start:end][order]
    _sort_range(rows, idx, start, end, axis, np.empty(n), np.empty(n, np.int64),
                np.empty(n, np.int64), np.empty(_NCOL + 1))
    np.testing.assert_array_equal(rows, want_rows)
    np.testing.assert_array_equal(idx, want_idx)


def test_all_axes_parts_two_sheets_the_longest_axis_would_mix():
    """Two flat sheets of small boxes, 12 wide in x and 10 apart in y (two nested shells'
    faces): split along x, the longest centroid axis, both halves hold both sheets; with
    ``all_axes`` the root splits along y and parts them."""
    rng = np.random.default_rng(7)
    c = np.column_stack([rng.uniform(0, 12, 400), np.repeat([0.0, 10.0], 200),
                         rng.uniform(0, 4, 400)])
    lo, hi = c - 0.02, c + 0.02
    lo[:, 1] = hi[:, 1] = c[:, 1]
    one = build_bvh(lo, hi)
    every = build_bvh(lo, hi, all_axes=True)
    check_bvh(every, lo, hi)
    check_rays(every, lo, hi, n_rays=60)
    assert one.node_axis[0] == 0 and every.node_axis[0] == 1
    left, right = 1, int(every.node_offset[0])
    assert every.node_max[left, 1] == every.node_min[left, 1]  # each child one flat sheet
    assert every.node_max[right, 1] == every.node_min[right, 1]
