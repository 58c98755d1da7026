"""Exact ray/shape intersection for every shape, through the real compiled scene (compile_scene ->
BVH -> ``closest_hit`` -> ``world_normal``), checked against hand-computed values.

Every hand-computed expected value is worked out in the comment next to it. ``t`` is the ray
parameter: the hit point is ``origin + t * direction`` and the direction need not be unit length.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, surface_normals
from whitted.kernels.layout import PRIM_OBJECT
from whitted.scene import (
    AxisAngle,
    Box,
    Cone,
    Cylinder,
    Disk,
    Plane,
    Rectangle,
    Scene,
    Sphere,
    Transform,
    Triangle,
)

REL = 1e-9  # relative tolerance of every hand-computed value
ABS = 1e-12  # absolute floor, for components that should be exactly zero
S2 = math.sqrt(2.0)
S3 = math.sqrt(3.0)
S5 = math.sqrt(5.0)


# ---------------------------------------------------------------- helpers


class Hit(NamedTuple):
    t: float
    p: np.ndarray
    n: np.ndarray
    obj: int  # index of the scene object that was hit


class Compiled:
    """A scene compiled once and queried with many rays."""

    def __init__(self, shapes):
        self.compiled = compile_scene(Scene(objects=list(shapes)))
        self.stack = np.empty(128, np.int32)

    def hit(self, origin, direction, tmin=0.0, tmax=math.inf) -> Hit | None:
        geo = self.compiled.geometry
        o = tuple(float(x) for x in origin)
        d = tuple(float(x) for x in direction)
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, float(tmin), float(tmax), self.stack)
        if prim < 0:
            return None
        p = tuple(oi + t * di for oi, di in zip(o, d, strict=True))
        n, _ = surface_normals(geo, prim, tri, b1, b2, p)
        return Hit(float(t), np.array(p), np.array(n), int(geo.prim_info[prim, PRIM_OBJECT]))


def first_hit(shapes, origin, direction, tmin=0.0, tmax=math.inf) -> Hit | None:
    return Compiled(shapes).hit(origin, direction, tmin, tmax)


def close(actual, expected):
    np.testing.assert_allclose(actual, expected, rtol=REL, atol=ABS)


def assert_hit(hit, t, p, n):
    assert hit is not None, "expected a hit, got a miss"
    assert hit.t == pytest.approx(t, rel=REL, abs=ABS)
    close(hit.p, p)
    close(hit.n, n)
    assert np.linalg.norm(hit.n) == pytest.approx(1.0, abs=1e-12)


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def rodrigues(v, axis, degrees):
    """v rotated right-handedly about ``axis``: v cos + (k x v) sin + k (k.v)(1 - cos)."""
    k = unit(axis)
    a = math.radians(degrees)
    v = np.asarray(v, dtype=np.float64)
    return v * math.cos(a) + np.cross(k, v) * math.sin(a) + k * np.dot(k, v) * (1 - math.cos(a))


def random_rays_into(rng, n, inside_point, far=20.0):
    """``n`` rays from random points on a sphere of radius ``far`` towards points inside a solid
    (``inside_point(rng)``); yields (origin, direction) pairs with non-unit directions."""
    for _ in range(n):
        o = unit(rng.normal(size=3)) * far
        target = inside_point(rng)
        d = (target - o) * rng.uniform(0.2, 3.0)
        yield o, d


UNIT_SPHERE = Sphere(center=(0, 0, 0), radius=1)


# ---------------------------------------------------------------- sphere


def test_sphere_head_on():
    # |(0,0,5-t)| = 1 -> t = 4, p = (0,0,1), n = p
    assert_hit(first_hit([UNIT_SPHERE], (0, 0, 5), (0, 0, -1)), 4.0, (0, 0, 1), (0, 0, 1))


def test_sphere_non_unit_direction_scales_t():
    # direction (0,0,-2): the same point (0,0,1) at t = 4 / 2 = 2
    assert_hit(first_hit([UNIT_SPHERE], (0, 0, 5), (0, 0, -2)), 2.0, (0, 0, 1), (0, 0, 1))


def test_sphere_off_axis():
    # x = 0.6: z = sqrt(1 - 0.36) = 0.8, t = 5 - 0.8 = 4.2, n = (0.6, 0, 0.8)
    hit = first_hit([UNIT_SPHERE], (0.6, 0, 5), (0, 0, -1))
    assert_hit(hit, 4.2, (0.6, 0, 0.8), (0.6, 0, 0.8))


def test_sphere_off_centre_oblique():
    # sphere c = (1,2,3), r = 2; o = c + (6,0,8) = (7,2,11), d = (-3,0,-4):
    # |o + t d - c| = |(2-t)(3,0,4)| = 5|2-t| = 2 -> t = 1.6, p = c + 0.4 (3,0,4), n = (.6,0,.8)
    hit = first_hit([Sphere(center=(1, 2, 3), radius=2)], (7, 2, 11), (-3, 0, -4))
    assert_hit(hit, 1.6, (2.2, 2, 4.6), (0.6, 0, 0.8))


@pytest.mark.parametrize(
    "origin, direction",
    [
        ((1.5, 0, 5), (0, 0, -1)),  # passes beside (distance 1.5 from the centre)
        ((0, 0, 5), (0, 0, 1)),  # points away
        ((0, 3, 0), (1, 0, 0)),  # passes above
    ],
)
def test_sphere_misses(origin, direction):
    assert first_hit([UNIT_SPHERE], origin, direction) is None


# the silhouette is probed where it touches the BVH box (side x = 1) and on the diagonal,
# well inside the box, where only the quadric decides
SILHOUETTE_DIRS = [(1.0, 0.0), (1 / S2, 1 / S2)]


@pytest.mark.parametrize("ux, uy", SILHOUETTE_DIRS)
def test_sphere_exact_tangent_is_finite_or_miss(ux, uy):
    # (ux, uy, 5) down -z touches the unit sphere at (ux, uy, 0), t = 5: hit or miss, no NaN
    hit = first_hit([UNIT_SPHERE], (ux, uy, 5), (0, 0, -1))
    if hit is not None:
        assert math.isfinite(hit.t) and np.all(np.isfinite(hit.n))
        assert np.linalg.norm(hit.p) == pytest.approx(1.0, abs=1e-6)
        assert hit.t == pytest.approx(5.0, abs=1e-3)


@pytest.mark.parametrize("ux, uy", SILHOUETTE_DIRS)
def test_sphere_grazing_just_outside_misses(ux, uy):
    # distance 1 + 1e-9 from the axis: b^2 - ac = -(2e-9 + 1e-18) < 0
    rho = 1 + 1e-9
    assert first_hit([UNIT_SPHERE], (rho * ux, rho * uy, 5), (0, 0, -1)) is None


@pytest.mark.parametrize("ux, uy", SILHOUETTE_DIRS)
def test_sphere_grazing_just_inside_hits(ux, uy):
    # distance rho = 1 - 1e-6: z = sqrt(1 - rho^2) = sqrt(2e-6 - 1e-12), t = 5 - z, n = p
    rho = 1 - 1e-6
    z = math.sqrt(1 - rho * rho)
    hit = first_hit([UNIT_SPHERE], (rho * ux, rho * uy, 5), (0, 0, -1))
    assert hit is not None
    assert hit.t == pytest.approx(5 - z, rel=REL)
    assert np.linalg.norm(hit.p) == pytest.approx(1.0, abs=1e-9)
    close(hit.n, (rho * ux, rho * uy, z))


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        ((0, 0, 0), (1, 0, 0), 1.0, (1, 0, 0)),
        ((0, 0, 0), (0, 0, -3), 1 / 3, (0, 0, -1)),
        # from (0.5,0,0) along +y: 0.25 + t^2 = 1 -> t = sqrt(0.75)
        ((0.5, 0, 0), (0, 1, 0), math.sqrt(0.75), (0.5, math.sqrt(0.75), 0)),
    ],
)
def test_sphere_origin_inside_hits_exit_with_outward_normal(origin, direction, t, p):
    hit = first_hit([UNIT_SPHERE], origin, direction)
    assert_hit(hit, t, p, p)  # unit sphere: n = p
    assert np.dot(hit.n, direction) > 0


def test_sphere_tmin_between_roots_returns_second_root():
    # roots at t = 4 (z = 1) and t = 6 (z = -1); tmin = 5 skips the first
    hit = first_hit([UNIT_SPHERE], (0, 0, 5), (0, 0, -1), tmin=5.0)
    assert_hit(hit, 6.0, (0, 0, -1), (0, 0, -1))


@pytest.mark.parametrize(
    "tmin, tmax, expected",
    [
        (0.0, 3.9, None),  # both roots beyond tmax
        (0.0, 4.000001, 4.0),  # first root just inside
        (0.0, 5.9, 4.0),
        (4.000001, 5.9, None),  # between the roots, both excluded
        (6.000001, math.inf, None),  # both roots behind tmin
        (-10.0, math.inf, 4.0),  # ray origin outside: negative tmin changes nothing
    ],
)
def test_sphere_tmin_tmax_window(tmin, tmax, expected):
    hit = first_hit([UNIT_SPHERE], (0, 0, 5), (0, 0, -1), tmin=tmin, tmax=tmax)
    if expected is None:
        assert hit is None
    else:
        assert hit is not None and hit.t == pytest.approx(expected, rel=REL)


def test_sphere_translated():
    # centre (2,3,-1): ray from (2,3,5) down -z meets z = 0 at t = 5, n = +z
    s = Sphere(radius=1, transform=Transform(translate=(2, 3, -1)))
    assert_hit(first_hit([s], (2, 3, 5), (0, 0, -1)), 5.0, (2, 3, 0), (0, 0, 1))


@pytest.mark.parametrize(
    "rotate, centre",
    [
        ((90, 0, 0), (0, 0, 1)),  # Rx(90): y -> z
        ((0, 90, 0), (0, 0, -1)),  # Ry(90): x -> -z (local centre (1,0,0), see below)
        ((0, 0, 90), (-1, 0, 0)),  # Rz(90): y -> -x
    ],
)
def test_sphere_off_centre_rotated(rotate, centre):
    # local centre (0,1,0); Ry leaves that fixed, so it gets (1,0,0) instead
    local = (1, 0, 0) if rotate[1] else (0, 1, 0)
    s = Sphere(center=local, radius=0.5, transform=Transform(rotate=rotate))
    c = np.array(centre, dtype=float)
    # ray from c + (0,10,0) down -y: hits the top at c + (0,0.5,0), t = 9.5
    assert_hit(first_hit([s], c + (0, 10, 0), (0, -1, 0)), 9.5, c + (0, 0.5, 0), (0, 1, 0))


def test_sphere_arbitrary_axis_angle():
    # centre (1,0,0) rotated 50 deg about (1,2,3), then translated by (0,0,1)
    c = rodrigues((1, 0, 0), (1, 2, 3), 50) + (0, 0, 1)
    s = Sphere(
        center=(1, 0, 0),
        radius=0.5,
        transform=Transform(axis_angle=AxisAngle(axis=(1, 2, 3), angle=50), translate=(0, 0, 1)),
    )
    # ray from c + (4,0,0) along -x: hits c + (0.5,0,0) at t = 3.5
    assert_hit(first_hit([s], c + (4, 0, 0), (-1, 0, 0)), 3.5, c + (0.5, 0, 0), (1, 0, 0))


def test_sphere_uniform_scale():
    # centre (1,0,0) r 1, scale 2, translate (0,1,0) -> centre (2,1,0), r 2
    s = Sphere(center=(1, 0, 0), radius=1, transform=Transform(scale=2, translate=(0, 1, 0)))
    assert_hit(first_hit([s], (2, 1, 10), (0, 0, -1)), 8.0, (2, 1, 2), (0, 0, 1))
    # from (6,1,0) along -x: hits x = 4 at t = 2
    assert_hit(first_hit([s], (6, 1, 0), (-1, 0, 0)), 2.0, (4, 1, 0), (1, 0, 0))


ELLIPSOID = Sphere(radius=1, transform=Transform(scale=(2, 1, 1)))  # x^2/4 + y^2 + z^2 = 1


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        # along -x: (10-t)^2/4 = 1 -> t = 8, p = (2,0,0)
        ((10, 0, 0), (-1, 0, 0), 8.0, (2, 0, 0)),
        # along -y: t = 9, p = (0,1,0)
        ((0, 10, 0), (0, -1, 0), 9.0, (0, 1, 0)),
        # x = 1 along -z: z^2 = 1 - 1/4 -> z = sqrt(3)/2, t = 10 - sqrt(3)/2
        ((1, 0, 10), (0, 0, -1), 10 - S3 / 2, (1, 0, S3 / 2)),
        # diagonal: p = (s,s,0), s^2/4 + s^2 = 1 -> s = 2/sqrt(5), t = 5 - s
        ((5, 5, 0), (-1, -1, 0), 5 - 2 / S5, (2 / S5, 2 / S5, 0)),
        # from inside along +x (exit point, outward normal +x)
        ((0, 0, 0), (1, 0, 0), 2.0, (2, 0, 0)),
    ],
)
def test_ellipsoid_hits_and_gradient_normal(origin, direction, t, p):
    # outward normal = normalised gradient of x^2/4 + y^2 + z^2: (x/4, y, z)
    x, y, z = p
    assert_hit(first_hit([ELLIPSOID], origin, direction), t, p, unit((x / 4, y, z)))


def test_ellipsoid_misses_where_the_unit_sphere_would_hit_and_vice_versa():
    # y = 0.9 along -x meets the ellipsoid at x = 2 sqrt(1 - 0.81) (hit), y = 1.1 misses
    assert first_hit([ELLIPSOID], (10, 0.9, 0), (-1, 0, 0)) is not None
    assert first_hit([ELLIPSOID], (10, 1.1, 0), (-1, 0, 0)) is None
    # x = 1.5 along -z: beyond the unit sphere but inside the ellipsoid (1.5^2/4 = 0.5625)
    hit = first_hit([ELLIPSOID], (1.5, 0, 10), (0, 0, -1))
    assert_hit(hit, 10 - math.sqrt(0.4375), (1.5, 0, math.sqrt(0.4375)),
               unit((1.5 / 4, 0, math.sqrt(0.4375))))


def test_ellipsoid_rotated_and_translated():
    # scale (2,1,1), Rz(90) (x -> y), translate (1,0,0): (x-1)^2 + y^2/4 + z^2 = 1
    e = Sphere(radius=1, transform=Transform(scale=(2, 1, 1), rotate=(0, 0, 90),
                                             translate=(1, 0, 0)))
    assert_hit(first_hit([e], (1, 10, 0), (0, -1, 0)), 8.0, (1, 2, 0), (0, 1, 0))
    # y = 1 along -x: (x-1)^2 = 3/4 -> x = 1 + sqrt(3)/2, gradient ((x-1), y/4, z)
    hit = first_hit([e], (10, 1, 0), (-1, 0, 0))
    assert_hit(hit, 9 - S3 / 2, (1 + S3 / 2, 1, 0), unit((S3 / 2, 1 / 4, 0)))


@settings(max_examples=50, deadline=None)
@given(
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3),
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
)
def test_ellipsoid_random_rays_hit_surface_with_gradient_normal(target, far_dir):
    # ellipsoid (x-1)^2/4 + (y+2)^2/9 + z^2 = 1 (scale (2,3,1), translate (1,-2,0));
    # rays from 30 units away towards a point strictly inside it
    e = Sphere(radius=1, transform=Transform(scale=(2, 3, 1), translate=(1, -2, 0)))
    axes = np.array([2.0, 3.0, 1.0])
    centre = np.array([1.0, -2.0, 0.0])
    inside = centre + 0.9 * axes * np.array(target) / max(1.0, np.linalg.norm(target))
    origin = centre + 30 * unit(far_dir)
    d = inside - origin
    hit = first_hit([e], origin, d)
    assert hit is not None
    q = (hit.p - centre) / axes
    assert np.dot(q, q) == pytest.approx(1.0, abs=1e-9)
    close(hit.n, unit((hit.p - centre) / axes**2))
    assert np.dot(hit.n, d) < 0


@settings(max_examples=50, deadline=None)
@given(
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
    st.tuples(*[st.floats(-0.99, 0.99, allow_nan=False)] * 2),
    st.floats(0.1, 10, allow_nan=False),
)
def test_sphere_random_rays_unit_outward_normal_on_surface(far_dir, offset, length):
    # sphere c = (0.5,-1,2), r = 1.5; rays from 10 units away towards c + an offset in the
    # plane perpendicular to the ray, so the ray passes within 0.99*r*sqrt(2) of the centre
    c = np.array([0.5, -1.0, 2.0])
    r = 1.5
    w = unit(far_dir)
    a = unit(np.cross(w, (1, 0, 0) if abs(w[0]) < 0.9 else (0, 1, 0)))
    b = np.cross(w, a)
    target = c + r * (offset[0] * a + offset[1] * b) / S2
    origin = c + 10 * w
    d = (target - origin) * length
    hit = first_hit([Sphere(center=tuple(c), radius=r)], origin, d)
    assert hit is not None
    assert np.linalg.norm(hit.p - c) == pytest.approx(r, rel=1e-9)
    assert np.linalg.norm(hit.n) == pytest.approx(1.0, abs=1e-12)
    close(hit.n, (hit.p - c) / r)
    assert np.dot(hit.n, d) < 0


# ---------------------------------------------------------------- plane


FLOOR = Plane(point=(0, -1, 0), normal=(0, 1, 0))


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        ((0, 1, 0), (0, -1, 0), 2.0, (0, -1, 0)),  # from above
        ((0, -3, 0), (0, 1, 0), 2.0, (0, -1, 0)),  # from below: the given normal either way
        ((0, 1, 0), (1, -1, 0), 2.0, (2, -1, 0)),  # oblique: y = 1 - t = -1
        ((3, 5, -2), (0, -0.5, 0), 12.0, (3, -1, -2)),  # non-unit direction: 6 / 0.5
    ],
)
def test_plane_hits(origin, direction, t, p):
    assert_hit(first_hit([FLOOR], origin, direction), t, p, (0, 1, 0))


@pytest.mark.parametrize(
    "origin, direction", [((0, 1, 0), (1, 0, 0)), ((0, 1, 0), (0, 1, 0)), ((0, -3, 0), (0, -1, 0))]
)
def test_plane_misses_parallel_and_away(origin, direction):
    assert first_hit([FLOOR], origin, direction) is None


def test_plane_tmax():
    # the plane is at t = 2
    assert first_hit([FLOOR], (0, 1, 0), (0, -1, 0), tmax=1.999) is None
    assert first_hit([FLOOR], (0, 1, 0), (0, -1, 0), tmin=2.001) is None


def test_plane_rotated_and_translated():
    # y-up plane, Rx(90) (normal -> +z), translate (0,0,-2): the plane z = -2
    pl = Plane(transform=Transform(rotate=(90, 0, 0), translate=(0, 0, -2)))
    assert_hit(first_hit([pl], (1, 1, 3), (0, 0, -1)), 5.0, (1, 1, -2), (0, 0, 1))


def test_plane_non_uniform_scale_normal():
    # plane x + y = 0 scaled by (2,1,1): points (x, y) -> (2x, y), so it becomes X/2 + Y = 0
    # with normal (1/2, 1, 0) -> (1, 2, 0)/sqrt(5); ray down -y from (0,5,0) hits the origin
    pl = Plane(normal=(1, 1, 0), transform=Transform(scale=(2, 1, 1)))
    assert_hit(first_hit([pl], (0, 5, 0), (0, -1, 0)), 5.0, (0, 0, 0), (1 / S5, 2 / S5, 0))
    # and along -x from (4, 1, 0): X = -2 -> t = 6
    assert_hit(first_hit([pl], (4, 1, 0), (-1, 0, 0)), 6.0, (-2, 1, 0), (1 / S5, 2 / S5, 0))


# ---------------------------------------------------------------- rectangle


RECT = Rectangle(corner=(0, 0, 0), edge1=(2, 0, 0), edge2=(0, 1, 0))  # normal e1 x e2 = +z


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        ((1, 0.5, 5), (0, 0, -1), 5.0, (1, 0.5, 0)),
        ((1, 0.5, -5), (0, 0, 1), 5.0, (1, 0.5, 0)),  # from behind: still e1 x e2
        ((0, 0, 4), (0.5, 0.25, -2), 2.0, (1, 0.5, 0)),  # oblique, non-unit
        ((1.99, 0.99, 1), (0, 0, -1), 1.0, (1.99, 0.99, 0)),  # u, v just under 1
        ((0.01, 0.01, 1), (0, 0, -1), 1.0, (0.01, 0.01, 0)),  # u, v just over 0
    ],
)
def test_rectangle_hits(origin, direction, t, p):
    assert_hit(first_hit([RECT], origin, direction), t, p, (0, 0, 1))


@pytest.mark.parametrize(
    "xy",
    [(2.01, 0.5), (-0.01, 0.5), (1, 1.01), (1, -0.01), (2.5, 1.5), (-1, -1)],
)
def test_rectangle_misses_outside_uv(xy):
    assert first_hit([RECT], (*xy, 5), (0, 0, -1)) is None


def test_rectangle_parallel_ray_and_pointing_away_miss():
    assert first_hit([RECT], (-1, 0.5, 0), (1, 0, 0)) is None  # in its plane
    assert first_hit([RECT], (1, 0.5, 5), (0, 0, 1)) is None


def test_parallelogram_uv_bounds():
    # corner 0, e1 = (2,0,0), e2 = (1,1,0): a point (x,y,0) has v = y, u = (x - y)/2
    pg = [Rectangle(corner=(0, 0, 0), edge1=(2, 0, 0), edge2=(1, 1, 0))]
    assert_hit(first_hit(pg, (2.4, 0.5, 3), (0, 0, -1)), 3.0, (2.4, 0.5, 0), (0, 0, 1))  # u .95
    assert first_hit(pg, (0.2, 0.5, 3), (0, 0, -1)) is None  # u = -0.15 (inside the AABB)
    assert first_hit(pg, (2.8, 0.5, 3), (0, 0, -1)) is None  # u = 1.15


@pytest.mark.parametrize("edge", [1.0, 0.3, 1 / 3])
def test_rectangles_sharing_an_edge_leave_no_crack(edge):
    # A = [0.1, edge] x [0,1], B = [edge, 1.7] x [0,1], both in z = 0. Rays through x = edge,
    # and through the few floats either side of it, always hit one of them at t = 1.
    a = Rectangle(corner=(0.1, 0, 0), edge1=(edge - 0.1, 0, 0), edge2=(0, 1, 0))
    b = Rectangle(corner=(edge, 0, 0), edge1=(1.7 - edge, 0, 0), edge2=(0, 1, 0))
    scene = Compiled([a, b])
    xs = [edge]
    for _ in range(4):
        xs = [np.nextafter(xs[0], -1), *xs, np.nextafter(xs[-1], 2)]
    for x in xs:
        for y in (0.25, 0.5, 0.7):
            hit = scene.hit((x, y, 1), (0, 0, -1))
            assert hit is not None, f"crack at x={x!r}, y={y}"
            assert hit.t == pytest.approx(1.0, rel=REL)
        # and obliquely, through the same edge point
        hit = scene.hit((x - 0.3, 0.1, 1), (0.3, 0.4, -1))
        assert hit is not None, f"crack at x={x!r} (oblique)"


def test_rectangle_non_uniform_scale_and_rotation():
    # unit square scaled (2,3,1) -> [0,2] x [0,3]; then Rx(90): (x,y,0) -> (x,0,y), normal
    # (0,0,1) -> (0,-1,0); translate (0,1,0): the rectangle [0,2] x {1} x [0,3]
    r = Rectangle(corner=(0, 0, 0), edge1=(1, 0, 0), edge2=(0, 1, 0),
                  transform=Transform(scale=(2, 3, 1), rotate=(90, 0, 0), translate=(0, 1, 0)))
    assert_hit(first_hit([r], (1.9, 5, 2.9), (0, -1, 0)), 4.0, (1.9, 1, 2.9), (0, -1, 0))
    assert first_hit([r], (2.1, 5, 1), (0, -1, 0)) is None
    assert first_hit([r], (1, 5, 3.1), (0, -1, 0)) is None


# ---------------------------------------------------------------- disk


DISK = Disk(center=(0, 0, 0), normal=(0, 1, 0), radius=1)


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        ((0.5, 2, 0), (0, -1, 0), 2.0, (0.5, 0, 0)),
        ((0.5, -2, 0), (0, 1, 0), 2.0, (0.5, 0, 0)),  # from below: the given normal
        ((0.6, 2, 0.79), (0, -1, 0), 2.0, (0.6, 0, 0.79)),  # r^2 = 0.9841
        ((0, 1, 0), (0.25, -0.5, 0.2), 2.0, (0.5, 0, 0.4)),  # oblique, non-unit, r^2 = 0.41
    ],
)
def test_disk_hits(origin, direction, t, p):
    assert_hit(first_hit([DISK], origin, direction), t, p, (0, 1, 0))


@pytest.mark.parametrize(
    "xz",
    [
        (0.8, 0.7),  # r^2 = 1.13
        (0.7072, 0.7072),  # r^2 = 1.00028 (inside the BVH box: only the disk test decides)
        (-0.6, 0.8 + 1e-6),  # r^2 = 1 + 1.6e-6
        (1.01, 0),
        (0, -1.01),
        (5, 5),
    ],
)
def test_disk_misses_outside_radius(xz):
    assert first_hit([DISK], (xz[0], 2, xz[1]), (0, -1, 0)) is None


def test_disk_hits_just_inside_rim():
    # r^2 = 0.99998 and r^2 = 1 - 1.6e-6
    for x, z in [(0.7071, 0.7071), (-0.6, 0.8 - 1e-6)]:
        assert_hit(first_hit([DISK], (x, 2, z), (0, -1, 0)), 2.0, (x, 0, z), (0, 1, 0))


def test_disk_parallel_and_away_miss():
    assert first_hit([DISK], (-5, 0, 0), (1, 0, 0)) is None
    assert first_hit([DISK], (0, 2, 0), (0, 1, 0)) is None


def test_disk_tilted_unnormalised_normal():
    # centre (0,0,-3), normal (0,0,5) (not unit), r 2; ray from origin along (1,0,-2) meets
    # z = -3 at t = 1.5, p = (1.5, 0, -3) (radial 1.5 < 2)
    dk = Disk(center=(0, 0, -3), normal=(0, 0, 5), radius=2)
    assert_hit(first_hit([dk], (0, 0, 0), (1, 0, -2)), 1.5, (1.5, 0, -3), (0, 0, 1))
    assert first_hit([dk], (0, 0, 0), (1.5, 0, -2)) is None  # radial 2.25


def test_disk_rotated_and_uniformly_scaled():
    # y-normal disk r 1, scale 2, Rz(90) (y -> -x), translate (1,0,0): in the plane x = 1,
    # normal (-1,0,0), radius 2
    dk = Disk(radius=1, transform=Transform(scale=2, rotate=(0, 0, 90), translate=(1, 0, 0)))
    assert_hit(first_hit([dk], (5, 1.9, 0), (-1, 0, 0)), 4.0, (1, 1.9, 0), (-1, 0, 0))
    assert first_hit([dk], (5, 1.5, 1.5), (-1, 0, 0)) is None  # radial sqrt(4.5) > 2


def test_disk_non_uniform_scale_is_an_ellipse():
    # y-normal unit disk scaled (2,1,1): the ellipse x^2/4 + z^2 <= 1 in y = 0
    dk = [Disk(radius=1, transform=Transform(scale=(2, 1, 1)))]
    assert_hit(first_hit(dk, (1.9, 2, 0), (0, -1, 0)), 2.0, (1.9, 0, 0), (0, 1, 0))
    assert_hit(first_hit(dk, (0.5, 2, 0.95), (0, -1, 0)), 2.0, (0.5, 0, 0.95), (0, 1, 0))
    assert first_hit(dk, (1.9, 2, 0.5), (0, -1, 0)) is None  # 0.9025 + 0.25 > 1
    assert first_hit(dk, (0, 2, 1.05), (0, -1, 0)) is None


def test_disk_tilted_non_uniform_scale_normal():
    # disk in the plane x + y = 0 (normal (1,1,0)), scale (2,1,1): the plane becomes
    # X/2 + Y = 0 with normal (1,2,0)/sqrt(5); ray down -y from (0,5,0) hits the centre
    dk = Disk(normal=(1, 1, 0), radius=1, transform=Transform(scale=(2, 1, 1)))
    assert_hit(first_hit([dk], (0, 5, 0), (0, -1, 0)), 5.0, (0, 0, 0), (1 / S5, 2 / S5, 0))


# ---------------------------------------------------------------- triangle


TRI = Triangle(vertices=((0, 0, 0), (1, 0, 0), (0, 1, 0)))  # (b-a) x (c-a) = +z


@pytest.mark.parametrize(
    "origin, direction, t, p",
    [
        ((0.25, 0.25, 3), (0, 0, -1), 3.0, (0.25, 0.25, 0)),
        ((0.25, 0.25, -3), (0, 0, 1), 3.0, (0.25, 0.25, 0)),  # from behind: still +z
        ((0, 0, 2), (0.15, 0.3, -1), 2.0, (0.3, 0.6, 0)),  # oblique, u + v = 0.9
    ],
)
def test_triangle_hits(origin, direction, t, p):
    assert_hit(first_hit([TRI], origin, direction), t, p, (0, 0, 1))


@pytest.mark.parametrize("xy", [(0.6, 0.6), (-0.1, 0.5), (0.5, -0.1), (1.1, 0), (2, 2)])
def test_triangle_misses(xy):
    assert first_hit([TRI], (*xy, 3), (0, 0, -1)) is None


def test_triangle_parallel_and_away_miss():
    assert first_hit([TRI], (-1, 0.2, 0), (1, 0, 0)) is None  # in its plane (det = 0)
    assert first_hit([TRI], (0.25, 0.25, 3), (0, 0, 1)) is None


def test_triangle_winding_sets_normal():
    # vertices a, c, b: (c-a) x (b-a) = (0,1,0) x (1,0,0) = (0,0,-1)
    tri = Triangle(vertices=((0, 0, 0), (0, 1, 0), (1, 0, 0)))
    assert_hit(first_hit([tri], (0.25, 0.25, 3), (0, 0, -1)), 3.0, (0.25, 0.25, 0), (0, 0, -1))


def test_triangles_sharing_the_diagonal_leave_no_crack():
    a = Triangle(vertices=((0, 0, 0), (1, 0, 0), (0, 1, 0)))
    b = Triangle(vertices=((1, 0, 0), (1, 1, 0), (0, 1, 0)))
    scene = Compiled([a, b])
    for x in np.linspace(0.01, 0.99, 37):
        hit = scene.hit((x, 1 - x, 1), (0, 0, -1))
        assert hit is not None, f"crack at x={x!r}"
        assert hit.t == pytest.approx(1.0, rel=REL)


def test_triangle_non_uniform_scale_and_translate():
    # scale (2,3,1): vertices (0,0), (2,0), (0,3) -> inside when x/2 + y/3 <= 1; translate z+1
    tri = Triangle(vertices=((0, 0, 0), (1, 0, 0), (0, 1, 0)),
                   transform=Transform(scale=(2, 3, 1), translate=(0, 0, 1)))
    assert_hit(first_hit([tri], (0.9, 1.6, 5), (0, 0, -1)), 4.0, (0.9, 1.6, 1), (0, 0, 1))  # .983
    assert first_hit([tri], (1.1, 1.5, 5), (0, 0, -1)) is None  # 0.55 + 0.5 = 1.05


@pytest.mark.parametrize("shape", [RECT, DISK, TRI], ids=["rectangle", "disk", "triangle"])
def test_flat_shapes_respect_tmin_tmax(shape):
    # each is hit by the ray from (p + 5 n) along -n at t = 5, at a point p inside it
    p = {"rectangle": (1, 0.5, 0), "disk": (0.5, 0, 0), "triangle": (0.25, 0.25, 0)}
    n = {"rectangle": (0, 0, 1), "disk": (0, 1, 0), "triangle": (0, 0, 1)}
    key = shape.type
    o = np.add(p[key], np.multiply(5, n[key]))
    scene = Compiled([shape])
    d = tuple(-x for x in n[key])
    assert_hit(scene.hit(o, d, tmin=4.9, tmax=5.1), 5.0, p[key], n[key])
    assert scene.hit(o, d, tmax=4.9) is None
    assert scene.hit(o, d, tmin=5.1) is None


# ---------------------------------------------------------------- box


BOX = Box(min=(-1, -1, -1), max=(1, 2, 3))


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        ((0, 0, 10), (0, 0, -1), 7.0, (0, 0, 3), (0, 0, 1)),
        ((-5, 0.5, 0), (1, 0, 0), 4.0, (-1, 0.5, 0), (-1, 0, 0)),
        ((0, -4, 0), (0, 2, 0), 1.5, (0, -1, 0), (0, -1, 0)),
        # (0.1,0.1,-1) from (0,0,10): z = 3 at t = 7, (0.7, 0.7) inside the face
        ((0, 0, 10), (0.1, 0.1, -1), 7.0, (0.7, 0.7, 3), (0, 0, 1)),
    ],
)
def test_box_hits(origin, direction, t, p, n):
    assert_hit(first_hit([BOX], origin, direction), t, p, n)


@pytest.mark.parametrize(
    "origin, direction",
    [
        ((1.5, 0, 10), (0, 0, -1)),  # beside
        ((0, 0, 10), (0, 0, 1)),  # away
        # past the corner: x in [-1,1] for t in [4,6], y = 5 - 0.45t in [-1,2] for t >= 6.67
        ((5, 5, 0), (-1, -0.45, 0)),
    ],
)
def test_box_misses(origin, direction):
    assert first_hit([BOX], origin, direction) is None


def test_box_grazing_edge():
    # the face x = 1: rays down -z at x = 1 + 1e-9 miss, at x = 1 - 1e-9 hit the top at t = 7
    assert first_hit([BOX], (1 + 1e-9, 0, 10), (0, 0, -1)) is None
    hit = first_hit([BOX], (1 - 1e-9, 0, 10), (0, 0, -1))
    assert_hit(hit, 7.0, (1 - 1e-9, 0, 3), (0, 0, 1))


@pytest.mark.parametrize(
    "direction, t, p, n",
    [
        ((1, 0, 0), 1.0, (1, 0, 0), (1, 0, 0)),
        ((0, -1, 0), 1.0, (0, -1, 0), (0, -1, 0)),
        ((0, 0, 0.5), 6.0, (0, 0, 3), (0, 0, 1)),
        ((1, 1, 1), 1.0, (1, 1, 1), (1, 0, 0)),  # x leaves first (t=1 vs y at 2, z at 3)
    ],
)
def test_box_origin_inside_exits_outward(direction, t, p, n):
    hit = first_hit([BOX], (0, 0, 0), direction)
    assert_hit(hit, t, p, n)
    assert np.dot(hit.n, direction) > 0


def test_box_tmin_tmax():
    # from (0,0,10) down -z: enters z = 3 at t = 7, leaves z = -1 at t = 11
    hit = first_hit([BOX], (0, 0, 10), (0, 0, -1), tmin=8.0)
    assert_hit(hit, 11.0, (0, 0, -1), (0, 0, -1))
    assert first_hit([BOX], (0, 0, 10), (0, 0, -1), tmax=6.5) is None
    assert first_hit([BOX], (0, 0, 10), (0, 0, -1), tmin=11.5) is None


# parallelepiped: p = a e1 + b e2 + c e3 with e1 = (2,0,0), e2 = (1,1,0), e3 = (0,0.5,1), so
# c = z, b = y - z/2, a = (x - b)/2 = (x - y + z/2)/2; faces a, b, c in {0, 1}; the outward
# normal of face k = 1 is grad k normalised (and minus that on k = 0):
#   grad a = (1,-1,1/2)/2 -> (2,-2,1)/3, grad b = (0,1,-1/2) -> (0,2,-1)/sqrt(5), grad c = +z
PAR = Box(corner=(0, 0, 0), edges=((2, 0, 0), (1, 1, 0), (0, 0.5, 1)))


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        # down -z at (1.5, 0.8): c = 1 at z = 1 where b = 0.3, a = 0.6 -> t = 9
        ((1.5, 0.8, 10), (0, 0, -1), 9.0, (1.5, 0.8, 1), (0, 0, 1)),
        # along +x at y = z = 0.5: b = 0.25, a = 0 at x = 0.25 -> t = 5.25
        ((-5, 0.5, 0.5), (1, 0, 0), 5.25, (0.25, 0.5, 0.5), (-2 / 3, 2 / 3, -1 / 3)),
        # along -y at x = 1.5, z = 0.4: b = 1 at y = 1.2 (a = 0.25, c = 0.4) -> t = 3.8
        ((1.5, 5, 0.4), (0, -1, 0), 3.8, (1.5, 1.2, 0.4), (0, 2 / S5, -1 / S5)),
        # along +y at x = 1, z = 0.4: b = 0 at y = 0.2 (a = 0.5) -> t = 5.2
        ((1, -5, 0.4), (0, 1, 0), 5.2, (1, 0.2, 0.4), (0, -2 / S5, 1 / S5)),
    ],
)
def test_parallelepiped_hits(origin, direction, t, p, n):
    assert_hit(first_hit([PAR], origin, direction), t, p, n)


def test_parallelepiped_exit_and_miss():
    # along +x at y = z = 0.5 leaves through a = 1 at x = 2.25 (t = 7.25)
    hit = first_hit([PAR], (-5, 0.5, 0.5), (1, 0, 0), tmin=6.0)
    assert_hit(hit, 7.25, (2.25, 0.5, 0.5), (2 / 3, -2 / 3, 1 / 3))
    # (0, 0.9, z) for z in [0,1]: a = (0 - 0.9 + z/2)/2 < 0 -> inside the AABB, outside
    assert first_hit([PAR], (0, 0.9, 10), (0, 0, -1)) is None


def test_box_non_uniform_scale_and_rotation():
    # [-1,1]^3 scaled (2,1,3) -> [-2,2] x [-1,1] x [-3,3]
    b = Box(min=(-1, -1, -1), max=(1, 1, 1), transform=Transform(scale=(2, 1, 3)))
    assert_hit(first_hit([b], (10, 0.5, 2.5), (-1, 0, 0)), 8.0, (2, 0.5, 2.5), (1, 0, 0))
    assert_hit(first_hit([b], (1.5, 0, 10), (0, 0, -1)), 7.0, (1.5, 0, 3), (0, 0, 1))
    # then Rz(90) (x -> y): [-1,1] x [-2,2] x [-3,3]
    b = Box(min=(-1, -1, -1), max=(1, 1, 1), transform=Transform(scale=(2, 1, 3),
                                                                 rotate=(0, 0, 90)))
    assert_hit(first_hit([b], (0.5, 10, 0), (0, -1, 0)), 8.0, (0.5, 2, 0), (0, 1, 0))
    assert first_hit([b], (1.5, 10, 0), (0, -1, 0)) is None


def test_box_arbitrary_axis_angle():
    # box [0,1] x [0,2] x [0,3] rotated 50 deg about (1,2,3), translated by (1,-1,2): aim at
    # the centre of the (rotated) face x = 1 along its inward normal from 5 units away
    tf = Transform(axis_angle=AxisAngle(axis=(1, 2, 3), angle=50), translate=(1, -1, 2))
    b = Box(min=(0, 0, 0), max=(1, 2, 3), transform=tf)
    face = rodrigues((1, 1, 1.5), (1, 2, 3), 50) + (1, -1, 2)
    n = rodrigues((1, 0, 0), (1, 2, 3), 50)
    assert_hit(first_hit([b], face + 5 * n, -2 * n), 2.5, face, n)


def test_box_random_rays_hit_a_face_with_outward_normal():
    rng = np.random.default_rng(7)
    corner = np.array([0.3, -0.2, 0.5])
    edges = np.array([[1.5, 0.2, 0.0], [0.4, 1.0, 0.3], [-0.2, 0.1, 0.8]])  # rows
    scene = Compiled([Box(corner=tuple(corner), edges=tuple(map(tuple, edges)))])
    inv = np.linalg.inv(edges.T)  # local coordinates (a, b, c) = inv @ (p - corner)
    for o, d in random_rays_into(rng, 200, lambda g: corner + g.uniform(0.01, 0.99, 3) @ edges):
        hit = scene.hit(o, d)
        assert hit is not None
        local = inv @ (hit.p - corner)
        assert np.all(local > -1e-9) and np.all(local < 1 + 1e-9)
        gap = np.minimum(np.abs(local), np.abs(local - 1))
        k = int(np.argmin(gap))
        assert gap[k] < 1e-9, "hit point is not on a face"
        side = 1.0 if abs(local[k] - 1) < abs(local[k]) else -1.0
        close(hit.n, side * unit(inv[k]))
        assert np.dot(hit.n, d) < 0


# ---------------------------------------------------------------- cylinder


CYL = Cylinder(base=(0, 0, 0), top=(0, 2, 0), radius=1)
OPEN_CYL = Cylinder(base=(0, 0, 0), top=(0, 2, 0), radius=1, capped=False)


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        ((5, 1, 0), (-1, 0, 0), 4.0, (1, 1, 0), (1, 0, 0)),
        # z = 0.6: x = 0.8 on the wall -> t = 4.2, n = (0.8, 0, 0.6)
        ((5, 1, 0.6), (-1, 0, 0), 4.2, (0.8, 1, 0.6), (0.8, 0, 0.6)),
        ((0.5, 5, 0), (0, -1, 0), 3.0, (0.5, 2, 0), (0, 1, 0)),  # top cap
        ((0.5, -5, 0.3), (0, 1, 0), 5.0, (0.5, 0, 0.3), (0, -1, 0)),  # bottom cap
        # oblique into the top cap: (0,4,0) + t(0.25,-1,0): y = 2 at t = 2, x = 0.5
        ((0, 4, 0), (0.25, -1, 0), 2.0, (0.5, 2, 0), (0, 1, 0)),
    ],
)
def test_cylinder_hits(origin, direction, t, p, n):
    assert_hit(first_hit([CYL], origin, direction), t, p, n)


@pytest.mark.parametrize(
    "origin, direction",
    [
        ((1.1, 5, 0), (0, -1, 0)),  # beside, parallel to the axis
        ((5, 2.5, 0), (-1, 0, 0)),  # above the top
        ((5, -0.5, 0), (-1, 0, 0)),  # below the base (the infinite cylinder would be hit)
        ((5, 1, 0), (1, 0, 0)),  # away
        ((5, 1, 1.2), (-1, 0, 0)),  # beside
    ],
)
def test_cylinder_misses(origin, direction):
    assert first_hit([CYL], origin, direction) is None


@pytest.mark.parametrize("diagonal", [False, True])
def test_cylinder_tangent_and_grazing(diagonal):
    # rays perpendicular to the axis (y) at distance rho from it, at height y = 1; either along
    # -z (silhouette x = 1, on the BVH box) or along -(1,0,1)/sqrt(2) (silhouette inside it).
    # With w = sqrt(1 - rho^2) the wall is met at t = 5 - w, p = rho e + w (-d) + (0,1,0)
    d = -unit((1, 0, 1)) if diagonal else np.array([0.0, 0.0, -1.0])
    e = unit((1, 0, -1)) if diagonal else np.array([1.0, 0.0, 0.0])
    y = np.array([0.0, 1.0, 0.0])

    def ray(rho):
        return first_hit([CYL], rho * e - 5 * d + y, d)

    hit = ray(1.0)  # exact tangent: hit or miss, no NaN
    if hit is not None:
        assert math.isfinite(hit.t) and np.all(np.isfinite(hit.n))
        assert math.hypot(hit.p[0], hit.p[2]) == pytest.approx(1.0, abs=1e-6)
    assert ray(1 + 1e-9) is None
    rho = 1 - 1e-6
    w = math.sqrt(1 - rho * rho)
    p = rho * e - w * d + y
    assert_hit(ray(rho), 5 - w, p, (p[0], 0, p[2]))


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        ((0, 1, 0), (1, 0, 0), 1.0, (1, 1, 0), (1, 0, 0)),
        ((0, 1, 0), (0, 1, 0), 1.0, (0, 2, 0), (0, 1, 0)),
        ((0, 1, 0), (0, -0.5, 0), 2.0, (0, 0, 0), (0, -1, 0)),
        # (0,1.5,0) + t(0.6,0,0.8)/... -> radial = t = 1 at (0.6, 1.5, 0.8)
        ((0, 1.5, 0), (0.6, 0, 0.8), 1.0, (0.6, 1.5, 0.8), (0.6, 0, 0.8)),
    ],
)
def test_cylinder_origin_inside_exits_outward(origin, direction, t, p, n):
    hit = first_hit([CYL], origin, direction)
    assert_hit(hit, t, p, n)
    assert np.dot(hit.n, direction) > 0


def test_cylinder_tmin_gives_far_wall():
    # from (5,1,0) along -x: wall at t = 4 (x = 1) and t = 6 (x = -1)
    hit = first_hit([CYL], (5, 1, 0), (-1, 0, 0), tmin=5.0)
    assert_hit(hit, 6.0, (-1, 1, 0), (-1, 0, 0))
    assert first_hit([CYL], (5, 1, 0), (-1, 0, 0), tmax=3.9) is None


def test_uncapped_cylinder_seen_through_open_end_hits_inner_wall():
    # from (0,5,0) along (0.3,-1,0): crosses y = 2 at t = 3 (x = 0.9, inside the rim) and meets
    # the wall x = 1 at t = 1/0.3 = 10/3, y = 5/3; the normal still points outward (+x)
    hit = first_hit([OPEN_CYL], (0, 5, 0), (0.3, -1, 0))
    assert_hit(hit, 10 / 3, (1, 5 / 3, 0), (1, 0, 0))
    assert np.dot(hit.n, (0.3, -1, 0)) > 0
    # the capped one stops at the top cap instead
    assert_hit(first_hit([CYL], (0, 5, 0), (0.3, -1, 0)), 3.0, (0.9, 2, 0), (0, 1, 0))


def test_uncapped_cylinder_outside_and_down_the_axis():
    # the outer wall is the same as the capped one's
    assert_hit(first_hit([OPEN_CYL], (5, 1, 0), (-1, 0, 0)), 4.0, (1, 1, 0), (1, 0, 0))
    # straight down the open tube: nothing to hit
    assert first_hit([OPEN_CYL], (0.5, 5, 0), (0, -1, 0)) is None


@pytest.mark.parametrize(
    "cyl_top, tf, cap_ray, cap_hit, side_ray, side_hit",
    [
        # y-axis cylinder, Rx(90) (y -> z): along +z from 0 to 2
        ((0, 2, 0), Transform(rotate=(90, 0, 0)),
         ((0, 0, 10), (0, 0, -1)), (8.0, (0, 0, 2), (0, 0, 1)),
         ((0, 5, 1), (0, -1, 0)), (4.5, (0, 0.5, 1), (0, 1, 0))),
        # z-axis cylinder, Ry(90) (z -> x): along +x from 0 to 2
        ((0, 0, 2), Transform(rotate=(0, 90, 0)),
         ((10, 0, 0), (-1, 0, 0)), (8.0, (2, 0, 0), (1, 0, 0)),
         ((1, 5, 0), (0, -1, 0)), (4.5, (1, 0.5, 0), (0, 1, 0))),
        # x-axis cylinder, Rz(90) (x -> y): along +y from 0 to 2
        ((2, 0, 0), Transform(rotate=(0, 0, 90)),
         ((0, 10, 0), (0, -1, 0)), (8.0, (0, 2, 0), (0, 1, 0)),
         ((5, 1, 0), (-1, 0, 0)), (4.5, (0.5, 1, 0), (1, 0, 0))),
        # x-axis cylinder, 120 deg about (1,1,1) (x -> y -> z -> x): along +y
        ((2, 0, 0), Transform(axis_angle=AxisAngle(axis=(1, 1, 1), angle=120)),
         ((0, 10, 0), (0, -1, 0)), (8.0, (0, 2, 0), (0, 1, 0)),
         ((0, 1, 5), (0, 0, -1)), (4.5, (0, 1, 0.5), (0, 0, 1))),
        # x-axis cylinder, 30 deg about z: axis (cos 30, sin 30, 0); uniform scale 3 first
        # makes it radius 1.5, length 6
        ((2, 0, 0), Transform(scale=3, axis_angle=AxisAngle(axis=(0, 0, 1), angle=30)),
         ((10 * S3 / 2, 5, 0), (-S3 / 2, -0.5, 0)), (4.0, (3 * S3, 3, 0), (S3 / 2, 0.5, 0)),
         ((S3 / 2, 0.5, 5), (0, 0, -1)), (3.5, (S3 / 2, 0.5, 1.5), (0, 0, 1))),
    ],
)
def test_cylinder_rotated(cyl_top, tf, cap_ray, cap_hit, side_ray, side_hit):
    radius = 0.5
    scene = Compiled([Cylinder(base=(0, 0, 0), top=cyl_top, radius=radius, transform=tf)])
    assert_hit(scene.hit(*cap_ray), *cap_hit)
    assert_hit(scene.hit(*side_ray), *side_hit)


def test_cylinder_non_uniform_scale():
    # y-axis unit cylinder of height 1 scaled (2,3,1): x^2/4 + z^2 <= 1, 0 <= y <= 3
    cyl = [Cylinder(base=(0, 0, 0), top=(0, 1, 0), radius=1, transform=Transform(scale=(2, 3, 1)))]
    assert_hit(first_hit(cyl, (10, 1.5, 0), (-1, 0, 0)), 8.0, (2, 1.5, 0), (1, 0, 0))
    # x = 1 along -z: z = sqrt(3)/2; normal = grad (x^2/4 + z^2) = (x/4, 0, z) normalised
    hit = first_hit(cyl, (1, 1.5, 10), (0, 0, -1))
    assert_hit(hit, 10 - S3 / 2, (1, 1.5, S3 / 2), unit((0.25, 0, S3 / 2)))
    assert_hit(first_hit(cyl, (1.5, 10, 0.2), (0, -1, 0)), 7.0, (1.5, 3, 0.2), (0, 1, 0))
    assert_hit(first_hit(cyl, (1.5, -1, 0.2), (0, 1, 0)), 1.0, (1.5, 0, 0.2), (0, -1, 0))
    assert first_hit(cyl, (1.9, 10, 0.5), (0, -1, 0)) is None  # 0.9025 + 0.25 > 1
    assert first_hit(cyl, (5, 3.1, 0), (-1, 0, 0)) is None


def _frustum_surface_check(hit, d, base, top, r0, r1):
    """The hit lies on the side (radius r0 + (r1-r0) z/h at height z along the axis) or on a
    cap, with that part's outward unit normal (either one on a rim), facing the ray."""
    axis = np.subtract(top, base)
    h = np.linalg.norm(axis)
    axis = axis / h
    q = hit.p - base
    z = float(q @ axis)
    perp = q - z * axis
    rho = float(np.linalg.norm(perp))
    k = (r1 - r0) / h
    tol = 1e-9 * max(h, r0, r1)
    normals = []
    if -tol <= z <= h + tol and abs(rho - (r0 + k * z)) <= tol:
        normals.append(unit(perp / rho - k * axis))  # grad(rho - r(z))
    if abs(z) <= tol and rho <= r0 + tol:
        normals.append(-axis)
    if abs(z - h) <= tol and rho <= r1 + tol:
        normals.append(axis)
    assert normals, f"hit {hit.p} is neither on the side nor on a cap"
    assert any(np.allclose(hit.n, n, rtol=0, atol=1e-9) for n in normals), (hit.n, normals)
    assert np.linalg.norm(hit.n) == pytest.approx(1.0, abs=1e-12)
    assert np.dot(hit.n, d) < 0


