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
from whitted.kernels.lighting import (
    BALL_SLACK,
    SHADOW_LIST_CAP,
    ball_meets_bundle,
    list_bundle_occluders,
)
from whitted.kernels.shapes import INF
from whitted.kernels.shapes.triangle import triangle_ball
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


# the per-primitive cut of a bundle's list (lighting.py ``ball_meets_bundle``): a sphere or
# triangle whose bounding ball misses the cone of the bundle's rays is left out of the list


def _cone(p, centre, radius):
    """The cone arguments ``ball_meets_bundle`` takes, as ``_keep_bundle_occluders`` makes
    them for a light ball of ``radius`` around ``centre`` seen from ``p``."""
    axis = tuple(centre[k] - p[k] for k in range(3))
    length = math.sqrt(sum(a * a for a in axis))
    grown = radius * (1.0 + BALL_SLACK) + 1e-12
    sin_a = grown / length
    return axis, length, sin_a, math.sqrt(1.0 - sin_a * sin_a), length + grown


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


scales = st.sampled_from([1e-3, 1.0, 1e4])


@settings(max_examples=400, deadline=None)
@given(p=st.tuples(coords, coords, coords), off=st.tuples(coords, coords, coords),
       radius=st.floats(0.01, 1.5), x=st.tuples(st.floats(-1, 1), st.floats(-1, 1),
                                                 st.floats(-1, 1)),
       t=st.floats(0.0, 1.0), side=st.tuples(coords, coords, coords),
       r=st.floats(1e-4, 2.0), shrink=st.sampled_from([1.0, 1.0 - 1e-12, 0.5]), scale=scales)
def test_a_ball_a_bundle_ray_touches_is_never_left_out(p, off, radius, x, t, side, r, shrink,
                                                       scale):
    """Build a ray of the bundle (from p to a point of the light's ball) and a ball that it
    touches (its centre r · shrink from a point of the ray, sideways): kept, at any scale."""
    p = tuple(scale * c for c in p)
    centre = tuple(p[k] + scale * (off[k] + (6.0 if k == 1 else 0.0)) for k in range(3))
    radius *= scale
    r *= scale
    norm = math.sqrt(sum(c * c for c in x))
    if norm > 1.0:
        x = tuple(c / norm for c in x)
    target = tuple(centre[k] + radius * x[k] for k in range(3))
    d = tuple(target[k] - p[k] for k in range(3))
    on_ray = tuple(p[k] + t * d[k] for k in range(3))
    # a direction across the ray
    s = tuple(side[k] - d[k] * sum(side[j] * d[j] for j in range(3)) / sum(c * c for c in d)
              for k in range(3))
    if sum(c * c for c in s) < 1e-6:
        s = _unit((d[1], -d[0], 0.0) if abs(d[2]) < abs(d[0]) + abs(d[1]) else (0.0, d[2], -d[1]))
    s = _unit(s)
    c = tuple(on_ray[k] + r * shrink * s[k] for k in range(3))
    axis, length, sin_a, cos_a, reach = _cone(p, centre, radius)
    assert ball_meets_bundle(c, r, p, axis, length, sin_a, cos_a, reach)


def test_balls_off_the_cone_are_left_out():
    p = (0.0, 0.0, 0.0)
    axis, length, sin_a, cos_a, reach = _cone(p, (0.0, 10.0, 0.0), 1.0)
    # beside the cone (its half-width at y = 5 is about 0.5)
    assert not ball_meets_bundle((2.0, 5.0, 0.0), 1.0, p, axis, length, sin_a, cos_a, reach)
    assert ball_meets_bundle((2.0, 5.0, 0.0), 1.6, p, axis, length, sin_a, cos_a, reach)
    # beyond the light, and behind the apex
    assert not ball_meets_bundle((0.0, 12.5, 0.0), 1.0, p, axis, length, sin_a, cos_a, reach)
    assert not ball_meets_bundle((0.0, -2.0, 0.0), 1.0, p, axis, length, sin_a, cos_a, reach)
    # around the apex
    assert ball_meets_bundle((0.0, -0.5, 0.0), 1.0, p, axis, length, sin_a, cos_a, reach)


@settings(max_examples=200, deadline=None)
@given(v0=st.tuples(coords, coords, coords), e1=st.tuples(coords, coords, coords),
       e2=st.tuples(coords, coords, coords), u=st.floats(-1e-9, 1 + 1e-9),
       w=st.floats(-1e-9, 1 + 1e-9), scale=scales)
def test_a_triangle_ball_holds_every_point_its_hit_test_finds(v0, e1, e2, u, w, scale):
    """Points within the hit test's edge tolerance (barycentrics down to -EDGE_TOL, sum up
    to 1 + EDGE_TOL) lie in the triangle's ball."""
    if u + w > 1 + 1e-9:
        u, w = u / (u + w) * (1 + 1e-9), w / (u + w) * (1 + 1e-9)
    P = np.zeros((1, 18))
    P[0, 0:3] = np.array(v0) * scale
    P[0, 3:6] = np.array(e1) * scale
    P[0, 6:9] = np.array(e2) * scale
    c, r = triangle_ball(P, 0)
    x = P[0, 0:3] + u * P[0, 3:6] + w * P[0, 6:9]
    assert np.linalg.norm(x - np.array(c)) <= r


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), grazing=st.floats(0.999, 1.001))
def test_spheres_grazing_the_bundle_are_listed_when_a_ray_hits_them(seed, grazing):
    """Spheres placed against the edge of a bundle's cone (at ``grazing`` times the distance
    that touches it): every one a ray of the bundle hits is listed."""
    rng = np.random.default_rng(seed)
    p = np.array([0.0, 0.0, 0.0])
    centre = np.array([-1.0, 6.0, 1.5])
    radius = 1.5
    axis = centre - p
    length = np.linalg.norm(axis)
    a_hat = axis / length
    sin_a = radius / length
    objects = [whitted.Plane(point=(0, -1, 0), normal=(0, 1, 0))]
    for _ in range(12):
        along = rng.uniform(0.5, 5.0)
        r = rng.uniform(0.05, 0.4)
        side = np.cross(a_hat, rng.normal(size=3))
        side /= np.linalg.norm(side)
        # the cone's half-width at ``along`` plus the sphere's radius, seen perpendicular
        # to the cone's side
        q = along * sin_a / math.sqrt(1 - sin_a**2) + grazing * r / math.sqrt(1 - sin_a**2)
        objects.append(whitted.Sphere(center=tuple(p + along * a_hat + q * side), radius=r))
    compiled = compile_scene(whitted.Scene(objects=objects, lights=[]))
    u_axis = np.cross(a_hat, [0.0, 0.0, 1.0])
    u_axis /= np.linalg.norm(u_axis)
    v_axis = np.cross(a_hat, u_axis)
    counts, _, unlisted = _audit_bundles(compiled.geometry, compiled.materials, p[None, :],
                                         centre, u_axis, v_axis, radius, 4000, seed % 1000)
    assert counts[0] >= 0 and unlisted == 0
