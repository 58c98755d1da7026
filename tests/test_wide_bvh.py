"""The scene BVH's eight-wide nodes (compile/wide_bvh.py): collapsed from the binary BVH with
every leaf kept once, every box holding what it bounds, and the walks finding what a brute
force finds."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from whitted.compile.bvh import MAX_DEPTH, build_bvh
from whitted.compile.scene import compile_scene
from whitted.compile.wide_bvh import wide_nodes
from whitted.kernels.accel import closest_hit, hit_analytic
from whitted.kernels.layout import (
    BVH_STACK,
    MESH_STACK_BASE,
    WIDE,
    WIDE_COUNT,
    WIDE_LINK,
    WIDE_ROWS,
)
from whitted.kernels.lighting import any_occluder
from whitted.kernels.shapes import INF


def _walk(wide):
    """(leaves as (first, count), the deepest stack a walk that pushes every child needs)."""
    leaves = []
    deepest = 0
    todo = [(0, 1)]  # (wide node, stack entries in use when it is popped)
    while todo:
        w, used = todo.pop()
        children = int(np.sum(wide[w, WIDE_COUNT] >= 0))
        deepest = max(deepest, used - 1 + children)
        for c in range(WIDE):
            count = wide[w, WIDE_COUNT, c]
            if count < 0:
                continue
            assert np.all(wide[w, 0:3, c] <= wide[w, 3:6, c])
            if count == 0:
                todo.append((int(wide[w, WIDE_LINK, c]), used - 1 + children))
            else:
                leaves.append((int(wide[w, WIDE_LINK, c]), int(count)))
    return leaves, deepest


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 400), seed=st.integers(0, 2**31 - 1), flat=st.booleans())
def test_every_leaf_once_and_boxes_hold_their_primitives(n, seed, flat):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-10, 10, (n, 3))
    size = rng.uniform(0, 2, (n, 3))
    if flat:
        size[:, 1] = 0.0  # rectangles in planes: flat boxes
    hi = lo + size
    bvh = build_bvh(lo, hi)
    wide = wide_nodes(bvh)
    assert wide.dtype == np.float32 and wide.shape[1:] == (WIDE_ROWS, WIDE)
    leaves, deepest = _walk(wide)
    binary = [(int(o), int(c)) for o, c in zip(bvh.node_offset, bvh.node_count, strict=True)
              if c > 0]
    assert sorted(leaves) == sorted(binary)
    # the walks' stack stays in its part: at most (WIDE - 1) per level plus one
    assert deepest <= MESH_STACK_BASE and (WIDE - 1) * MAX_DEPTH + 1 <= MESH_STACK_BASE
    assert MESH_STACK_BASE + MAX_DEPTH + 1 <= BVH_STACK
    # a leaf's float32 box holds each of its primitives' float64 boxes
    for w in range(len(wide)):
        for c in range(WIDE):
            count = int(wide[w, WIDE_COUNT, c])
            if count <= 0:
                continue
            first = int(wide[w, WIDE_LINK, c])
            prims = bvh.prim_order[first:first + count]
            assert np.all(wide[w, 0:3, c].astype(np.float64) <= lo[prims])
            assert np.all(wide[w, 3:6, c].astype(np.float64) >= hi[prims])
    # the root's children together hold everything, and no more than float32 rounding adds
    used = wide[0][:, wide[0, WIDE_COUNT] >= 0]
    np.testing.assert_allclose(used[0:3].min(axis=1), lo.min(axis=0), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(used[3:6].max(axis=1), hi.max(axis=0), rtol=1e-6, atol=1e-6)


def test_no_primitives_no_nodes():
    wide = wide_nodes(build_bvh(np.zeros((0, 3)), np.zeros((0, 3))))
    assert wide.shape == (0, WIDE_ROWS, WIDE)


def test_a_lone_leaf_is_one_node_of_one_child():
    wide = wide_nodes(build_bvh(np.zeros((1, 3)), np.ones((1, 3))))
    assert wide.shape[0] == 1
    assert wide[0, WIDE_COUNT].tolist() == [1, -1, -1, -1, -1, -1, -1, -1]
    assert wide[0, 0:3, 0].tolist() == [0, 0, 0] and wide[0, 3:6, 0].tolist() == [1, 1, 1]


def _spheres(n, seed, kt):
    rng = np.random.default_rng(seed)
    objects = [whitted.Sphere(center=tuple(rng.uniform(-4, 4, 3)), radius=float(r),
                              material=whitted.Material(kt=kt))
               for r in rng.uniform(0.05, 0.6, n)]
    objects.append(whitted.Plane(point=(0, -5, 0), normal=(0, 1, 0)))
    return compile_scene(whitted.Scene(objects=objects))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_walks_find_what_brute_force_finds(seed):
    """any_occluder (the any-hit walk of the wide nodes) says whether anything lies on the
    segment, as testing every primitive does; closest_hit (the binary nodes) agrees."""
    compiled = _spheres(120, seed, 0.0)
    geo = compiled.geometry
    stack = np.empty(BVH_STACK, np.int32)
    rng = np.random.default_rng(seed + 1)
    n_prims = geo.prim_info.shape[0]
    for _ in range(60):
        o = tuple(rng.uniform(-6, 6, 3))
        d = rng.normal(size=3)
        d = tuple(d / np.linalg.norm(d))
        t, prim, _, _, _ = closest_hit(geo, o, d, 0.0, math.inf, stack)
        ts = [hit_analytic(geo, i, o, d, 0.0, math.inf) for i in range(n_prims)]
        best = min(ts)
        assert t == best if best < INF else prim == -1
        seg = float(rng.uniform(0.1, 8.0))
        blocked = any_occluder(geo, compiled.materials, o, d, 0.0, seg, stack)
        assert (blocked == 1) == any(x < seg for x in ts)
