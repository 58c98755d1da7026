"""Work reused between frames gives exactly the images of fresh compiles."""

from __future__ import annotations

import numpy as np

import whitted
from whitted.animation import Track
from whitted.animation.reuse import CompileCache, ReuseStats
from whitted.compile.reuse import BvhMemo
from whitted.compile.scene import compile_scene
from whitted.render.api import RenderJob

SCENE = """\
[render]
width = 32
height = 24

[camera]
position = [0, 1.5, 6]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
name = "ball"
type = "sphere"
center = [-1, 0.5, 0]
radius = 0.5
material = { color = [0.9, 0.2, 0.1], kr = 0.2 }

[[objects]]
name = "tetra"
type = "mesh"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
transform = { translate = [0.5, 0, 0] }

[[objects]]
type = "plane"
"""


def _scene(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE)
    scene = whitted.load_scene(path)
    return scene.with_animation(3, tracks=[
        Track("camera.position", {0: [0, 1.5, 6], 2: [2, 1.5, 5]}),
        Track("lights[0].position", {0: [3, 5, 4], 2: [-3, 5, 4]}),
        Track("objects[ball].center", {0: [-1, 0.5, 0], 1: [-1, 0.5, 0], 2: [-1.5, 0.5, 0]}),
    ])


def _pixels(still, compiled=None) -> np.ndarray:
    return RenderJob(still, threads=1, compiled=compiled).run().pixels


def test_each_level_of_reuse_renders_what_a_fresh_compile_renders(tmp_path):
    scene = _scene(tmp_path)
    cache = CompileCache()
    levels = []
    for k in range(3):
        still = scene.at_frame(k)
        compiled, level = cache.compile(still)
        levels.append(level)
        assert np.array_equal(_pixels(still, compiled), _pixels(still)), k
    # frame 1: camera and light moved (geometry reused); frame 2: the ball moved too
    assert levels[0] == "none" and levels[1] == "geometry" and levels[2] in ("bvh", "none")
    camera_only = scene.at_frame(0).model_copy(update={"camera": scene.at_frame(2).camera})
    again, level = cache.compile(scene.at_frame(2))
    assert level == "all"
    moved, level = cache.compile(camera_only)
    assert level in ("bvh", "none")
    assert np.array_equal(_pixels(camera_only, moved), _pixels(camera_only))
    dimmer = camera_only.model_copy(update={"lights": [
        camera_only.lights[0].model_copy(update={"intensity": 0.4, "color": (1, 0.5, 0.2)})]})
    kept, level = cache.compile(dimmer)
    assert level == "light buffers"
    assert kept.lights.buffer_cells is moved.lights.buffer_cells
    assert np.array_equal(_pixels(dimmer, kept), _pixels(dimmer))
    assert not np.array_equal(_pixels(dimmer), _pixels(camera_only))


def test_a_mesh_keeps_its_bvh_when_another_object_moves(tmp_path):
    scene = _scene(tmp_path)
    # flatten_limit 0: the mesh is stored with its own BVH (whitted's: tests/test_embree.py
    # has the memo keeping Embree's)
    with BvhMemo() as memo:
        first = compile_scene(scene.at_frame(1), flatten_limit=0, mesh_tracer="whitted")
        assert memo.built == 3 and memo.reused == 0  # scene, instances, the mesh
        second = compile_scene(scene.at_frame(2), flatten_limit=0, mesh_tracer="whitted")
    assert memo.reused == 2 and memo.built == 4  # the mesh's and the instance BVH kept
    fresh = compile_scene(scene.at_frame(2), flatten_limit=0, mesh_tracer="whitted")
    for name in fresh.geometry._fields:
        assert np.array_equal(getattr(second.geometry, name), getattr(fresh.geometry, name)), name
    assert not np.array_equal(first.geometry.node_box, second.geometry.node_box)


def test_the_reuse_summary_says_in_words_what_each_frame_reused():
    stats = ReuseStats(frames={"all": 11, "none": 1, "geometry": 2}, bvh_built=2,
                       bvh_reused=22, primitives_built=30, primitives_reused=90,
                       compile_seconds=0.1234)
    assert stats.summary() == (
        "scene compiles: 1 compiled in full, 2 kept the geometry (new lights), 11 reused the "
        "frame before's whole; BVHs: 22 of 24 reused (75% of their primitives); 0.123 s")
    assert ReuseStats().summary() == (
        "scene compiles: none; BVHs: 0 of 0 reused (100% of their primitives); 0.000 s")
