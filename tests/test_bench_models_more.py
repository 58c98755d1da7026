"""bench/models.py and bench/embree.py pieces: the coursework's cones, the bunny's source,
generated model names, the world triangles Embree is given, and the two refusals of the
Embree comparison (no embreex, no point light)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from whitted.bench import models
from whitted.bench.models import (
    CONE_SEGMENTS,
    MissingSourceModel,
    bunny_mesh,
    bunny_source,
    cone_mesh,
    generated_model,
    write_cones,
)


def test_cones_closed_outward_and_written(tmp_path):
    vertices, faces = cone_mesh(8)
    assert len(vertices) == 10 and len(faces) == 16
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).tolist()
    directed = set(map(tuple, edges))
    assert len(directed) == 48 and all((b, a) in directed for a, b in directed)  # closed
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    # outward; an octagon of radius 1 (area 2·sqrt 2) under an apex of height 1
    assert volume == pytest.approx(2 * np.sqrt(2) / 3)
    paths = write_cones(tmp_path)
    from whitted.assets import load_mesh

    assert [p.name for p in paths] == [f"cone_{n}.obj" for n in sorted(set(CONE_SEGMENTS))]
    assert [len(load_mesh(p).faces) for p in paths] == [2 * n for n in sorted(set(
        CONE_SEGMENTS))]


def test_the_bunnys_source(monkeypatch, tmp_path):
    monkeypatch.setenv("WHITTED_BUNNY_OBJ", str(tmp_path / "none.obj"))
    assert bunny_source() is None
    (tmp_path / "bunny.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    monkeypatch.setenv("WHITTED_BUNNY_OBJ", str(tmp_path / "bunny.obj"))
    assert bunny_source() == tmp_path / "bunny.obj"
    vertices, faces = bunny_mesh(1)  # one subdivision: 4 triangles
    assert len(faces) == 4 and len(vertices) == 6
    monkeypatch.setattr(models, "bunny_source", lambda: None)
    with pytest.raises(MissingSourceModel) as info:
        bunny_mesh()
    assert str(info.value) == ("the Stanford bunny is not on this machine: set "
                               "WHITTED_BUNNY_OBJ to stanford-bunny.obj")


def test_generated_model_names(tmp_path):
    with pytest.raises(KeyError) as info:
        generated_model("teapot.obj", tmp_path)
    assert info.value.args[0].startswith("no generated model 'teapot.obj' (known: bubble.obj, ")
    path = generated_model("height_field_1m.ply", tmp_path, quick=True)
    assert path == tmp_path / "quick-height_field_1m.ply"
    stamp = path.stat().st_mtime_ns
    assert generated_model("height_field_1m.ply", tmp_path, quick=True) == path
    assert path.stat().st_mtime_ns == stamp  # there already: not written again
    bubble = generated_model("bubble.obj", tmp_path, quick=True)  # no small version
    assert bubble == tmp_path / "bubble.obj" and bubble.read_text().startswith("# air bubble")


def test_world_triangles_of_meshes_and_planes():
    from whitted.bench.embree import PLANE_HALF_SIZE, world_triangles
    from whitted.scene import Mesh, Plane, Scene, Sphere, Transform

    scene = Scene(objects=[
        Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
             transform=Transform(scale=2, translate=(0, 0, 5))),
        Plane(point=(0, -1, 0)), Sphere(radius=1)])
    tris = world_triangles(scene)
    assert tris.shape == (3, 3, 3) and tris.dtype == np.float32
    np.testing.assert_array_equal(tris[0], [[0, 0, 5], [2, 0, 5], [0, 2, 5]])
    assert (tris[1:, :, 1] == -1).all()  # the plane's two, at y = -1
    assert np.abs(tris[1:, :, [0, 2]]).max() == PLANE_HALF_SIZE
    assert world_triangles(Scene(objects=[Sphere(radius=1)])).shape == (0, 3, 3)


def test_the_embree_comparison_refuses_early(monkeypatch):
    from whitted.bench.embree import EmbreeMissing, compare_embree, embree_available
    from whitted.scene import Scene

    monkeypatch.setitem(sys.modules, "embreex", None)
    monkeypatch.setitem(sys.modules, "embreex.rtcore_scene", None)
    assert embree_available() is False
    with pytest.raises(EmbreeMissing) as info:
        compare_embree(Scene())
    assert str(info.value) == "--compare embree needs embreex: pip install 'whitted[bench]'"


def test_the_embree_comparison_needs_a_point_light():
    pytest.importorskip("embreex")
    from whitted.bench.embree import compare_embree
    from whitted.scene import Scene

    with pytest.raises(ValueError, match="^the scene has no point light to cast shadow rays "
                                         "toward$"):
        compare_embree(Scene())