@pytest.mark.parametrize(
    "base, top, r0, r1",
    [
        ((1, 2, 3), (2, 4, 5), 0.7, 0.7),  # oblique cylinder
        ((0, 0, 0), (0, 0, 1), 2.0, 2.0),  # short fat one
        ((-1, 0, 1), (1, 1, -1), 1.0, 0.0),  # oblique cone
        ((0.5, 0.5, 0.5), (0.5, -1.5, 0.5), 1.2, 0.4),  # frustum pointing down
        ((0, 0, 0), (0, 1, 1), 0.3, 1.0),  # frustum widening towards the top
    ],
)
def test_cylinder_and_cone_random_rays_on_surface_outward(base, top, r0, r1):
    shape = (Cylinder(base=base, top=top, radius=r0) if r0 == r1
             else Cone(base=base, top=top, radius=r0, top_radius=r1))
    scene = Compiled([shape])
    axis = np.subtract(top, base)
    a = unit(np.cross(axis, (1, 0.3, 0.1)))
    b = unit(np.cross(axis, a))
    rng = np.random.default_rng(11)

    def inside(g):
        s = g.uniform(0.02, 0.98)
        r = (r0 + (r1 - r0) * s) * 0.95 * math.sqrt(g.uniform())
        phi = g.uniform(0, 2 * math.pi)
        return np.add(base, s * axis) + r * (math.cos(phi) * a + math.sin(phi) * b)

    for o, d in random_rays_into(rng, 150, inside):
        hit = scene.hit(o, d)
        assert hit is not None
        _frustum_surface_check(hit, d, base, top, r0, r1)


