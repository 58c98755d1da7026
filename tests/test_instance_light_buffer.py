"""Light buffers in scenes with mesh instances: a point light's cell lists, after its analytic
primitives, the leaves of the instance BVH (as ``-1 - node``) whose boxes meet the cell's cone
(compile/light_buffers.py). Every instance a shadow ray through the cell can reach must be
listed, and the image must be the one the walk of both BVHs gives."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import whitted
from meshgen import uv_sphere
from one_lane import render_one_lane
from whitted.compile.light_buffers import build_light_buffers
from whitted.compile.scene import compile_scene
from whitted.kernels.layout import (
    CELL_COUNT,
    CELL_FIRST,
    CELL_OPAQUE,
    LIGHT_BUFFER,
    LIGHT_BUFFER_SIDE,
)
from whitted.kernels.light_buffer import cube_cell

EPS = 1e-6


def _ball(centre, radius=1.0, material=None):
    verts, faces = uv_sphere(8, 12)
    return whitted.Mesh(vertices=verts * radius + np.asarray(centre), faces=faces,
                        material=material)


def _listed(compiled, direction, light=0):
    """(analytic primitives, instance primitives) the cell of ``direction`` from the light
    lists, or None when the cell overflowed."""
    lights, geo = compiled.lights, compiled.geometry
    side = int(lights.table[light, LIGHT_BUFFER_SIDE])
    cell = lights.buffer_cells[int(lights.table[light, LIGHT_BUFFER]) + cube_cell(direction,
                                                                                   side)]
    if cell[CELL_COUNT] < 0:
        return None
    analytic, instances = set(), set()
    for e in lights.buffer_prims[cell[CELL_FIRST] : cell[CELL_FIRST] + cell[CELL_COUNT]]:
        if e >= 0:
            analytic.add(int(e))
            continue
        node = -1 - int(e)
        assert geo.inst_link[node, 1] > 0  # a leaf
        first = geo.inst_link[node, 0]
        instances |= {int(i) for i in geo.inst_prims[first : first + geo.inst_link[node, 1]]}
    return analytic, instances


def test_a_cell_lists_the_instances_in_its_cone_and_only_those():
    """A light at (0, 10, 0) over a ball at (0, 5, 0) and one at (6, 0, 0): straight down the
    cell lists the first (and the ground plane), toward (6, -10, 0) the second, upward
    nothing; the cell of a direction clear of both (the cone misses their boxes) neither."""
    scene = whitted.Scene(
        objects=[whitted.Plane(point=(0, -2, 0), normal=(0, 1, 0)),
                 _ball((0, 5, 0)), _ball((6, 0, 0))],
        lights=[whitted.PointLight(position=(0, 10, 0))])
    compiled = compile_scene(scene, flatten_limit=0)
    geo = compiled.geometry
    plane, upper, lower = 0, 1, 2
    assert sorted(geo.inst_prims.tolist()) == [upper, lower]
    assert compiled.lights.table[0, LIGHT_BUFFER] == 0
    assert _listed(compiled, (0.0, -1.0, 0.0)) == ({plane}, {upper})
    assert _listed(compiled, (6.0, -10.0, 0.0)) == ({plane}, {lower})
    assert _listed(compiled, (0.1, 1.0, 0.2)) == (set(), set())
    assert _listed(compiled, (5.0, -10.0, -5.0)) == ({plane}, set())
    # a cell listing an instance is never taken for opaque-only (its triangles are tested
    # through the instance, not as analytic primitives)
    side = int(compiled.lights.table[0, LIGHT_BUFFER_SIDE])
    assert compiled.lights.buffer_cells[cube_cell((0.0, -1.0, 0.0), side), CELL_OPAQUE] == 0
    assert compiled.lights.buffer_cells[cube_cell((5.0, -10.0, -5.0), side), CELL_OPAQUE] == 1


def _segment_meets_box(p, q, lo, hi):
    d = q - p
    t0, t1 = 0.0, 1.0
    for k in range(3):
        if d[k] == 0.0:
            if not lo[k] <= p[k] <= hi[k]:
                return False
            continue
        a, b = (lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k]
        t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
    return t0 <= t1


def _grid_scene(light_position=(-3.0, 7.0, 2.0), clear=False):
    objects = [whitted.Plane(point=(0, -1, 0), normal=(0, 1, 0))]
    for k in range(16):
        x, z = -4.5 + 3.0 * (k % 4), -4.5 + 3.0 * (k // 4)
        material = "glass" if clear and k % 3 == 0 else None
        objects.append(_ball((x, 0.3 * (k % 3), z), 0.8 + 0.1 * (k % 4), material))
    return whitted.Scene(objects=objects, lights=[whitted.PointLight(position=light_position)],
                         materials={"glass": whitted.Material(preset="glass")})


@pytest.mark.parametrize("light_position", [(-3.0, 7.0, 2.0), (0.0, 0.4, 0.0)])
def test_every_instance_a_shadow_segment_meets_is_listed(light_position):
    """16 instances on a grid, the light above them or down among them: for 3,000 shaded
    points (on the floor, among the balls, far beyond them), every instance whose world box
    the segment from the point to the light meets is in the list of the point's cell, and
    most cells list a few, not all."""
    compiled = compile_scene(_grid_scene(light_position), flatten_limit=0)
    geo, lights = compiled.geometry, compiled.lights
    assert len(geo.inst_prims) == 16 and lights.table[0, LIGHT_BUFFER] == 0
    light = lights.table[0, 4:7].copy()
    rng = np.random.default_rng(3)
    points = rng.uniform((-7, -1, -7), (7, 2.5, 7), (3000, 3))
    points[:800, 1] = -1.0
    points[800:1000] = rng.uniform((-60, -1, -60), (60, -1, 60), (200, 3))
    sizes = []
    for p in points:
        listed = _listed(compiled, tuple(p - light))
        if listed is None:  # the cell overflowed: its rays walk the BVHs
            continue
        sizes.append(len(listed[1]))
        for i in geo.inst_prims:
            if _segment_meets_box(p, light, compiled.prim_lo[i], compiled.prim_hi[i]):
                assert int(i) in listed[1], (p, i)
    assert len(sizes) > 2900 and np.median(sizes) <= 3 and max(sizes) < 16


def test_an_instance_scene_renders_the_same_with_and_without_its_light_buffer():
    """Opaque and glass instances, a ground plane, the light among the balls' heights and
    above them: the image through the cells' lists is the walk's, bit for bit, in both
    Embree's tracer and whitted's own mesh walk."""
    for tracer in ("embree", "whitted"):
        scene = _grid_scene((-2.0, 4.0, 1.0), clear=True).model_copy(update={
            "render": whitted.RenderSettings(width=64, height=48, mesh_tracer=tracer),
            "camera": whitted.Camera(position=(0, 9, 12), look_at=(0, 0, 0), fov=55)})
        compiled = compile_scene(scene, flatten_limit=0)
        assert compiled.lights.table[0, LIGHT_BUFFER] == 0
        listed = render_one_lane(compiled, scene)
        table = compiled.lights.table.copy()
        table[:, LIGHT_BUFFER] = -1.0
        walked = render_one_lane(dataclasses.replace(
            compiled, lights=compiled.lights._replace(table=table)), scene)
        assert np.array_equal(listed, walked)
        # lists of at most two entries: many cells overflow, and their rays walk
        short = build_light_buffers(compiled.geometry, compiled.materials,
                                    compiled.lights.table, cap=2)
        assert (short.buffer_cells[:, CELL_COUNT] < 0).any()
        assert (short.buffer_cells[:, CELL_COUNT] > 0).any()
        assert np.array_equal(listed, render_one_lane(dataclasses.replace(compiled, lights=short),
                                              scene))
        assert listed.mean() > 0.05
        # shadows are there: the floor under the balls is darker than the floor in the open
        assert (listed.sum(axis=2) < 0.5 * listed.sum(axis=2).max()).mean() > 0.01
