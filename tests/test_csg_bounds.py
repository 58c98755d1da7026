"""The box of a CSG difference cut by axis-aligned boxes (compile/csg_bounds.py): worked
boxes, the cutters that may not clip, and the same surfaces with and without the clip."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from whitted.compile import csg as csg_compile
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit
from whitted.kernels.layout import PRIM_TYPE, SHAPE_CSG
from whitted.scene import CSG, Box, Cylinder, Scene, Sphere, Torus, Transform


def _root_box(shape):
    geo = compile_scene(Scene(objects=[shape])).geometry
    root = [i for i in range(len(geo.prim_info)) if geo.prim_info[i, PRIM_TYPE] == SHAPE_CSG][0]
    return geo.prim_params[root, 2:5], geo.prim_params[root, 5:8]


def test_half_a_ring_is_bounded_by_its_half():
    # a torus R = 0.9, r = 0.3 about y spans x in [-1.2, 1.2]; the box x <= 0 (covering it in
    # y and z) takes the low half: x in [0, 1.2]
    ring = CSG(operation="difference", objects=[
        Torus(major_radius=0.9, minor_radius=0.3),
        Box(min=(-1.5, -1.0, -1.5), max=(0.0, 1.0, 1.5))])
    lo, hi = _root_box(ring)
    assert lo == pytest.approx((0.0, -0.3, -1.2), abs=1e-8)
    assert hi == pytest.approx((1.2, 0.3, 1.2), abs=1e-8)


def test_the_clip_is_taken_to_the_world_by_the_whole_transform():
    # a unit ball minus its top half (z >= 0), the whole turned 90 degrees about x: the
    # bottom half z in [-1, 0] goes to y in [0, 1] (y' = -z), and moved by (5, 0, 0)
    half = CSG(operation="difference", objects=[
        Sphere(radius=1.0), Box(min=(-2.0, -2.0, 0.0), max=(2.0, 2.0, 2.0))],
        transform=Transform(rotate=(90.0, 0.0, 0.0), translate=(5.0, 0.0, 0.0)))
    lo, hi = _root_box(half)
    assert lo == pytest.approx((4.0, 0.0, -1.0), abs=1e-8)
    assert hi == pytest.approx((6.0, 1.0, 1.0), abs=1e-8)


@pytest.mark.parametrize("cutter", [
    Sphere(center=(-2.0, 0.0, 0.0), radius=2.0),  # not a box
    Box(min=(-1.5, -1.0, -1.5), max=(0.0, 1.0, 1.5),
        transform=Transform(rotate=(0.0, 45.0, 0.0))),  # turned off the axes
    Box(corner=(-1.5, -1.0, -1.5), edges=((1.5, 0.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, 3.0))),
    Box(min=(-1.5, -0.1, -1.5), max=(0.0, 1.0, 1.5)),  # does not hold the ring across y
    Cylinder(base=(0.0, -2.0, 0.0), top=(0.0, 2.0, 0.0), radius=0.5),
])
def test_other_cutters_leave_the_first_operands_box(cutter):
    ring = CSG(operation="difference", objects=[Torus(major_radius=0.9, minor_radius=0.3),
                                                cutter])
    lo, hi = _root_box(ring)
    assert lo == pytest.approx((-1.2, -0.3, -1.2), abs=1e-8)
    assert hi == pytest.approx((1.2, 0.3, 1.2), abs=1e-8)


# (difference, its cut faces as (axis, position in the difference's own frame, the side
# of it that stays: +1 or -1))
_CUT_SHAPES = [
    (CSG(operation="difference", objects=[
        Torus(major_radius=0.9, minor_radius=0.3, transform=Transform(rotate=(20.0, 0.0, 0.0))),
        Box(min=(-1.5, -1.5, -1.5), max=(0.1, 1.5, 1.5))],
        transform=Transform(rotate=(70.0, 10.0, 0.0), translate=(0.2, 0.0, -0.3))),
     [(0, 0.1, 1)]),
    (CSG(operation="difference", objects=[
        Sphere(radius=1.0), Box(min=(-2.0, -2.0, 0.3), max=(2.0, 2.0, 2.0)),
        Box(min=(-2.0, -2.0, -2.0), max=(2.0, 2.0, -0.6))]),
     [(2, 0.3, -1), (2, -0.6, 1)]),
    (CSG(operation="difference", objects=[
        Box(min=(-1.0, -1.0, -1.0), max=(1.0, 1.0, 1.0)),
        Box(min=(0.5, -2.0, -2.0), max=(3.0, 2.0, 2.0), transform=Transform(scale=1.2)),
        Sphere(center=(0.0, 1.0, 0.0), radius=0.5)]),
     [(0, 0.6, -1)]),
]


def _compiled(shape, clip: bool):
    saved = csg_compile.clipped_bounds
    if not clip:
        csg_compile.clipped_bounds = lambda shape, matrix, lo, hi: (lo, hi)
    try:
        return compile_scene(Scene(objects=[shape])).geometry
    finally:
        csg_compile.clipped_bounds = saved


_GEOS = [(_compiled(s, True), _compiled(s, False)) for s, _ in _CUT_SHAPES]


@settings(max_examples=500, deadline=None)
@given(st.integers(0, len(_CUT_SHAPES) - 1), st.integers(0, 1), st.tuples(*[st.floats(-3, 3)] * 3),
       st.floats(-1.2, 1.2), st.floats(-1.2, 1.2), st.sampled_from(["face", "along", "near"]),
       st.floats(1e-6, 0.02))
def test_the_clipped_box_loses_no_surface(which, face, origin, u, v, how, gap):
    """Rays aimed at points of the cut faces, rays running along a cut face just on the side
    that stays (a clip that took too much loses them first), and rays anywhere near: the
    same first surface with the clip as without it."""
    shape, faces = _CUT_SHAPES[which]
    clipped, whole = _GEOS[which]
    axis, at, kept = faces[face % len(faces)]
    local = [u, v]
    local.insert(axis, at)
    m = shape.transform.matrix() if shape.transform is not None else np.eye(4)
    if how == "near":
        local[axis] = u * v
    if how == "along":  # in the plane at ``gap`` inside the kept side, across the object
        local[axis] = at + kept * gap
        along = np.array(origin, dtype=float)
        along[axis] = 0.0
        if np.linalg.norm(along) < 1e-3:
            return
        start = np.array(local) - 3.0 * along / np.linalg.norm(along)
        origin = m[:3, :3] @ start + m[:3, 3]
    aim = m[:3, :3] @ np.array(local) + m[:3, 3]
    d = tuple(map(float, np.subtract(aim, origin)))
    if math.sqrt(sum(x * x for x in d)) < 1e-3:
        return
    o = tuple(map(float, origin))
    stack = np.empty(128, np.int32)
    for tmin in (0.0, 0.5):
        a = closest_hit(clipped, o, d, tmin, math.inf, stack)
        b = closest_hit(whole, o, d, tmin, math.inf, stack)
        assert a[:2] == b[:2]