# ---------------------------------------------------------------- cone


CONE = Cone(base=(0, 0, 0), top=(0, 1, 0), radius=1)  # r(y) = 1 - y, apex (0,1,0)
SIDE_N = (1 / S2, 1 / S2, 0)  # grad(rho - (1 - y)) at a point with z = 0, x > 0


def test_cone_down_the_axis_hits_apex():
    # from (0,3,0) straight down: the apex (0,1,0) at t = 2 (a double root of the quadric)
    hit = first_hit([CONE], (0, 3, 0), (0, -1, 0))
    assert hit is not None
    assert hit.t == pytest.approx(2.0, abs=1e-9)
    assert np.all(np.isfinite(hit.n)) and np.dot(hit.n, (0, -1, 0)) < 0


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        # x = 0.1 straight down: r(y) = 0.1 at y = 0.9 -> t = 2.1
        ((0.1, 3, 0), (0, -1, 0), 2.1, (0.1, 0.9, 0), SIDE_N),
        # horizontal at y = 0.5: r = 0.5 -> t = 4.5
        ((5, 0.5, 0), (-1, 0, 0), 4.5, (0.5, 0.5, 0), SIDE_N),
        # z = 0.3 at y = 0.5: x = sqrt(0.25 - 0.09) = 0.4, n = (0.4/0.5, 1, 0.3/0.5)/sqrt(2)
        ((5, 0.5, 0.3), (-1, 0, 0), 4.6, (0.4, 0.5, 0.3), (0.8 / S2, 1 / S2, 0.6 / S2)),
        ((0.5, -3, 0), (0, 1, 0), 3.0, (0.5, 0, 0), (0, -1, 0)),  # base cap from below
    ],
)
def test_cone_hits(origin, direction, t, p, n):
    assert_hit(first_hit([CONE], origin, direction), t, p, n)


