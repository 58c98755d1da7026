"""The camera's orientation checks and its focus, model and texture names re-pointed when a
scene is saved in another folder, and the benchmark scenes' own checks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from whitted.errors import SceneError
from whitted.scene import Camera, ImageTexture, Material, Mesh, Scene
from whitted.scene.writing import rebase_files


@pytest.mark.parametrize(("fields", "message"), [
    ({"look_at": (0, 0, 0), "rotate": (0, 10, 0)},
     "Camera: give either look_at or rotate/axis_angle, not both"),
    ({"position": (0, 5, 0), "look_at": (0, 0, 0)},
     "Camera: up is parallel to the viewing direction"),
    ({"focal_distance": 2, "focal_point": (0, 0, 0)},
     "Camera: give either focal_distance or focal_point, not both"),
    ({"focal_point": (0, 0, 10)}, "Camera: focal_point is not in front of the camera"),
])
def test_camera_checks(fields, message):
    with pytest.raises(SceneError) as info:
        Camera(**fields)
    assert str(info.value) == message


def test_focus_and_turned_cameras():
    # the plane through the focal point facing the camera: 4 along -z from z = 5
    assert Camera(position=(0, 0, 5), focal_point=(3, 1, 1)).focus() == 4.0
    assert Camera(position=(0, 0, 5), look_at=(0, 0, 2)).focus() == 3.0
    assert Camera(position=(0, 0, 5), rotate=(0, 90, 0)).focus() == 1.0  # nothing to focus on
    # a quarter turn about y, by angles or by axis and angle: looking down -x
    for cam in (Camera(rotate=(0, 90, 0)),
                Camera(axis_angle={"axis": [0, 1, 0], "angle": 90})):
        right, up, forward = cam.basis()
        np.testing.assert_allclose(forward, [-1, 0, 0], atol=1e-12)
        np.testing.assert_allclose(right, [0, 0, -1], atol=1e-12)
        np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)


def test_files_re_pointed_from_another_folder(tmp_path):
    home = tmp_path / "a" / "b"
    scene = Scene(
        materials={"wood": Material(texture=ImageTexture(file="tex/wood.png")),
                   "plain": Material()},
        objects=[Mesh(file="m.obj"), Mesh(file="/abs/m.obj")],
    ).with_base_dir(home)
    near = rebase_files(scene, tmp_path / "a" / "c")
    assert near.base_dir == (tmp_path / "a" / "c").resolve()
    assert near.materials["wood"].texture.file == "../b/tex/wood.png"
    assert [o.file for o in near.objects] == ["../b/m.obj", "/abs/m.obj"]
    assert near.materials["plain"] == Material()
    # three levels up or more: the name is made absolute instead
    far = rebase_files(scene, tmp_path / "a" / "x" / "y" / "z")
    assert far.objects[0].file == str((home / "m.obj").resolve())
    same = rebase_files(scene, home)
    assert same.objects[0].file == "m.obj" and same.base_dir == home.resolve()


def test_benchmark_scene_checks(tmp_path):
    from whitted.bench.scenes import SCENES, load_bench_scene, pick_scenes, with_absolute_files

    assert SCENES["mesh1m"].meshes and SCENES["sphere1m"].meshes
    assert not SCENES["seed000"].meshes
    with pytest.raises(SceneError) as info:
        pick_scenes(["seed000", "nonesuch"])
    assert str(info.value).startswith("unknown benchmark scene 'nonesuch' (known: seed000, ")
    with pytest.raises(SceneError) as info:
        load_bench_scene("lecture", folder=tmp_path)
    assert str(info.value) == (f"{tmp_path / 'lecture.toml'}: no such benchmark scene file "
                               "(whitted's benchmark scenes are not installed here)")
    scene = Scene(materials={"w": Material(texture=ImageTexture(file="w.png"))},
                  objects=[Mesh(file="m.obj", material=Material(
                      texture=ImageTexture(file="t.png")))]).with_base_dir(tmp_path)
    out = with_absolute_files(scene)
    assert out.objects[0].file == str(tmp_path / "m.obj")
    assert out.objects[0].material.texture.file == str(tmp_path / "t.png")
    assert out.materials["w"].texture.file == str(tmp_path / "w.png")


def test_benchmarks_folder_outside_a_checkout(monkeypatch, tmp_path):
    from whitted.bench import scenes
    from whitted.files import shipped

    # neither an installed package's nor a checkout's benchmarks/ above this source
    monkeypatch.setattr(shipped, "__file__", str(tmp_path / "x" / "shipped.py"))
    monkeypatch.chdir(tmp_path)
    assert scenes.benchmarks_dir() == Path(tmp_path) / "benchmarks"
