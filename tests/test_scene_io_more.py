"""scene/io.py: a JSON scene that is not an object, a byte-order mark before TOML, and a
model file name that cannot be resolved (``~user`` of no such user), each one line naming the
file, the line and the key."""

from __future__ import annotations

import pytest

import whitted
from whitted.errors import SceneError


def test_a_json_scene_must_be_an_object(tmp_path):
    path = tmp_path / "s.json"
    path.write_text("[1, 2]")
    with pytest.raises(SceneError) as info:
        whitted.load_scene(path)
    assert str(info.value) == f"{path}: the top level must be an object"


def test_a_byte_order_mark_is_skipped(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_text("\ufeff[camera]\nfov = 30\n", encoding="utf-8")
    assert whitted.load_scene(path).camera.fov == 30.0


def test_a_model_name_that_cannot_be_resolved(tmp_path):
    path = tmp_path / "user.toml"
    path.write_text('[[objects]]\ntype = "mesh"\nfile = "~no_such_user_cov2/m.obj"\n')
    with pytest.raises(SceneError) as info:
        whitted.load_scene(path)
    assert str(info.value) == (
        f"{path}:3: objects[0].file: unusable file name (Could not determine home "
        "directory.): '~no_such_user_cov2/m.obj' (looked in ~no_such_user_cov2)")
