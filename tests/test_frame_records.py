"""animation/frames.py: the frame hash covers inline mesh arrays and notices a model file
appearing; the frame record of a path that is not a regular file is empty (it was None, and
asking it for the hash raised AttributeError: a frames folder holding a folder or a pipe
named like a frame broke the film)."""

from __future__ import annotations

import os

from whitted.animation.frames import (
    frame_digest,
    frame_is_current,
    is_whitted_frame,
    model_files,
    read_frame_digest,
)
from whitted.scene import Mesh, Scene


def _mesh_scene(z: float) -> Scene:
    return Scene(objects=[Mesh(vertices=[[0, 0, z], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]])])


def test_the_hash_covers_inline_arrays_and_files(tmp_path):
    assert frame_digest(_mesh_scene(0.0), 0) == frame_digest(_mesh_scene(0.0), 0)
    assert frame_digest(_mesh_scene(0.0), 0) != frame_digest(_mesh_scene(0.5), 0)
    scene = Scene(objects=[Mesh(file="m.obj")]).with_base_dir(tmp_path)
    missing = frame_digest(scene, 0)
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert frame_digest(scene, 0) != missing  # the model appeared
    assert model_files(tmp_path / "m.obj") == []
    (tmp_path / "bad.obj").write_text("v 0 0\n")
    assert model_files(tmp_path / "bad.obj") == []  # unreadable: the render says so


def test_paths_that_are_not_frame_files(tmp_path):
    os.mkfifo(tmp_path / "pipe.png")
    (tmp_path / "folder.png").mkdir()
    for path in (tmp_path / "pipe.png", tmp_path / "folder.png", tmp_path / "none.png"):
        assert read_frame_digest(path) is None
        assert not frame_is_current(path, "abc")
        assert not is_whitted_frame(path)
    (tmp_path / "plain.png").write_bytes(b"not a png")
    assert read_frame_digest(tmp_path / "plain.png") is None
