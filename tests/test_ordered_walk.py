"""The scene BVH's closest-hit walk (kernels/traverse.py, ordered): nearer child first, the
farther one waiting with a lower bound on its entry distance, skipped once a nearer hit is
closer. It must find the hit that testing every primitive finds, at any scene scale."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from scattered import scattered_shapes
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, hit_analytic
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.shapes import INF
from whitted.kernels.traverse import ENTRY_SCALE, entry_bound


@settings(max_examples=200, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=True, width=64))
def test_entry_bound_is_a_lower_bound(t):
    q = int(entry_bound(t))
    assert -(2**31) <= q <= 2**31 - 1
    if t <= 0.0:
        assert q == -(2**31)  # before the segment: never skipped
        return
    assert q / ENTRY_SCALE <= t
    if t < 1e4:  # tight where it is not clamped: within two steps
        assert t - q / ENTRY_SCALE <= 2.0 / ENTRY_SCALE


def test_entry_bound_worked_values():
    assert int(entry_bound(1.0)) == 65535
    assert int(entry_bound(0.5 / 65536.0)) == -1
    assert int(entry_bound(0.0)) == -(2**31)
    assert int(entry_bound(-1.0)) == -(2**31)
    assert int(entry_bound(1e300)) == 2**31 - 1
    assert int(entry_bound(math.inf)) == 2**31 - 1
    assert int(entry_bound(math.nan)) == -(2**31)  # no bound: never skipped


def _scene(seed, n_spheres, n_tris, scale):
    """Spheres and triangles scattered in a cube of half-side 4·scale, clustered so boxes
    overlap and nest, and a plane (unbounded)."""
    rng = np.random.default_rng(seed)
    objects = scattered_shapes(rng, n_spheres, n_tris, half=4.0, radius_max=0.8, spread=0.7,
                               scale=scale)
    objects.append(whitted.Plane(point=(0, -5 * scale, 0), normal=(0, 1, 0)))
    return compile_scene(whitted.Scene(objects=objects)).geometry


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), scale=st.sampled_from([1e-3, 1.0, 1e5]),
       n_spheres=st.integers(0, 60), n_tris=st.integers(0, 120))
def test_closest_hit_is_the_brute_force_nearest(seed, scale, n_spheres, n_tris):
    geo = _scene(seed, n_spheres, n_tris, scale)
    stack = np.empty(BVH_STACK, np.int32)
    rng = np.random.default_rng(seed + 1)
    n_prims = geo.prim_info.shape[0]
    for _ in range(40):
        o = tuple(rng.uniform(-6, 6, 3) * scale)
        d = rng.normal(size=3)
        d = tuple(d / np.linalg.norm(d))
        tmin = float(rng.choice([0.0, rng.uniform(0, 3) * scale]))
        tmax = float(rng.choice([math.inf, rng.uniform(0.5, 12) * scale]))
        t, prim, _, _, _ = closest_hit(geo, o, d, tmin, tmax, stack)
        ts = np.array([hit_analytic(geo, i, o, d, tmin, tmax) for i in range(n_prims)])
        best = ts.min() if n_prims else INF
        if best == INF or best >= tmax:
            assert prim == -1 and t == tmax
        else:
            assert t == best
            assert ts[prim] == best