@pytest.mark.parametrize(
    "origin, direction",
    [
        ((5, 0.5, 0.6), (-1, 0, 0)),  # beside: r(0.5) = 0.5 < 0.6
        ((5, 1.2, 0), (-1, 0, 0)),  # above the apex: the quadric's upper nappe is not the cone
        ((5, -0.5, 0), (-1, 0, 0)),  # below the base, where the quadric has radius 1.5
        ((1.01, 5, 0), (0, -1, 0)),  # beside the base rim
        ((0.1, 3, 0), (0, 1, 0)),  # away
    ],
)
def test_cone_misses(origin, direction):
    assert first_hit([CONE], origin, direction) is None


def test_cone_grazing_silhouette():
    # at y = 0.5 the silhouette is z = 0.5: just outside misses, just inside hits
    assert first_hit([CONE], (5, 0.5, 0.5 + 1e-9), (-1, 0, 0)) is None
    z = 0.5 - 1e-6
    hit = first_hit([CONE], (5, 0.5, z), (-1, 0, 0))
    x = math.sqrt(0.25 - z * z)
    assert hit is not None and hit.t == pytest.approx(5 - x, rel=REL)
    assert math.hypot(hit.p[0], hit.p[2]) == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize(
    "direction, t, p, n",
    [
        ((1, 0, 0), 0.75, (0.75, 0.25, 0), SIDE_N),  # r(0.25) = 0.75
        ((0, -1, 0), 0.25, (0, 0, 0), (0, -1, 0)),  # base cap
        # (t/2, 0.25 + t/2, 0) meets x = 1 - y at t/2 = 0.75 - t/2 -> t = 0.75
        ((0.5, 0.5, 0), 0.75, (0.375, 0.625, 0), SIDE_N),
    ],
)
def test_cone_origin_inside_exits_outward(direction, t, p, n):
    hit = first_hit([CONE], (0, 0.25, 0), direction)
    assert_hit(hit, t, p, n)
    assert np.dot(hit.n, direction) > 0


