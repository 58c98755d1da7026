"""Soft shadows test each area-light sample only against the primitives listed for the
shaded point's bundle of shadow rays: the list must hold every primitive any of those rays
can hit (else a shadow would be lost), and should leave out the rest (the speed-up)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

import whitted
from meshgen import uv_sphere
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import hit_analytic
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.lighting import SHADOW_LIST_CAP, list_bundle_occluders
from whitted.kernels.shapes import INF
from whitted.kernels.traverse import cone_meets_box

EPS = 1e-6  # the shadow rays' tmin


@njit(cache=False)
def _audit_bundles(geo, mats, points, centre, u_axis, v_axis, radius, n_rays, seed):
    """For each point: the length of its list (-1: too many) and whether all it lists are
    opaque, and how many primitives one of its shadow rays to a random point of the disk hits
    (beyond EPS) without their being listed."""
    np.random.seed(seed)
    stack = np.empty(BVH_STACK, np.int32)
    listed = np.empty(SHADOW_LIST_CAP, np.int32)
    n_prims = geo.prim_info.shape[0]
    counts = np.empty(points.shape[0], np.int64)
    opaque = np.empty(points.shape[0], np.bool_)
    unlisted = 0
    for k in range(points.shape[0]):
        p = (points[k, 0], points[k, 1], points[k, 2])
        c = (centre[0], centre[1], centre[2])
        n, opaque[k] = list_bundle_occluders(geo, mats, p, c, radius, EPS, stack, listed)
        counts[k] = n
        if n < 0:
            continue
        for _ in range(n_rays):
            rr = radius * math.sqrt(np.random.random())
            phi = 2.0 * math.pi * np.random.random()
            a = rr * math.cos(phi)
            b = rr * math.sin(phi)
            d = (centre[0] + a * u_axis[0] + b * v_axis[0] - p[0],
                 centre[1] + a * u_axis[1] + b * v_axis[1] - p[1],
                 centre[2] + a * u_axis[2] + b * v_axis[2] - p[2])
            dist = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            d = (d[0] / dist, d[1] / dist, d[2] / dist)
            for i in range(n_prims):
                if hit_analytic(geo, i, p, d, EPS, dist - EPS) == INF:
                    continue
                found = False
                for j in range(n):
                    if listed[j] == i:
                        found = True
                if not found:
                    unlisted += 1
    return counts, opaque, unlisted


def _cluttered_scene():
    rng = np.random.default_rng(7)
    objects = [whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0))]
    for _ in range(14):
        c = rng.uniform((-4, 0.2, -4), (4, 3, 4))
        objects.append(whitted.Sphere(center=tuple(c), radius=float(rng.uniform(0.2, 0.7))))
    for _ in range(4):
        c = rng.uniform((-4, 0.5, -4), (4, 2, 4))
        objects.append(whitted.Box(
            min=(-0.4, -0.3, -0.5), max=(0.4, 0.3, 0.5),
            transform=whitted.Transform(rotate=tuple(rng.uniform(-60, 60, 3)),
                                        translate=tuple(c))))
    verts, faces = uv_sphere(8, 12)
    objects.append(whitted.Mesh(vertices=verts * 0.8 + (1.0, 1.2, -1.0), faces=faces))
    objects.append(whitted.Rectangle(corner=(-1, 2.5, 2), edge1=(1.5, 0, 0), edge2=(0, 0.2, 1)))
    return whitted.Scene(objects=objects, lights=[])


def test_every_primitive_a_bundle_ray_hits_is_listed():
    compiled = compile_scene(_cluttered_scene())
    rng = np.random.default_rng(3)
    # shaded points on the ground and in the air among the objects
    points = rng.uniform((-5, 0.0, -5), (5, 3.0, 5), (400, 3))
    points[:200, 1] = 0.0
    centre = np.array([-1.0, 6.0, 1.5])
    counts, _, unlisted = _audit_bundles(compiled.geometry, compiled.materials, points, centre,
                                         np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), 1.5, 64,
                                         11)
    assert unlisted == 0
    n_prims = compiled.geometry.prim_info.shape[0]
    listed = counts[counts >= 0]
    assert len(listed) > 300  # the lists rarely overflow here
    # ...and they prune: a point sees far fewer candidates than the scene has primitives
    assert n_prims > 150 and np.median(listed) < 10


def test_planes_the_light_and_the_point_are_clear_of_are_left_out():
    scene = whitted.Scene(
        objects=[whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0)),
                 whitted.Plane(point=(0, 0, -3), normal=(0, 0, 1)),  # a wall behind
                 whitted.Sphere(center=(5, 1, 0), radius=1, material="glass")],
        materials={"glass": whitted.Material(preset="glass")}, lights=[])
    compiled = compile_scene(scene)
    points = np.array([[-5.0, 0.0, 0.0],  # on the floor, nothing overhead
                       [-5.0, -1e-12, 0.0],  # a hair under it (rounding): the same
                       [5.0, 0.0, 0.0],  # under the glass sphere
                       [-5.0, 1.0, -4.0],  # behind the wall: the wall is in the way
                       [-5.0, -1.0, 0.0]])  # under the floor: the floor is in the way
    counts, opaque, unlisted = _audit_bundles(
        compiled.geometry, compiled.materials, points, np.array([-5.0, 5.0, 0.0]),
        np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), 1.0, 16, 1)
    assert counts.tolist() == [0, 0, 1, 1, 1]
    assert opaque.tolist()[2:] == [False, True, True]  # the sphere is glass
    assert unlisted == 0
    # a light straddling the wall's plane keeps the wall listed
    counts, _, unlisted = _audit_bundles(
        compiled.geometry, compiled.materials, points[:1], np.array([-5.0, 5.0, -3.0]),
        np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), 1.0, 16, 1)
    assert counts.tolist() == [1] and unlisted == 0


coords = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(p=st.tuples(coords, coords, coords), axis=st.tuples(coords, coords, coords),
       radius=st.floats(0.0, 2.0), lo=st.tuples(coords, coords, coords),
       size=st.tuples(st.floats(0, 2), st.floats(0, 2), st.floats(0, 2)),
       t=st.floats(0.0, 1.0), u=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)))
def test_cone_box_test_never_misses_a_box_the_cone_enters(p, axis, radius, lo, size, t, u):
    """A point of the cone (apex p, ball of ``radius`` around p + axis) inside the box means
    the test must say the cone meets it."""
    norm = math.sqrt(sum(c * c for c in u))
    if norm > 1.0:
        u = tuple(c / norm for c in u)
    x = tuple(p[k] + t * (axis[k] + radius * u[k]) for k in range(3))
    box = np.array([[lo, tuple(lo[k] + size[k] for k in range(3))]])
    inside = all(box[0, 0, k] <= x[k] <= box[0, 1, k] for k in range(3))
    if inside:
        assert cone_meets_box(box, 0, p, axis, radius)


def test_cone_box_test_rejects_boxes_off_the_cone():
    box = np.array([[(4.0, 8.0, -1.0), (5.0, 10.0, 1.0)]])
    # a thin cone along +y from the origin passes far from a box at x = 4..5, y = 8..10
    assert not cone_meets_box(box, 0, (0.0, 0.0, 0.0), (0.0, 10.0, 0.0), 1.0)
    # widened to radius 5 at its base (4.5 at y = 9), it reaches it
    assert cone_meets_box(box, 0, (0.0, 0.0, 0.0), (0.0, 10.0, 0.0), 5.0)
    # behind the apex there is nothing
    assert not cone_meets_box(box, 0, (6.0, 0.0, 0.0), (10.0, 0.0, 0.0), 1.0)
