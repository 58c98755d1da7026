"""assets/mesh.py: OBJ text that cannot be read (UTF-16 cut short, long and Latin-1 tokens
shown in the error), material libraries named with Windows separators or twice, a library
too large to read, and a material whose texture placement cannot be used."""

from __future__ import annotations

import codecs

import pytest

from whitted.assets import clear_mesh_cache, load_mesh
from whitted.errors import SceneError

TRIANGLE = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"


@pytest.fixture(autouse=True)
def _fresh():
    clear_mesh_cache()
    yield
    clear_mesh_cache()


@pytest.mark.parametrize(("data", "problem"), [
    (codecs.BOM_UTF16_LE + b"v\x00 \x00\x00\xd8", "invalid UTF-16 text (unexpected end of data)"),
    (b"v 0 0 " + b"x" * 100 + b"\n", "1: invalid number '" + "x" * 60 + "...' in vertex position"),
    (b"v 0 0 \xe9\xe9\n", "1: invalid number '\u00e9\u00e9' in vertex position"),
])
def test_text_that_cannot_be_read(tmp_path, data, problem):
    path = tmp_path / "m.obj"
    path.write_bytes(data)
    with pytest.raises(SceneError) as info:
        load_mesh(path)
    sep = ":" if problem[0].isdigit() else ": "
    assert str(info.value) == f"{path}{sep}{problem}"


def test_libraries_named_twice_too_large_or_with_unusable_materials(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "lib.mtl").write_text(
        "newmtl a\nKd 1 0 0\nnewmtl z\nmap_Kd -s 0 0 tex.png\n")
    (tmp_path / "sub" / "tex.png").write_bytes(b"")
    with open(tmp_path / "big.mtl", "wb") as f:
        f.truncate(65 << 20)  # sparse: over the 64 MiB a library may have
    (tmp_path / "m.obj").write_bytes(b"mtllib sub\\lib.mtl sub/lib.mtl big.mtl\n" + TRIANGLE
                                     + b"usemtl a\nf 1 2 3\nusemtl z\nf 1 2 3\n")
    mesh = load_mesh(tmp_path / "m.obj")
    assert mesh.warnings == [
        f"{tmp_path / 'big.mtl'}: material library too large: 65.0 MiB (the limit is "
        "64.0 MiB)",
        f"{tmp_path / 'm.obj'}:1: material library 'big.mtl' cannot be read",
        f"{tmp_path / 'sub' / 'lib.mtl'}:3: material 'z' cannot be used (ImageTexture.scale: "
        "scale must not be zero (the texture would be one colour)); default material used",
    ]
    # the library named twice (once with a backslash) is read once
    assert mesh.library_files == [str(tmp_path / "sub" / "lib.mtl"), str(tmp_path / "big.mtl")]
    assert mesh.face_material.tolist() == [0, 1]
    assert mesh.materials[0].color == (1.0, 0.0, 0.0)
    assert mesh.materials[1].texture is None and mesh.materials[1].color == (0.8, 0.8, 0.8)