def test_cone_tmin_tmax():
    # horizontal at y = 0.5: side at t = 4.5 and t = 5.5
    hit = first_hit([CONE], (5, 0.5, 0), (-1, 0, 0), tmin=5.0)
    assert_hit(hit, 5.5, (-0.5, 0.5, 0), (-1 / S2, 1 / S2, 0))
    assert first_hit([CONE], (5, 0.5, 0), (-1, 0, 0), tmax=4.4) is None
    assert first_hit([CONE], (5, 0.5, 0), (-1, 0, 0), tmin=5.6) is None


FRUSTUM = Cone(base=(0, 0, 0), top=(0, 2, 0), radius=2, top_radius=1)  # r(y) = 2 - y/2
FRUSTUM_N = (2 / S5, 1 / S5, 0)  # grad(rho - 2 + y/2) = (1, 1/2, 0) at z = 0, x > 0


@pytest.mark.parametrize(
    "origin, direction, t, p, n",
    [
        ((5, 1, 0), (-1, 0, 0), 3.5, (1.5, 1, 0), FRUSTUM_N),  # r(1) = 1.5
        ((0.5, 5, 0), (0, -1, 0), 3.0, (0.5, 2, 0), (0, 1, 0)),  # top cap (r 1)
        ((0, 5, 0), (0, -1, 0), 3.0, (0, 2, 0), (0, 1, 0)),  # down the axis: top cap centre
        # x = 1.2: outside the top cap, r(y) = 1.2 at y = 1.6 -> t = 3.4
        ((1.2, 5, 0), (0, -1, 0), 3.4, (1.2, 1.6, 0), FRUSTUM_N),
        ((1.9, -1, 0), (0, 1, 0), 1.0, (1.9, 0, 0), (0, -1, 0)),  # base cap
    ],
)
def test_frustum_hits(origin, direction, t, p, n):
    assert_hit(first_hit([FRUSTUM], origin, direction), t, p, n)


