"""Point lights' shadow rays test only the primitives their light-buffer cell lists: a cell's
list must hold every primitive a shadow ray through it can hit (else a shadow would be lost),
the cell a direction falls in must be the one whose cone holds it, and the image must be the
one the BVH walk gives."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

import whitted
from meshgen import uv_sphere
from one_lane import render_one_lane
from whitted.compile.light_buffers import buffer_side
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import hit_analytic
from whitted.kernels.layout import (
    CELL_COUNT,
    CELL_FIRST,
    CELL_OPAQUE,
    LIGHT_BUFFER,
    LIGHT_BUFFER_SIDE,
)
from whitted.kernels.light_buffer import LIGHT_BUFFER_CELLS, cell_cone, cube_cell
from whitted.kernels.shapes import INF

EPS = 1e-6  # the shadow rays' tmin


@njit(cache=False)
def _audit_cells(geo, cells, prims, first, side, light, points):
    """For each point: its cell's count (-1: overflowed), and how many primitives the shadow
    segment from the point to the light hits without their being listed."""
    n_prims = geo.prim_info.shape[0]
    counts = np.empty(points.shape[0], np.int64)
    unlisted = 0
    for k in range(points.shape[0]):
        p = (points[k, 0], points[k, 1], points[k, 2])
        w = (p[0] - light[0], p[1] - light[1], p[2] - light[2])
        dist = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        d = (-w[0] / dist, -w[1] / dist, -w[2] / dist)
        cell = first + cube_cell(w, side)
        n = cells[cell, 1]
        counts[k] = n
        if n < 0:
            continue
        start = cells[cell, 0]
        for i in range(n_prims):
            if hit_analytic(geo, i, p, d, EPS, dist - EPS) == INF:
                continue
            found = False
            for j in range(start, start + n):
                if prims[j] == i:
                    found = True
            if not found:
                unlisted += 1
    return counts, unlisted


def _cluttered_scene(lights):
    rng = np.random.default_rng(7)
    objects = [whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0)),
               whitted.Plane(point=(0, 0, -6), normal=(0, 0, 1))]
    for _ in range(14):
        c = rng.uniform((-4, 0.2, -4), (4, 3, 4))
        objects.append(whitted.Sphere(center=tuple(c), radius=float(rng.uniform(0.2, 0.7)),
                                      material="glass" if _ % 4 == 0 else None))
    for _ in range(4):
        c = rng.uniform((-4, 0.5, -4), (4, 2, 4))
        objects.append(whitted.Box(
            min=(-0.4, -0.3, -0.5), max=(0.4, 0.3, 0.5),
            transform=whitted.Transform(rotate=tuple(rng.uniform(-60, 60, 3)),
                                        translate=tuple(c))))
    verts, faces = uv_sphere(8, 12)
    objects.append(whitted.Mesh(vertices=verts * 0.8 + (1.0, 1.2, -1.0), faces=faces))
    objects.append(whitted.Rectangle(corner=(-1, 2.5, 2), edge1=(1.5, 0, 0), edge2=(0, 0.2, 1)))
    objects.append(whitted.Cone(base=(2.5, 0, 2.5), top=(2.5, 2, 2.5), radius=0.6))
    return whitted.Scene(objects=objects, lights=lights,
                         materials={"glass": whitted.Material(preset="glass")})


LIGHTS = [whitted.PointLight(position=(-1.0, 6.0, 1.5)),  # above the clutter
          whitted.PointLight(position=(0.5, 1.5, 0.2), intensity=0.5)]  # in the middle of it


def _points(rng, n):
    """Shaded points: on the floor, in the air among the objects, on the floor far beyond
    the objects' bounds, under the floor and behind the wall."""
    points = rng.uniform((-5, 0.0, -5), (5, 3.0, 5), (n, 3))
    points[: n // 4, 1] = 0.0
    points[n // 4 : n // 3, :] = rng.uniform((-80, 0, -5.9), (80, 0, 80), (n // 3 - n // 4, 3))
    points[n // 3 : n // 3 + 20, 1] = -0.5
    points[n // 3 + 20 : n // 3 + 40, 2] = -7.0
    return points


def test_every_primitive_a_shadow_ray_hits_is_in_its_cells_list():
    compiled = compile_scene(_cluttered_scene(LIGHTS))
    lights = compiled.lights
    rng = np.random.default_rng(5)
    points = _points(rng, 3000)
    for j in range(2):
        first = int(lights.table[j, LIGHT_BUFFER])
        side = int(lights.table[j, LIGHT_BUFFER_SIDE])
        assert first >= 0 and side == buffer_side(2, compiled.geometry.prim_info.shape[0])
        light = lights.table[j, 4:7].copy()
        counts, unlisted = _audit_cells(compiled.geometry, lights.buffer_cells,
                                        lights.buffer_prims, first, side, light, points)
        assert unlisted == 0
        # the cells prune: a shadow ray tests a few primitives, not the scene's ~190
        assert compiled.geometry.prim_info.shape[0] > 150
        assert (counts >= 0).mean() > 0.8 and np.median(counts[counts >= 0]) <= 3


def test_points_on_cell_and_face_edges_are_covered():
    """Directions exactly on the borders between cells and between cube faces (where the
    cell a direction falls in is decided by rounding) still find every occluder."""
    compiled = compile_scene(_cluttered_scene(LIGHTS[:1]))
    lights = compiled.lights
    side = int(lights.table[0, LIGHT_BUFFER_SIDE])
    light = lights.table[0, 4:7].copy()
    grid = -1.0 + 2.0 * np.arange(side + 1) / side
    dirs = []
    for u in grid[::4]:
        for v in grid[::3]:
            for sign in (1.0, -1.0):
                dirs += [(sign, u, v), (v, sign, u), (u, v, sign), (sign, sign, v)]
    dirs = np.array(dirs)
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    points = np.concatenate([light + dirs * r for r in (1.0, 3.0, 7.0, 12.0)])
    counts, unlisted = _audit_cells(compiled.geometry, lights.buffer_cells, lights.buffer_prims,
                                    0, side, light, points)
    assert unlisted == 0


def test_planes_out_of_a_cells_reach_are_left_out():
    scene = whitted.Scene(objects=[whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0))],
                          lights=[whitted.PointLight(position=(0, 5, 0))])
    lights = compile_scene(scene).lights
    side = int(lights.table[0, LIGHT_BUFFER_SIDE])
    up = lights.buffer_cells[cube_cell((0.3, 1.0, -0.2), side)]
    down = lights.buffer_cells[cube_cell((0.3, -1.0, -0.2), side)]
    level = lights.buffer_cells[cube_cell((1.0, 0.0, 0.0), side)]  # on the horizon: kept
    assert up[CELL_COUNT] == 0
    assert down[CELL_COUNT] == 1 and lights.buffer_prims[down[CELL_FIRST]] == 0
    assert down[CELL_OPAQUE] == 1
    assert level[CELL_COUNT] == 1


def test_point_lights_get_buffers_with_mesh_instances_too_and_other_lights_none():
    verts, faces = uv_sphere(8, 12)
    scene = whitted.Scene(objects=[whitted.Mesh(vertices=verts, faces=faces),
                                   whitted.Sphere(radius=1.0)],
                          lights=[whitted.PointLight(position=(0, 5, 0))])
    assert compile_scene(scene).lights.table[0, LIGHT_BUFFER] == 0  # the mesh flattened
    instanced = compile_scene(scene, flatten_limit=0)
    assert instanced.geometry.inst_prims.shape[0] == 1
    # its cells list the instance BVH's leaves too (tests/test_instance_light_buffer.py)
    assert instanced.lights.table[0, LIGHT_BUFFER] == 0
    scene = whitted.Scene(objects=[whitted.Sphere(radius=1.0)],
                          lights=[whitted.DirectionalLight(direction=(0, -1, 0)),
                                  whitted.DiskLight(center=(0, 4, 0), radius=1.0)])
    assert (compile_scene(scene).lights.table[:, LIGHT_BUFFER] == -1).all()


def test_many_lights_share_the_cell_budget_and_small_scenes_get_coarse_cells():
    assert buffer_side(1, 1000) == 128 and buffer_side(10, 1000) == 128
    side = buffer_side(40, 1000)
    assert 6 * side**2 * 40 <= LIGHT_BUFFER_CELLS < 6 * (side + 1) ** 2 * 40
    # a tiny scene gets coarse cells: it has nothing finer cells could separate
    assert buffer_side(1, 1) == 6 and buffer_side(1, 200) == 92


unit = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(w=st.tuples(unit, unit, unit), side=st.sampled_from([1, 2, 7, 64, 128]))
def test_a_direction_lies_in_the_cone_of_its_cell(w, side):
    norm = math.sqrt(sum(x * x for x in w))
    if norm < 1e-6:
        return
    c, tan_half = cell_cone(cube_cell(w, side), side)
    cos_w = sum(a * b for a, b in zip(c, w, strict=True)) / norm
    assert cos_w > 0
    tan_w = math.sqrt(max(0.0, 1.0 - cos_w * cos_w)) / cos_w
    assert tan_w <= tan_half * (1 + 1e-9) + 1e-12


def test_light_buffers_give_the_image_the_bvh_walk_gives():
    scene = _cluttered_scene(LIGHTS).model_copy(update={
        "render": whitted.RenderSettings(width=96, height=72),
        "camera": whitted.Camera(position=(0, 4, 10), look_at=(0, 1, 0), fov=50)})
    compiled = compile_scene(scene)
    with_buffers = render_one_lane(compiled, scene)
    table = compiled.lights.table.copy()
    table[:, LIGHT_BUFFER] = -1.0
    compiled.lights = compiled.lights._replace(table=table)
    walked = render_one_lane(compiled, scene)
    assert np.array_equal(with_buffers, walked)
    assert with_buffers.mean() > 0.05  # lit, not black


def test_compile_without_light_buffers_builds_none_and_gives_the_same_image():
    """Interactive previews compile without light buffers (most of a small scene's build
    time): no point light gets a buffer, and the picture is the one the buffers give."""
    scene = _cluttered_scene(LIGHTS).model_copy(update={
        "render": whitted.RenderSettings(width=64, height=48),
        "camera": whitted.Camera(position=(0, 4, 10), look_at=(0, 1, 0), fov=50)})
    buffered = compile_scene(scene)
    bare = compile_scene(scene, light_buffers=False)
    assert (buffered.lights.table[:, LIGHT_BUFFER] >= 0).any()
    assert (bare.lights.table[:, LIGHT_BUFFER] == -1).all()
    assert len(bare.lights.buffer_prims) == 0
    assert np.array_equal(render_one_lane(buffered, scene), render_one_lane(bare, scene))


def test_buffers_built_on_threads_equal_the_one_thread_build():
    """compile_scene's ``threads`` splits every light's cells into runs for a thread each
    (compile/light_buffers.py): the cells, their lists and the table are the same arrays on
    1, 2, 3 and 5 threads, for one light and for two (more runs than cells included)."""
    for lights in (LIGHTS[:1], LIGHTS):
        scene = _cluttered_scene(lights)
        one = compile_scene(scene, threads=1).lights
        assert one.buffer_prims.size > 0 and (one.buffer_cells[:, CELL_COUNT] > 0).any()
        for threads in (2, 3, 5):
            many = compile_scene(scene, threads=threads).lights
            for name in ("table", "buffer_cells", "buffer_prims"):
                a, b = getattr(one, name), getattr(many, name)
                assert a.dtype == b.dtype and np.array_equal(a, b), (len(lights), threads, name)
    tiny = whitted.Scene(objects=[whitted.Sphere(radius=1.0)], lights=LIGHTS[:1])  # 6 cells a side
    cells = [compile_scene(tiny, threads=t).lights.buffer_cells for t in (1, 300)]
    assert len(cells[0]) == 6 * 6 * 6 and np.array_equal(cells[0], cells[1])
    # lists are packed one after another: each cell starts where the previous one ended
    listed = np.maximum(one.buffer_cells[:, CELL_COUNT], 0)
    assert np.array_equal(one.buffer_cells[1:, CELL_FIRST],
                          np.cumsum(listed)[:-1].astype(np.int32))
