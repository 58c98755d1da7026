"""The torus: exact crossings (worked by hand in the comments), normals, uv, transforms, and
no acne: every hit lies on the surface, even for rays that only graze it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, surface_normals
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.uv import surface_uv
from whitted.scene import Scene, Torus, Transform

REL = 1e-12


class Compiled:
    def __init__(self, *shapes):
        self.geo = compile_scene(Scene(objects=list(shapes))).geometry
        self.stack = np.empty(BVH_STACK, np.int32)

    def hit(self, o, d, tmin=0.0):
        o = tuple(map(float, o))
        d = tuple(map(float, d))
        t, prim, tri, b1, b2 = closest_hit(self.geo, o, d, float(tmin), math.inf, self.stack)
        if prim < 0:
            return None
        p = tuple(a + t * b for a, b in zip(o, d, strict=True))
        n, _ = surface_normals(self.geo, prim, tri, b1, b2, p)
        return t, np.array(p), np.array(n), (prim, tri, b1, b2)

    def all_hits(self, o, d):
        ts = []
        tmin = 0.0
        while (h := self.hit(o, d, tmin)) is not None:
            ts.append(h[0])
            tmin = h[0]
        return ts


RING = Torus(major_radius=2.0, minor_radius=0.5)


def test_crossings_along_the_equator_are_the_four_walls():
    # along the x axis from x = -10: the outer wall at x = -2.5, the inner one at -1.5, then
    # +1.5 and +2.5 -> t = 7.5, 8.5, 11.5, 12.5
    ts = Compiled(RING).all_hits((-10, 0, 0), (1, 0, 0))
    np.testing.assert_allclose(ts, [7.5, 8.5, 11.5, 12.5], rtol=REL)


def test_normals_point_out_of_the_tube():
    c = Compiled(RING)
    t, p, n, _ = c.hit((-10, 0, 0), (1, 0, 0))
    np.testing.assert_allclose(n, [-1, 0, 0], atol=1e-12)
    # straight down onto the top of the tube above x = 2: y = 0.5 -> t = 9.5, normal +y
    t, p, n, _ = c.hit((2, 10, 0), (0, -1, 0))
    assert t == pytest.approx(9.5, rel=REL)
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-12)
    # from the centre outward along z: the inner wall at z = 1.5, its normal toward the axis
    t, p, n, _ = c.hit((0, 0, 0), (0, 0, 2))
    assert t == pytest.approx(0.75, rel=REL)  # d has length 2
    np.testing.assert_allclose(n, [0, 0, -1], atol=1e-12)


def test_similarity_transform_is_baked_in():
    # rotated 90 degrees about x (axis now along z), scaled by 2 and moved to (0, 0, -3):
    # R = 4, r = 1 in the xy plane around (0, 0, -3); a ray down the z axis from z = 10 goes
    # through the hole: miss; one at x = 4 meets the tube's top at z = -3 + 1 -> t = 12
    c = Compiled(Torus(major_radius=2.0, minor_radius=0.5,
                       transform=Transform(scale=2.0, rotate=(90.0, 0.0, 0.0),
                                           translate=(0.0, 0.0, -3.0))))
    assert c.hit((0, 0, 10), (0, 0, -1)) is None
    t, p, n, _ = c.hit((4, 0, 10), (0, 0, -1))
    assert t == pytest.approx(12.0, rel=REL)
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)


def test_non_uniform_scale_keeps_a_matrix():
    # stretched by 2 along y: the tube's top above x = 2 is at y = 1 -> t = 9, normal +y;
    # on the equator the outer wall is still at x = 2.5
    c = Compiled(Torus(major_radius=2.0, minor_radius=0.5,
                       transform=Transform(scale=(1.0, 2.0, 1.0))))
    t, p, n, _ = c.hit((2, 10, 0), (0, -1, 0))
    assert t == pytest.approx(9.0, rel=REL)
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-12)
    assert c.hit((-10, 0, 0), (1, 0, 0))[0] == pytest.approx(7.5, rel=REL)


def test_a_tangent_touch_is_no_crossing():
    # the plane y = 0.5 touches the tube's top along the circle of radius 2: a ray in it
    # through the centre only touches the torus at x = -2 and x = 2
    assert Compiled(RING).hit((-10, 0.5, 0), (1, 0, 0)) is None
    # a hair lower it crosses the tube near x = -2 +- sqrt(0.25 - y^2)
    y = 0.5 - 1e-6
    t, p, n, _ = Compiled(RING).hit((-10, y, 0), (1, 0, 0))
    assert t == pytest.approx(8.0 - math.sqrt(0.25 - y * y), rel=1e-9)


def test_uv_runs_around_the_axis_and_the_tube():
    c = Compiled(RING)
    # the outer equator at +x: u = 0, v = 0; at -z (a quarter turn): u = 0.25
    _, p, _, (prim, tri, b1, b2) = c.hit((10, 0, 0), (-1, 0, 0))
    u, v = surface_uv(c.geo, prim, tri, b1, b2, tuple(p))
    assert (u, v) == pytest.approx((0.0, 0.0), abs=1e-12)
    _, p, _, (prim, tri, b1, b2) = c.hit((0, 0, -10), (0, 0, 1))
    u, v = surface_uv(c.geo, prim, tri, b1, b2, tuple(p))
    assert (u, v) == pytest.approx((0.25, 0.0), abs=1e-12)
    # the top of the tube: v = 0.25
    _, p, _, (prim, tri, b1, b2) = c.hit((2, 10, 0), (0, -1, 0))
    u, v = surface_uv(c.geo, prim, tri, b1, b2, tuple(p))
    assert (u, v) == pytest.approx((0.0, 0.25), abs=1e-12)


GRAZING = Compiled(Torus(major_radius=1.0, minor_radius=0.25))


@settings(max_examples=300, deadline=None)
@given(st.floats(0, 2 * math.pi), st.floats(-0.3, 0.3), st.floats(-1e-3, 1e-3),
       st.floats(0, 2 * math.pi))
def test_hits_lie_on_the_surface_even_at_grazing_angles(phi, height, tilt, turn):
    # rays from far away, nearly parallel to the torus's plane (tilt small), at every
    # height through the tube: wherever they hit, the point is on the surface
    o = (10 * math.cos(phi), height + 10 * tilt, 10 * math.sin(phi))
    aim = (0.9 * math.cos(turn), height, 0.9 * math.sin(turn))
    d = tuple(a - b for a, b in zip(aim, o, strict=True))
    h = GRAZING.hit(o, d)
    if h is None:
        return
    x, y, z = h[1]
    dist = math.hypot(math.hypot(x, z) - 1.0, y)
    assert abs(dist - 0.25) < 1e-12
    # and a ray leaving the surface along the normal never meets the torus right there
    p = tuple(h[1] + 1e-9 * h[2])
    again = GRAZING.hit(p, tuple(h[2]))
    assert again is None or again[0] > 1e-3


@pytest.mark.parametrize("field, value", [("major_radius", 0.0), ("minor_radius", -1.0),
                                          ("major_radius", math.nan),
                                          ("minor_radius", math.inf)])
def test_bad_radii_are_refused(field, value):
    radii = {"major_radius": 1.0, "minor_radius": 0.25, field: value}
    with pytest.raises(ValidationError):
        Torus(**radii)


def _assert_root_finders_agree(o, d, minor):
    """The two root finders of kernels/shapes/torus.py give the same roots for the ray (o, d) at a
    torus of major radius 1 (where the fast one takes the ray)."""
    from whitted.kernels.shapes.torus import _roots_by_cubic, _roots_by_curvature, torus_quartic

    near, _, _, a, b, c, e, lo, hi, q0, q1 = torus_quartic(o, d, 1.0, minor)
    if not near:
        return
    ok, *fast = _roots_by_curvature(a, b, c, e, lo, hi, q0, q1)
    general = list(_roots_by_cubic(a, b, c, e, lo, hi, q0, q1))
    if ok:
        assert fast == pytest.approx(general, rel=1e-12, abs=1e-12)


@settings(max_examples=400, deadline=None)
@given(st.floats(0, 2 * math.pi), st.floats(-0.35, 0.35), st.floats(-0.2, 0.2),
       st.floats(0, 2 * math.pi), st.floats(0.0, 1.4), st.sampled_from([0.25, 0.6, 1.3]))
def test_both_root_finders_give_the_same_crossings(phi, height, tilt, turn, reach, minor):
    """The quartic's roots found piece by piece between its inflections (the fast path) and
    with every root of its slope found first (the general path, kept for rays it leaves):
    the same roots, to the last bits, on rays from every side, grazing ones among them."""
    o = (10 * math.cos(phi), height + 10 * tilt, 10 * math.sin(phi))
    aim = (reach * math.cos(turn), height, reach * math.sin(turn))
    d = tuple(a - b for a, b in zip(aim, o, strict=True))
    _assert_root_finders_agree(o, d, minor)


@settings(max_examples=400, deadline=None)
@given(st.floats(0, 2 * math.pi), st.floats(0, 2 * math.pi), st.floats(0, math.pi),
       st.floats(-0.02, 0.02), st.sampled_from([0.25, 0.6]))
def test_both_root_finders_agree_on_rays_tangent_to_the_tube(u, v, w, gap, minor):
    """Rays along a tangent of the surface, moved off it by ``gap`` along the normal: the
    quartic dips just below zero or stays just above it, the cases the fast path settles
    from the tangents at a piece's ends."""
    ring = np.array([math.cos(u), 0.0, math.sin(u)])
    n = math.cos(v) * ring + math.sin(v) * np.array([0.0, 1.0, 0.0])
    p = ring + minor * n
    t_u = np.array([-math.sin(u), 0.0, math.cos(u)])
    t_v = np.cross(n, t_u)
    t = math.cos(w) * t_u + math.sin(w) * t_v
    o = tuple(p + gap * n - 5.0 * t)
    _assert_root_finders_agree(o, tuple(t), minor)


SPINDLE = Torus(major_radius=0.6, minor_radius=0.9)  # the tube overlaps itself: a lemon


def test_a_spindle_torus_is_met_only_on_its_outer_surface():
    # along the x axis through the centre: the outer surface at |x| = 0.6 + 0.9 = 1.5; the
    # lemon's (|x| = 0.9 - 0.6 = 0.3) lies inside the solid and bounds nothing
    np.testing.assert_allclose(Compiled(SPINDLE).all_hits((-10, 0, 0), (1, 0, 0)),
                               [8.5, 11.5], rtol=REL)
    # straight down the axis: the two cusps are points where the tube meets itself: the
    # ray enters at the top cusp (y = sqrt(0.81 - 0.36)) and leaves at the bottom one;
    # off the axis, down through the dimple above the lemon: in and out of the outer surface
    c = Compiled(SPINDLE)
    ts = c.all_hits((0.2, 10, 0), (0, -1, 0))
    # (rho - R)^2 + y^2 = r^2 at rho = 0.2: y = +-sqrt(0.81 - 0.16)
    np.testing.assert_allclose(ts, [10 - math.sqrt(0.65), 10 + math.sqrt(0.65)], rtol=1e-9)