def test_frustum_misses_and_open_ends():
    assert first_hit([FRUSTUM], (5, 2.1, 0), (-1, 0, 0)) is None  # above the top cap
    assert first_hit([FRUSTUM], (5, 1, 1.6), (-1, 0, 0)) is None  # r(1) = 1.5 < 1.6
    # uncapped: straight down the axis passes through both open ends
    open_frustum = Cone(base=(0, 0, 0), top=(0, 2, 0), radius=2, top_radius=1, capped=False)
    assert first_hit([open_frustum], (0, 5, 0), (0, -1, 0)) is None


def test_uncapped_cone_seen_through_open_base_hits_inner_wall():
    # from (0,-3,0) along (0.1,1,0): crosses y = 0 at x = 0.3 (inside), then meets x = 1 - y:
    # 0.1 t = 1 - (t - 3) -> t = 4/1.1 = 40/11, p = (4/11, 7/11, 0); normal outward
    cone = Cone(base=(0, 0, 0), top=(0, 1, 0), radius=1, capped=False)
    hit = first_hit([cone], (0, -3, 0), (0.1, 1, 0))
    assert_hit(hit, 40 / 11, (4 / 11, 7 / 11, 0), SIDE_N)
    assert np.dot(hit.n, (0.1, 1, 0)) > 0


