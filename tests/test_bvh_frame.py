"""The scene BVH built in a rotated frame (compile/bvh_frame.py): a flattened mesh turned by
its transform gets its boxes in its own orientation, and the walks turn the ray for the box
tests only. Every walk must find what testing every primitive finds, and a render must be
bit-identical to the one with the BVH in world space."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from scattered import scattered_shapes
from whitted.bench.models import rounded_box_mesh
from whitted.compile import bvh_frame
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, hit_analytic
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.lighting import any_occluder
from whitted.kernels.shapes import INF
from whitted.kernels.traverse import (
    bvh_frame_ray,
    inverse_direction,
    next_scene_candidate,
    start_scene_walk,
)
from whitted.render.api import RenderJob


def _rot_y(deg):
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def test_rotation_of_takes_the_scale_off():
    m = np.eye(4)
    m[:3, :3] = _rot_y(30.0) @ np.diag([2.0, 0.5, 3.0])
    m[:3, 3] = (1.0, 2.0, 3.0)
    assert np.allclose(bvh_frame.rotation_of(m), _rot_y(30.0), atol=1e-12)
    assert bvh_frame.rotation_of(np.diag([1.0, 1.0, -1.0])) is None  # a mirror
    assert bvh_frame.rotation_of(np.diag([1.0, 0.0, 1.0])) is None  # flat
    assert bvh_frame.axis_aligned(_rot_y(90.0))
    assert not bvh_frame.axis_aligned(_rot_y(30.0))


def _glass():
    return whitted.Material(color=(1.0, 1.0, 1.0), ka=0.0, kd=0.1, ks=0.3, kt=0.9, ior=1.3)


def _mesh(rotate, translate=(0.0, 0.0, 0.0), scale=1.0, divisions=6):
    v, f = rounded_box_mesh((1.0, 0.7, 0.8), 0.2, divisions)
    return whitted.Mesh(vertices=v * scale, faces=f, smooth=True, material=_glass(),
                        transform=whitted.Transform(rotate=rotate,
                                                    translate=tuple(x * scale
                                                                    for x in translate)))


def _flat_leaves(geo):
    lo, hi = geo.node_box[:, 0], geo.node_box[:, 1]
    leaves = geo.node_link[:, 1] > 0
    return float(np.mean(np.min(hi[leaves] - lo[leaves], axis=1) < 1e-6))


def test_a_turned_mesh_gets_its_own_frame_and_flat_boxes(monkeypatch):
    scene = whitted.Scene(objects=[_mesh((0.0, 30.0, 0.0))])
    geo = compile_scene(scene).geometry
    assert geo.bvh_frame.shape == (3, 3)
    assert np.allclose(geo.bvh_frame, _rot_y(30.0).T, atol=1e-12)
    # in that frame the box's flat faces have flat leaves again; in world space only the
    # top and bottom faces (turned about y, they stay level)
    monkeypatch.setattr(bvh_frame, "MIN_GAIN", 0.0)
    world = compile_scene(scene).geometry
    assert world.bvh_frame.shape == (0, 3)
    assert _flat_leaves(geo) > 0.4 > 0.2 > _flat_leaves(world)
    lo, hi = geo.node_box[:, 0], geo.node_box[:, 1]
    leaves = geo.node_link[:, 1] > 0
    # every triangle's corners, turned, lie in the box of the leaf that lists it
    P = geo.prim_params
    for node in np.flatnonzero(leaves):
        first, count = geo.node_link[node]
        for i in geo.node_prims[first:first + count]:
            corners = np.array([P[i, 0:3], P[i, 0:3] + P[i, 3:6], P[i, 0:3] + P[i, 6:9]])
            turned = corners @ geo.bvh_frame.T
            assert np.all(turned >= lo[node]) and np.all(turned <= hi[node])


def test_no_frame_without_a_turned_mesh():
    for rotate in [(0.0, 0.0, 0.0), (0.0, 90.0, 0.0), (180.0, 0.0, 0.0)]:
        geo = compile_scene(whitted.Scene(objects=[_mesh(rotate)])).geometry
        assert geo.bvh_frame.shape == (0, 3)
    spheres = [whitted.Sphere(center=(float(k), 0.0, 0.0), radius=0.3) for k in range(5)]
    assert compile_scene(whitted.Scene(objects=spheres)).geometry.bvh_frame.shape == (0, 3)


def _scene(seed, scale, n_spheres, n_tris, rotate):
    """A turned rounded box (a few hundred triangles), with spheres and triangles scattered
    around and through it, all clear (so walks gather every crossing), and a plane."""
    rng = np.random.default_rng(seed)
    objects = [_mesh(rotate, (0.3, -0.2, 0.1), scale)]
    objects += scattered_shapes(rng, n_spheres, n_tris, half=2.0, radius_max=0.6, spread=0.5,
                                scale=scale, material=_glass)
    objects.append(whitted.Plane(point=(0, -3 * scale, 0), normal=(0, 1, 0), material=_glass()))
    return compile_scene(whitted.Scene(objects=objects))


def _rays(rng, scale, count):
    for _ in range(count):
        if rng.random() < 0.5:  # from inside the box, as refracted and shadow rays start
            o = tuple(rng.uniform(-0.5, 0.5, 3) * scale)
        else:
            o = tuple(rng.uniform(-3, 3, 3) * scale)
        d = rng.normal(size=3)
        yield o, tuple(d / np.linalg.norm(d))


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), scale=st.sampled_from([1e-3, 1.0, 1e5]),
       n_spheres=st.integers(0, 12), n_tris=st.integers(0, 30),
       rotate=st.tuples(*[st.sampled_from([-60.0, -35.0, 25.0, 40.0, 70.0])] * 3),
       jitter=st.floats(-3.0, 3.0))
def test_walks_in_the_frame_find_what_brute_force_finds(seed, scale, n_spheres, n_tris, rotate,
                                                       jitter):
    rotate = tuple(a + jitter for a in rotate)
    with pytest.MonkeyPatch.context() as mp:  # the mesh's frame, even where it gains little
        mp.setattr(bvh_frame, "MIN_GAIN", math.inf)
        compiled = _scene(seed, scale, n_spheres, n_tris, rotate)
    geo, mats = compiled.geometry, compiled.materials
    assert geo.bvh_frame.shape == (3, 3)
    stack = np.empty(BVH_STACK, np.int32)
    n_prims = geo.prim_info.shape[0]
    rng = np.random.default_rng(seed + 1)
    for o, d in _rays(rng, scale, 30):
        tmin = float(rng.choice([0.0, 1e-9 * scale, rng.uniform(0, 1) * scale]))
        tmax = float(rng.choice([math.inf, rng.uniform(0.2, 6) * scale]))
        ts = np.array([hit_analytic(geo, i, o, d, tmin, tmax) for i in range(n_prims)])
        best = ts.min()
        t, prim, _, _, _ = closest_hit(geo, o, d, tmin, tmax, stack)
        if best == INF:
            assert prim == -1 and t == tmax
        else:
            assert t == best and ts[prim] == best
        state = any_occluder(geo, mats, o, d, tmin, tmax, stack)
        assert state == (0 if best == INF else 2)
        # the shadow rays' gathering walk (through the wide nodes) meets every primitive hit
        fo, finv = bvh_frame_ray(geo, o, d, inverse_direction(d))
        cursor = start_scene_walk(geo, stack, False)
        met = set()
        while True:
            i, *cursor = next_scene_candidate(geo, fo, finv, tmin, tmax, stack, *cursor, False)
            if i < 0:
                break
            met.add(int(i))
        assert {i for i in range(n_prims) if ts[i] < INF} <= met


@pytest.mark.parametrize("rotate", [(0.0, 30.0, 0.0), (20.0, -50.0, 35.0)])
def test_a_render_is_bit_identical_to_the_world_frame_one(rotate, monkeypatch):
    """Closest hits, shadow rays through the glass (light buffers and walks) and a soft
    light's bundles: the same float32 image whichever frame the BVH is built in."""
    objects = [_mesh(rotate, (0.0, 1.0, 0.0), divisions=5),
               _mesh((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), scale=0.4, divisions=3),
               whitted.Sphere(center=(1.6, 0.6, 0.5), radius=0.5),
               whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0))]
    lights = [whitted.PointLight(position=(-3.0, 5.0, 4.0), intensity=0.8),
              whitted.DiskLight(center=(3.0, 4.0, 2.0), radius=0.6, intensity=0.5,
                                samples=4)]
    scene = whitted.Scene(objects=objects, lights=lights,
                          camera=whitted.Camera(position=(0.0, 2.5, 6.0),
                                                look_at=(0.0, 0.9, 0.0)),
                          render=whitted.RenderSettings(width=40, height=32, max_depth=6))
    turned = compile_scene(scene)
    assert turned.geometry.bvh_frame.shape == (3, 3)
    monkeypatch.setattr(bvh_frame, "MIN_GAIN", 0.0)  # no frame can win: world space
    world = compile_scene(scene)
    assert world.geometry.bvh_frame.shape == (0, 3)
    images = []
    for compiled in (turned, world):
        job = RenderJob(scene, compiled=compiled, threads=1)
        job.run()
        images.append(job.framebuffer.copy())
    assert np.array_equal(images[0], images[1])
    assert images[0].max() > 0.05  # something was lit