def test_cone_apex_down():
    # base (0,1,0) r 1, apex (0,0,0): r(y) = y; horizontal at y = 0.5 hits x = 0.5, the normal
    # grad(rho - y) = (1, -1, 0)/sqrt(2); from above it hits the cap y = 1 with normal +y
    cone = [Cone(base=(0, 1, 0), top=(0, 0, 0), radius=1)]
    assert_hit(first_hit(cone, (5, 0.5, 0), (-1, 0, 0)), 4.5, (0.5, 0.5, 0), (1 / S2, -1 / S2, 0))
    assert_hit(first_hit(cone, (0.5, 3, 0), (0, -1, 0)), 2.0, (0.5, 1, 0), (0, 1, 0))
    assert first_hit(cone, (5, -0.5, 0), (-1, 0, 0)) is None  # the lower nappe


def test_cone_transformed():
    # Rz(-90) (y -> x) then translate (1,0,0): base (1,0,0), apex (2,0,0), r(x) = 2 - x
    cone = Cone(base=(0, 0, 0), top=(0, 1, 0), radius=1,
                transform=Transform(rotate=(0, 0, -90), translate=(1, 0, 0)))
    assert_hit(first_hit([cone], (1.5, 5, 0), (0, -1, 0)), 4.5, (1.5, 0.5, 0), (1 / S2, 1 / S2, 0))
    assert_hit(first_hit([cone], (-3, 0.2, 0), (1, 0, 0)), 4.0, (1, 0.2, 0), (-1, 0, 0))


def test_cone_non_uniform_scale():
    # scale (1,2,1): height 2, r(y) = 1 - y/2; at y = 1 the radius is 0.5 and the outward
    # normal is grad(rho - 1 + y/2) = (1, 1/2, 0) -> (2, 1, 0)/sqrt(5)
    cone = [Cone(base=(0, 0, 0), top=(0, 1, 0), radius=1, transform=Transform(scale=(1, 2, 1)))]
    assert_hit(first_hit(cone, (5, 1, 0), (-1, 0, 0)), 4.5, (0.5, 1, 0), (2 / S5, 1 / S5, 0))
    assert first_hit(cone, (5, 2.1, 0), (-1, 0, 0)) is None
    assert_hit(first_hit(cone, (0.5, -1, 0), (0, 1, 0)), 1.0, (0.5, 0, 0), (0, -1, 0))


def test_cone_ray_parallel_to_a_generatrix():
    # d = (1,-1,0) is parallel to the side line from the apex (0,1,0) to (1,0,0), so the
    # quadratic degenerates to a linear equation. From (-2,2,0) the ray meets the far side
    # line x = y - 1 at 2t - 3 = 0 -> t = 1.5, p = (-0.5, 0.5, 0), n = (-1,1,0)/sqrt(2); it
    # never meets the near side line (parallel) and leaves through the base centre at t = 2
    assert_hit(first_hit([CONE], (-2, 2, 0), (1, -1, 0)), 1.5, (-0.5, 0.5, 0),
               (-1 / S2, 1 / S2, 0))
    assert_hit(first_hit([CONE], (-2, 2, 0), (1, -1, 0), tmin=1.6), 2.0, (0, 0, 0), (0, -1, 0))


def test_mirrored_scales_keep_normals_outward():
    # scale (-2,1,1) gives the same ellipsoid as (2,1,1): normal (x/4, y, z) normalised
    e = [Sphere(radius=1, transform=Transform(scale=(-2, 1, 1)))]
    assert_hit(first_hit(e, (1, 0, 10), (0, 0, -1)), 10 - S3 / 2, (1, 0, S3 / 2),
               unit((0.25, 0, S3 / 2)))
    # cone flipped by (1,-1,1): apex (0,-1,0), r(y) = 1 + y; at y = -0.5, x = 0.5 and the
    # outward normal is grad(rho - 1 - y) = (1,-1,0)/sqrt(2)
    c = [Cone(base=(0, 0, 0), top=(0, 1, 0), radius=1, transform=Transform(scale=(1, -1, 1)))]
    assert_hit(first_hit(c, (5, -0.5, 0), (-1, 0, 0)), 4.5, (0.5, -0.5, 0), (1 / S2, -1 / S2, 0))
    assert_hit(first_hit(c, (0.5, 3, 0), (0, -1, 0)), 3.0, (0.5, 0, 0), (0, 1, 0))  # base cap
    # cylinder flipped and stretched by (1,-2,1): y in [-2, 0]
    y = [Cylinder(base=(0, 0, 0), top=(0, 1, 0), radius=1, transform=Transform(scale=(1, -2, 1)))]
    assert_hit(first_hit(y, (0.5, -5, 0), (0, 1, 0)), 3.0, (0.5, -2, 0), (0, -1, 0))
    assert_hit(first_hit(y, (0.5, 5, 0), (0, -1, 0)), 5.0, (0.5, 0, 0), (0, 1, 0))
    # box [0,1]^3 scaled (-1,2,1): [-1,0] x [0,2] x [0,1]
    b = [Box(min=(0, 0, 0), max=(1, 1, 1), transform=Transform(scale=(-1, 2, 1)))]
    assert_hit(first_hit(b, (-5, 1, 0.5), (1, 0, 0)), 4.0, (-1, 1, 0.5), (-1, 0, 0))
    assert_hit(first_hit(b, (-0.5, 1, 0.5), (1, 0, 0)), 0.5, (0, 1, 0.5), (1, 0, 0))  # inside


# ---------------------------------------------------------------- random affine transforms


def affine(scale, rotate, axis_angle, translate):
    """Object-to-world (linear part, offset), built independently of ``Transform.matrix``:
    scale, then rotate about x, y, z in turn, then about ``axis_angle``, then translate."""
    lin = np.diag(np.asarray(scale, dtype=np.float64))
    steps = [(axis, angle) for axis, angle in zip(np.eye(3), rotate, strict=True)]
    steps.append(axis_angle)
    for axis, angle in steps:
        lin = np.column_stack([rodrigues(col, axis, angle) for col in lin.T])
    return lin, np.asarray(translate, dtype=np.float64)


def random_transform(rng, uniform):
    scale = rng.uniform(0.3, 3.0, 3) * rng.choice([-1.0, 1.0], 3)
    if uniform:
        scale = np.full(3, scale[0])
    rotate = rng.uniform(-180, 180, 3)
    axis, angle = rng.normal(size=3), rng.uniform(-180, 180)
    translate = rng.uniform(-3, 3, 3)
    tf = Transform(scale=tuple(scale), rotate=tuple(rotate),
                   axis_angle=AxisAngle(axis=tuple(axis), angle=angle), translate=tuple(translate))
    return tf, affine(scale, rotate, (axis, angle), translate)


def _sdf_and_sampler(kind):
    """(shape factory, a function that is 0 on the surface in object space, and a sampler of
    points strictly inside) for each closed shape."""
    if kind == "sphere":
        c = np.array([0.2, 0.1, -0.3])
        return (lambda tf: Sphere(center=tuple(c), radius=0.8, transform=tf),
                lambda x: np.linalg.norm(x - c) - 0.8,
                lambda g: c + 0.75 * unit(g.normal(size=3)) * g.uniform() ** (1 / 3))
    if kind == "box":
        lo, hi = np.array([-1.0, 0.0, -0.5]), np.array([1.0, 0.5, 0.5])
        return (lambda tf: Box(min=tuple(lo), max=tuple(hi), transform=tf),
                lambda x: float(np.max(np.maximum(lo - x, x - hi))),
                lambda g: g.uniform(lo + 0.01, hi - 0.01))
    r0, r1 = {"cylinder": (0.7, 0.7), "cone": (0.7, 0.0), "frustum": (0.7, 0.3)}[kind]

    def make(tf):
        if kind == "cylinder":
            return Cylinder(base=(0, 0, 0), top=(0, 1.5, 0), radius=r0, transform=tf)
        return Cone(base=(0, 0, 0), top=(0, 1.5, 0), radius=r0, top_radius=r1, transform=tf)

    def sdf(x):
        r = r0 + (r1 - r0) * x[1] / 1.5
        return max(math.hypot(x[0], x[2]) - r, -x[1], x[1] - 1.5)

    def inside(g):
        y = g.uniform(0.02, 1.48)
        r = (r0 + (r1 - r0) * y / 1.5) * 0.95 * math.sqrt(g.uniform())
        phi = g.uniform(0, 2 * math.pi)
        return np.array([r * math.cos(phi), y, r * math.sin(phi)])

    return make, sdf, inside


@pytest.mark.parametrize("kind", ["sphere", "box", "cylinder", "cone", "frustum"])
def test_random_affine_transforms_closed_shapes(kind):
    # random scale (uniform or not, possibly mirrored), rotations, axis_angle and translation:
    # a ray aimed at an interior point hits; mapped back to object space the hit is on the
    # surface, and the normal is the normalised world gradient of the surface function
    # (by central differences), facing the ray
    make, sdf, inside = _sdf_and_sampler(kind)
    rng = np.random.default_rng(17)
    for trial in range(40):
        tf, (lin, off) = random_transform(rng, uniform=trial % 3 == 0)
        inv = np.linalg.inv(lin)

        def world_sdf(p, inv=inv, off=off):
            return sdf(inv @ (p - off))

        scene = Compiled([make(tf)])
        for o, d in random_rays_into(rng, 5, lambda g, lin=lin, off=off: lin @ inside(g) + off,
                                     far=40.0):
            hit = scene.hit(o, d)
            assert hit is not None, (kind, trial)
            assert abs(world_sdf(hit.p)) < 1e-8, (kind, trial)
            eps = 1e-6
            grad = np.array([world_sdf(hit.p + eps * e) - world_sdf(hit.p - eps * e)
                             for e in np.eye(3)])
            close_enough = np.linalg.norm(hit.n - unit(grad)) < 1e-4
            assert close_enough, (kind, trial, hit.n, unit(grad))
            assert np.dot(hit.n, d) < 0


@pytest.mark.parametrize("kind", ["rectangle", "disk", "triangle"])
def test_random_affine_transforms_flat_shapes(kind):
    # a ray aimed at a point of the (transformed) flat shape, with d = (target - o) * s, hits
    # exactly there at t = 1/s; the normal is unit and perpendicular to the shape's edges
    rng = np.random.default_rng(23)
    e1, e2 = np.array([1.5, 0.0, 0.2]), np.array([0.3, 1.0, -0.1])
    corner = np.array([-0.5, -0.4, 0.1])
    for trial in range(40):
        tf, (lin, off) = random_transform(rng, uniform=trial % 3 == 0)
        if kind == "rectangle":
            shape = Rectangle(corner=tuple(corner), edge1=tuple(e1), edge2=tuple(e2), transform=tf)
        elif kind == "triangle":
            shape = Triangle(vertices=(tuple(corner), tuple(corner + e1), tuple(corner + e2)),
                             transform=tf)
        else:
            shape = Disk(center=tuple(corner), normal=tuple(np.cross(e1, e2)), radius=1.0,
                         transform=tf)
        scene = Compiled([shape])
        for _ in range(5):
            if kind == "disk":
                a, b = unit(e1), unit(np.cross(np.cross(e1, e2), e1))
                r, phi = 0.98 * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
                local = corner + r * (math.cos(phi) * a + math.sin(phi) * b)
            else:
                u, v = rng.uniform(0.01, 0.99, 2)
                while kind == "triangle" and u + v > 0.98:
                    u, v = rng.uniform(0.01, 0.99, 2)
                local = corner + u * e1 + v * e2
            target = lin @ local + off
            o = target + unit(rng.normal(size=3)) * 20
            s = rng.uniform(0.2, 3.0)
            hit = scene.hit(o, (target - o) * s)
            assert hit is not None, (kind, trial)
            assert hit.t == pytest.approx(1 / s, rel=1e-9)
            np.testing.assert_allclose(hit.p, target, atol=1e-9)
            assert np.linalg.norm(hit.n) == pytest.approx(1.0, abs=1e-12)
            assert abs(np.dot(hit.n, unit(lin @ e1))) < 1e-9
            assert abs(np.dot(hit.n, unit(lin @ e2))) < 1e-9


# ---------------------------------------------------------------- several shapes


@pytest.mark.parametrize("reverse", [False, True])
def test_nearest_of_two_spheres_wins_in_either_order(reverse):
    near = Sphere(center=(0, 0, 0), radius=1)
    far = Sphere(center=(0, 0, -5), radius=2)
    shapes = [near, far][::-1] if reverse else [near, far]
    hit = first_hit(shapes, (0, 0, 10), (0, 0, -1))
    assert_hit(hit, 9.0, (0, 0, 1), (0, 0, 1))
    assert shapes[hit.obj] is near
    # from the other side, the far one is nearer: z = -7 at t = 3
    hit = first_hit(shapes, (0, 0, -10), (0, 0, 1))
    assert_hit(hit, 3.0, (0, 0, -7), (0, 0, -1))
    assert shapes[hit.obj] is far


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize(
    "plane_z, t, p, n",
    [(-3.0, 9.0, (0, 0, 1), (0, 0, 1)),  # plane behind the sphere: the sphere wins
     (2.0, 8.0, (0, 0, 2), (0, 0, 1))],  # plane in front: the plane wins
)
def test_sphere_and_infinite_plane(reverse, plane_z, t, p, n):
    shapes = [UNIT_SPHERE, Plane(point=(0, 0, plane_z), normal=(0, 0, 1))]
    if reverse:
        shapes.reverse()
    assert_hit(first_hit(shapes, (0, 0, 10), (0, 0, -1)), t, p, n)


def test_row_of_spheres_any_order():
    # spheres r 0.5 at x = 0, 2, ..., 38; from x = -10 along +x the first is hit at x = -0.5;
    # from x = 9 (between the spheres at 8 and 10) the one at 10 is hit at x = 9.5
    rng = np.random.default_rng(3)
    xs = np.arange(20) * 2.0
    for _ in range(3):
        rng.shuffle(xs)
        scene = Compiled([Sphere(center=(float(x), 0, 0), radius=0.5) for x in xs])
        assert_hit(scene.hit((-10, 0, 0), (1, 0, 0)), 9.5, (-0.5, 0, 0), (-1, 0, 0))
        assert_hit(scene.hit((9, 0, 0), (1, 0, 0)), 0.5, (9.5, 0, 0), (-1, 0, 0))
        assert_hit(scene.hit((9, 0, 0), (-1, 0, 0)), 0.5, (8.5, 0, 0), (1, 0, 0))


def _stack_of_shapes():
    """One of every shape along the z axis, with the t at which a ray from (0,0,20) down -z
    meets each surface (entry and, for solids, exit)."""
    return [
        (Rectangle(corner=(-1, -1, 9), edge1=(2, 0, 0), edge2=(0, 2, 0)), [(11, 1)]),
        (Disk(center=(0, 0, 8), normal=(0, 0, 1), radius=1), [(12, 1)]),
        (Triangle(vertices=((-1, -1, 7), (1, -1, 7), (0, 1, 7))), [(13, 1)]),
        (Sphere(center=(0, 0, 5), radius=1), [(14, 1), (16, -1)]),
        (Box(min=(-1, -1, 2), max=(1, 1, 3)), [(17, 1), (18, -1)]),
        (Cylinder(base=(0, 0, -1), top=(0, 0, 1), radius=1), [(19, 1), (21, -1)]),
        (Cone(base=(0, 0, -2), top=(0, 0, -4), radius=1, top_radius=0.5), [(22, 1), (24, -1)]),
        (Plane(point=(0, 0, -6), normal=(0, 0, 1)), [(26, 1)]),
    ]


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_peeling_every_shape_in_any_order(seed):
    # walk the ray through the scene, restarting just past each hit (tmin), and check the
    # sequence of t, object and normal (+z on entry, -z on exit; flat shapes give +z)
    stack = _stack_of_shapes()
    order = np.random.default_rng(seed).permutation(len(stack)) if seed else np.arange(8)
    shapes = [stack[i][0] for i in order]
    expected = sorted((t, shape_i, nz) for shape_i, (_, hits) in enumerate(stack)
                      for t, nz in hits)
    scene = Compiled(shapes)
    tmin = 0.0
    for t, shape_i, nz in expected:
        hit = scene.hit((0, 0, 20), (0, 0, -1), tmin=tmin)
        assert hit is not None, f"missed {type(stack[shape_i][0]).__name__} at t={t}"
        assert shapes[hit.obj] is stack[shape_i][0]
        assert_hit(hit, t, (0, 0, 20 - t), (0, 0, nz))
        tmin = hit.t + 1e-9
    assert scene.hit((0, 0, 20), (0, 0, -1), tmin=tmin) is None


_FRUSTA = [
    Cylinder(base=(1, 2, 3), top=(2, 4, 5), radius=0.7),
    Cone(base=(-1, 0, 1), top=(1, 1, -1), radius=1.0, top_radius=0.0),
    Cone(base=(0, 0, 0), top=(0, 1, 1), radius=0.3, top_radius=1.0),
    Cylinder(base=(0, -1, 0), top=(0, 1, 0), radius=0.5, capped=False),
]


@settings(max_examples=300, deadline=None)
@given(st.integers(0, len(_FRUSTA) - 1), st.tuples(*[st.floats(-4, 4)] * 3),
       st.tuples(*[st.floats(-1.5, 1.5)] * 3), st.booleans())
def test_all_crossings_of_a_frustum_are_the_nearest_asked_again(which, origin, aim, at_rim):
    """``frustum_crossings`` (every crossing of the line at once, for CSG walks) lists what
    ``intersect_frustum`` returns when asked again from past each crossing: the same values
    in the same order, each once, including rays aimed exactly at a cap's rim."""
    from whitted.kernels.layout import PRIM_TYPE, SHAPE_FRUSTUM
    from whitted.kernels.shapes.frustum import frustum_crossings, intersect_frustum

    shape = _FRUSTA[which]
    geo = compile_scene(Scene(objects=[shape])).geometry
    i = [r for r in range(len(geo.prim_info)) if geo.prim_info[r, PRIM_TYPE] == SHAPE_FRUSTUM][0]
    P = geo.prim_params
    if at_rim:  # aim at a point of the top cap's rim
        axis = np.subtract(shape.top, shape.base)
        side = unit(np.cross(axis, (0.3, 1.0, 0.2)))
        r_top = getattr(shape, "top_radius", None)
        aim = np.add(shape.top, (shape.radius if r_top is None else r_top) * side)
    d = np.subtract(aim, origin)
    if np.linalg.norm(d) < 1e-3:
        return
    o = tuple(map(float, origin))
    d = tuple(map(float, d))
    asked = []
    t = -math.inf
    while len(asked) < 4 and (t := intersect_frustum(P, i, o, d, t, math.inf)) < math.inf:
        asked.append(t)
    found = [x for x in frustum_crossings(P, i, o, d) if x < math.inf]
    assert found == pytest.approx(asked, rel=1e-12, abs=1e-12)
    assert found == sorted(set(found))
