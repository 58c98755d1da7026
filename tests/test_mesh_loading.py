"""Model-file loading (whitted.assets): the shared OBJ corpus, the strict OBJ policy, MTL
materials, the trimesh formats and the cache."""

from __future__ import annotations

import math
import re
import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from whitted.assets import MeshData, clear_mesh_cache, load_mesh
from whitted.assets.mesh import load_obj_bytes
from whitted.assets.mtl import parse_texture_map
from whitted.errors import SceneError
from whitted.scene.textures import ImageTexture

CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "obj"
needs_corpus = pytest.mark.skipif(
    not (CORPUS / "MANIFEST.md").is_file(),
    reason=f"the shared OBJ corpus is not at {CORPUS} (clone the repository next to shared/)",
)


# ---------------------------------------------------------------------------------------------
# The shared corpus, row by row from its MANIFEST


def _manifest_rows() -> list[tuple[str, str]]:
    manifest = CORPUS / "MANIFEST.md"
    if not manifest.is_file():
        return []
    rows = []
    for line in manifest.read_text(encoding="utf-8").splitlines():
        match = re.match(r"^\|\s*`([^`]+)`\s*\|", line)
        if not match:
            continue
        expected = line.rstrip().rstrip("|").rsplit(" | ", 1)[-1].strip()
        rows.append((match.group(1), expected))
    return rows


def _number(text: str) -> int:
    return int(text.replace(",", ""))


MANIFEST_ROWS = _manifest_rows()


@needs_corpus
def test_manifest_lists_the_corpus():
    assert len(MANIFEST_ROWS) >= 40
    assert sum(expected.startswith("loads:") for _, expected in MANIFEST_ROWS) >= 20
    assert sum(expected.startswith("should fail") for _, expected in MANIFEST_ROWS) >= 5


@needs_corpus
@pytest.mark.parametrize(
    ("file", "expected"), MANIFEST_ROWS or [("(no corpus)", "n/a")],
    ids=[file for file, _ in MANIFEST_ROWS] or ["no-corpus"],
)
def test_manifest_row(file: str, expected: str):
    path = CORPUS / file
    if expected.startswith("loads:"):
        match = re.match(r"loads: ([\d,]+) vertices?, ([\d,]+) triangles?", expected)
        assert match, f"cannot read the expected counts of {file}: {expected}"
        mesh = load_mesh(path)
        assert mesh.vertex_records == _number(match.group(1))
        assert mesh.triangle_records == _number(match.group(2))
        assert mesh.faces.shape == (mesh.triangle_records, 3)
        assert mesh.face_material.shape == (mesh.triangle_records,)
        assert len(mesh.vertices) >= mesh.vertex_records
        if len(mesh.faces):
            assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
            assert mesh.face_material.max() < len(mesh.materials)
        assert np.all(np.isfinite(mesh.vertices))
    elif expected.startswith("should fail"):
        with pytest.raises(SceneError) as caught:
            load_mesh(path)
        error = caught.value
        assert error.file == str(path)
        line = re.search(r"\blines? (\d+)", expected)
        if line:
            assert error.line == int(line.group(1)), str(error)
        assert str(error).startswith(f"{path}:")
        assert "\n" not in str(error)
    else:
        pytest.skip(f"support file: {expected}")


# ---------------------------------------------------------------------------------------------
# Corpus files with more to check


@needs_corpus
def test_corpus_error_messages():
    def message(file: str) -> str:
        with pytest.raises(SceneError) as caught:
            load_mesh(CORPUS / file)
        return str(caught.value)

    assert message("tinyobjloader/issue-140-zero-face-idx.obj").endswith(
        ":16: vertex index 0 (OBJ indices are 1-based) in '0/0/0'")
    assert message("assimp/invalid/malformed.obj").endswith(
        ":23: vertex index 12 out of range (8 defined so far) in '12'")
    assert message("assimp/number_formats.obj").endswith(":11: invalid number '3.1+e2' in vertex "
                                                         "position")
    assert message("trimesh/notenoughindices.obj").endswith(
        ":9: face has 2 corners, needs at least 3")
    assert message("tinyobjloader/invalid-relative-vertex-index.obj").endswith(
        ":1: vertex index -4 out of range (0 defined so far) in '-4'")
    assert message("tinyobjloader/smoothing-group-two-squares.obj").endswith(
        ":21: normal index 1 out of range (0 defined so far) in '1//1'")
    assert "not finite" in message("tinyobjloader/test-nan.obj")


@needs_corpus
def test_teapot_has_unit_per_vertex_normals():
    mesh = load_mesh(CORPUS / "pytorch3d/teapot.obj")
    assert mesh.normals is not None and mesh.normals.shape == mesh.vertices.shape
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1.0)
    assert mesh.uvs is None
    # the file's positions come first, in file order, bit for bit
    text = (CORPUS / "pytorch3d/teapot.obj").read_text()
    written = np.array([[float(x) for x in line.split()[1:4]]
                        for line in text.splitlines() if line.startswith("v ")])
    assert np.array_equal(mesh.vertices[: len(written)], written)


@needs_corpus
def test_cow_has_uvs_and_its_texture():
    mesh = load_mesh(CORPUS / "pytorch3d/cow_mesh/cow.obj")
    assert mesh.uvs is not None and mesh.uvs.shape == (len(mesh.vertices), 2)
    assert len(mesh.vertices) > mesh.vertex_records  # split at the uv seams
    assert np.all(np.abs(mesh.uvs - 0.5) < 0.6)  # the file's values, a few just outside 0..1
    assert [Path(f).name for f in mesh.texture_files] == ["cow_texture.png"]
    assert Path(mesh.texture_files[0]).is_absolute()
    (material,) = mesh.materials
    assert isinstance(material.texture, ImageTexture)
    assert material.texture.file == mesh.texture_files[0]
    assert material.color == (1.0, 1.0, 1.0)
    assert mesh.warnings == []


@needs_corpus
def test_split_vertices_keep_their_positions_bit_for_bit():
    mesh = load_mesh(CORPUS / "assimp/cube_with_vertexcolors.obj")
    assert mesh.vertex_records == 8 and len(mesh.vertices) == 24
    originals = {tuple(v) for v in mesh.vertices[:8].tolist()}
    assert {tuple(v) for v in mesh.vertices[8:].tolist()} <= originals


@needs_corpus
def test_cornell_box_negative_indices_and_materials():
    mesh = load_mesh(CORPUS / "mcguire-cornell-box/CornellBox-Original.obj")
    assert mesh.faces[:2].tolist() == [[0, 1, 2], [0, 2, 3]]  # floor: f -4 -3 -2 -1
    assert len(mesh.materials) == 8
    assert mesh.warnings == []
    left_wall = mesh.materials[mesh.face_material[-6]]
    colours = {m.color for m in mesh.materials}
    assert (0.63, 0.065, 0.05) in colours
    assert left_wall.shininess == 10.0


@needs_corpus
def test_missing_library_and_texture_are_warnings():
    model2 = load_mesh(CORPUS / "pytorch3d/missing_files_obj/model2.obj")
    assert any(w.endswith("model2.obj:2: material library 'model2.mtl' not found (default "
                          "material used)") for w in model2.warnings)
    assert any("model2.obj:8: material 'material_1' is not defined" in w
               for w in model2.warnings)
    model = load_mesh(CORPUS / "pytorch3d/missing_files_obj/model.obj")
    assert any(re.search(r"model\.mtl:\d+: texture image 'material_1\.png' not found", w)
               for w in model.warnings)
    assert model.texture_files == [] and model.materials[0].texture is None
    for warning in model.warnings + model2.warnings:
        assert "\n" not in warning


@needs_corpus
def test_mtl_names_with_spaces_escapes_and_latin1():
    spaces = load_mesh(CORPUS / "assimp/box_mat_with_spaces.obj")
    assert spaces.warnings == []
    assert spaces.materials[0].color == (0.2, 0.2, 0.2)
    escaped = load_mesh(CORPUS / "tinyobjloader/mtl filename with whitespace issue46.obj")
    assert not any("'green'" in w for w in escaped.warnings)
    assert escaped.materials[0].color == (0.0, 1.0, 0.0)


@needs_corpus
def test_utf16_corpus_file():
    mesh = load_mesh(CORPUS / "assimp/box_UTF16BE.obj")
    assert (mesh.vertex_records, mesh.triangle_records) == (8, 12)


# ---------------------------------------------------------------------------------------------
# The OBJ reader on files written here


def _load_text(text: str, tmp_path: Path, name: str = "model.obj") -> MeshData:
    path = tmp_path / name
    path.write_text(text)
    return load_mesh(path)


def _error(text: str | bytes, tmp_path: Path) -> SceneError:
    path = tmp_path / "bad.obj"
    if isinstance(text, str):
        path.write_text(text)
    else:
        path.write_bytes(text)
    with pytest.raises(SceneError) as caught:
        load_mesh(path)
    return caught.value


def test_negative_indices_count_back_from_records_so_far(tmp_path):
    mesh = _load_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\n"
        "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf -4 -3 -2 -1\nf 1 -1 2\n",
        tmp_path,
    )
    assert mesh.faces.tolist() == [[0, 1, 2], [3, 4, 5], [3, 5, 6], [0, 6, 1]]


def test_polygons_become_fans_in_file_order(tmp_path):
    mesh = _load_text(
        "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\nf 5 4 3\nf 2 3 4 5\n",
        tmp_path,
    )
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4], [4, 3, 2], [1, 2, 3],
                                   [1, 3, 4]]
    assert mesh.triangle_records == 6 and mesh.faces.dtype == np.int32
    assert mesh.vertices.dtype == np.float64 and mesh.face_material.dtype == np.int32


def test_degenerate_polygons_are_kept(tmp_path):
    mesh = _load_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2 3 1\n", tmp_path)
    assert mesh.faces.tolist() == [[0, 1, 1], [0, 1, 2], [0, 2, 0]]


def test_corner_forms_and_per_corner_attributes(tmp_path):
    mesh = _load_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
        "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1 0.5\nvn 0 0 2\nvn 0 0 -1\n"
        "f 1/1/1 2/2/1 3/3/1\nf 2/2/2 4/4/2 3/3/2\n",
        tmp_path,
    )
    # vertices 2 and 3 (1-based) are used with two normals: one copy each, appended
    assert len(mesh.vertices) == 6
    assert mesh.faces.tolist() == [[0, 1, 2], [4, 3, 5]]
    assert np.array_equal(mesh.vertices[4], mesh.vertices[1])
    assert np.array_equal(mesh.vertices[5], mesh.vertices[2])
    assert mesh.normals.tolist()[:3] == [[0, 0, 1]] * 3  # normalised
    assert mesh.normals.tolist()[3:] == [[0, 0, -1]] * 3
    assert mesh.uvs.tolist() == [[0, 0], [1, 0], [0, 1], [1, 1], [1, 0], [0, 1]]


def test_trailing_slashes_comments_continuations_and_crlf(tmp_path):
    text = ("# header\r\nv 0 0 0 # a comment\r\nv\t1 0 0\r\nv 0 1 \\\r\n 0\r\n"
            "vt 0 0\r\nvt 1 0\r\nvt 0 1\r\nf 1/1/ 2/2/ 3/3/\r\ng group\r\ns off\r\no thing\r\n"
            "vw 1 2 3\r\nf 1// 2// 3// # done")
    mesh = _load_text(text, tmp_path)
    assert mesh.vertex_records == 3 and mesh.triangle_records == 2
    assert mesh.vertices[:3].tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    # the second face has no texture coordinates: its corners are copies with uv (0, 0)
    assert mesh.faces.tolist() == [[0, 1, 2], [3, 4, 5]]
    assert mesh.uvs[3:].tolist() == [[0, 0]] * 3
    assert any("some faces have texture coordinates and some not" in w for w in mesh.warnings)


def test_vertex_colours_and_w_are_not_positions(tmp_path):
    mesh = _load_text("v 1 2 3 0.5 0.6 0.7\nv 4 5 6 1.0\nv 7 8 9\nf 1 2 3\n", tmp_path)
    assert mesh.vertices.tolist() == [[1, 2, 3], [4, 5, 6], [7, 8, 9]]


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "face has 2 corners, needs at least 3"),
        ("v 0 0 0\nf\n", 2, "face has 0 corners, needs at least 3"),
        ("v 0 0\n", 1, "'v' has 2 values, needs at least 3"),
        ("vn 0 1\n", 1, "'vn' has 2 values, needs at least 3"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 4\n", 4,
         "vertex index 4 out of range (3 defined so far) in '4'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1/1 2/1 3/1\n", 4,
         "texture coordinate index 1 out of range (0 defined so far) in '1/1'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nvn 0 0 1\nf 1//1 2//-2 3//1\n", 5,
         "normal index -2 out of range (1 defined so far) in '2//-2'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 0\n", 4,
         "vertex index 0 (OBJ indices are 1-based) in '0'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3x\n", 4, "invalid face corner '3x'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 /3\n", 4, "face corner '/3' has no vertex index"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3/1/1/1\n", 4, "invalid face corner '3/1/1/1'"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 99999999999999999999\n", 4,
         "vertex index huge out of range"),
        ("v 1 2 3\nv 1.#IND 0 0\n", 2, "invalid number '1.#IND' in vertex position"),
        ("v 1 2 3\nv 1 inf 0\n", 2, "vertex position value 'inf' is not finite"),
        ("v 1 2 -NaN\n", 1, "vertex position value '-NaN' is not finite"),
        ("v 1 2 1e400\n", 1, "vertex position value '1e400' is not finite"),
        ("v 1 2 1.7976931348623159e308\n", 1, "is not finite"),
        ("v 1 2 3\nvt 0.5 x\n", 2, "invalid number 'x' in texture coordinate"),
        ("v 1 2 3\nvn 1 0 1e\n", 2, "invalid number '1e' in normal"),
        ("v 1 2 3\nv 1 2 3.1-e2\n", 2, "invalid number '3.1-e2'"),
        ("v 1 2 3\nv 1 2 1,5\n", 2, "invalid number '1,5'"),
        ("v 1 2 3\nv 1 2 0x10\n", 2, "invalid number '0x10'"),
        ("v 1 2 3\n\x00\x01binary\n", 2, "binary data (byte 0x00)"),
        ("# ok\nusemtl a\x07b\n", 2, "binary data (byte 0x07)"),
        ("v 0 0 \\\n0\nv 1 0 0\nv 1 x 0\n", 4, "invalid number 'x'"),
        ("v 0 0 0\rv 1 0 0\r\rv 1 x 0\r", 4, "invalid number 'x'"),
        ("v 0 0 0\r\nv 1 0 0\r\nf 1 2 3 # two\r\n", 3, "vertex index 3 out of range"),
    ],
)
def test_obj_errors(tmp_path, text, line, message):
    error = _error(text, tmp_path)
    assert error.line == line
    assert message in error.message, error.message
    assert str(error).startswith(f"{tmp_path / 'bad.obj'}:{line}: ")


def test_huge_normals_are_normalised(tmp_path):
    mesh = _load_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1e300 1e300 0\nvn 0 0 0\n"
                      "f 1//1 2//1 3//2\n", tmp_path)
    assert np.allclose(mesh.normals[:2], [[0.5**0.5, 0.5**0.5, 0]] * 2)
    assert mesh.normals[2].tolist() == [0, 0, 0]  # the file's zero normal stays zero


def test_binary_garbage_is_an_error(tmp_path):
    rng = np.random.default_rng(7)
    garbage = bytes(rng.integers(0, 256, 4096, dtype=np.uint8))
    error = _error(garbage, tmp_path)
    assert error.line is not None
    png_header = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(64)
    assert "binary data" in _error(png_header, tmp_path).message


def test_utf16_with_bom_and_utf8_bom(tmp_path):
    text = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n"
    for encoding, name in (("utf-16", "le.obj"), ("utf-16-be", "be.obj"), ("utf-8-sig", "u8.obj")):
        data = text.encode(encoding)
        if encoding == "utf-16-be":
            data = b"\xfe\xff" + data
        (tmp_path / name).write_bytes(data)
        mesh = load_mesh(tmp_path / name)
        assert (mesh.vertex_records, mesh.triangle_records) == (3, 1)
    # UTF-16 without a BOM is not text to this reader: a clear error, not an empty mesh
    assert "binary data" in _error(text.encode("utf-16-le"), tmp_path).message


def test_empty_and_line_only_files(tmp_path):
    empty = _load_text("# nothing\n", tmp_path, "empty.obj")
    assert empty.faces.shape == (0, 3) and empty.vertices.shape == (0, 3)
    assert len(empty.materials) == 1 and empty.face_material.shape == (0,)
    lines = _load_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\np 1\n", tmp_path, "lines.obj")
    assert (lines.vertex_records, lines.triangle_records) == (3, 0)
    blank = _load_text("", tmp_path, "blank.obj")
    assert blank.triangle_records == 0


def test_missing_file_and_unknown_format(tmp_path):
    with pytest.raises(SceneError, match="no such file"):
        load_mesh(tmp_path / "absent.obj")
    (tmp_path / "model.xyz").write_text("hello")
    with pytest.raises(SceneError, match=r"unsupported model format '\.xyz' \(supported: \.obj, "
                                         r"\.ply, \.stl, \.off, \.gltf, \.glb\)"):
        load_mesh(tmp_path / "model.xyz")
    with pytest.raises(SceneError, match="is a directory, not a regular file"):
        load_mesh(tmp_path)


# ---------------------------------------------------------------------------------------------
# MTL


@pytest.mark.parametrize(
    ("arguments", "file", "options"),
    [
        ("-clamp on ambient.jpg", "ambient.jpg", {"-clamp": ["on"]}),
        ("-o 0.1 diffuse.jpg", "diffuse.jpg", {"-o": ["0.1"]}),
        ("-s 0.1 0.2 specular.jpg", "specular.jpg", {"-s": ["0.1", "0.2"]}),
        ("-t 0.1 0.2 0.3 specular_highlight.jpg", "specular_highlight.jpg",
         {"-t": ["0.1", "0.2", "0.3"]}),
        ("-bm 3 bumpmap.jpg", "bumpmap.jpg", {"-bm": ["3"]}),
        ("-blendu on diffuse.jpg", "diffuse.jpg", {"-blendu": ["on"]}),
        ("-mm 0.1 0.3 specular_highlight.jpg", "specular_highlight.jpg", {"-mm": ["0.1", "0.3"]}),
        ("-imfchan r bumpmap2.jpg -bm 1.5", "bumpmap2.jpg", {"-imfchan": ["r"], "-bm": ["1.5"]}),
        ("-type cube_top specular.jpg", "specular.jpg", {"-type": ["cube_top"]}),
        ("my\\ texture.png", "my texture.png", {}),
        ("textures/wood grain.png -s 2 2", "textures/wood grain.png", {"-s": ["2", "2"]}),
    ],
)
def test_texture_map_options(arguments, file, options):
    texture_map = parse_texture_map(arguments)
    assert texture_map is not None
    assert texture_map.file == file
    assert texture_map.options == options


@needs_corpus
def test_texture_options_corpus_file_warns_only():
    mesh = load_mesh(CORPUS / "tinyobjloader/texture-options-issue-85.obj")
    assert (mesh.vertex_records, mesh.triangle_records) == (3, 1)
    assert any("texture image 'diffuse.jpg' not found" in w for w in mesh.warnings)


def _write_png(path: Path) -> None:
    from PIL import Image

    Image.new("RGB", (4, 4), (200, 100, 50)).save(path)


def test_mtl_to_material(tmp_path):
    (tmp_path / "tex").mkdir()
    _write_png(tmp_path / "tex" / "wood.png")
    (tmp_path / "scene.mtl").write_text(
        "newmtl plain\nKd 0.5 0.25 2.0 # clipped\nKa 0 0 0\nKs 0.5 0.25 0\nNs 250000\n"
        "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.9 0.9 0.9\nillum 3\n"
        "newmtl glass\nKd 1 1 1\nKs 0.5 0.5 0.5\nTf 0.9 0.8 0.9\nNi 1.52\nillum 7\nKe 1 1 1\n"
        "newmtl faded\nKd 0.8 0.8 0.8\nd 0.25\n"
        "newmtl faded_tr\nTr 0.5\n"
        "newmtl textured\nmap_Kd -s 4 2 -o 0.5 0.25 -clamp on tex/wood.png\n"
        "newmtl missing\nKd 0.3 0.3 0.3\nmap_Kd -bm 2 nowhere.png\n"
    )
    faces = "".join(f"usemtl {name}\nf 1 2 3\n" for name in
                    ("plain", "mirror", "glass", "faded", "faded_tr", "textured", "missing",
                     "nothing"))
    mesh = _load_text("mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n" + faces, tmp_path)
    plain, mirror, glass, faded, faded_tr, textured, missing, nothing = (
        mesh.materials[i] for i in mesh.face_material)
    assert plain.color == (0.5, 0.25, 1.0) and plain.ambient_color is None
    assert plain.ks == 0.5 and plain.specular_color == (1.0, 0.5, 0.0)
    assert plain.shininess == 100000.0 and plain.kt == 0.0 and not plain.fresnel
    assert mirror.kr == pytest.approx(0.9) and mirror.kt == 0.0
    assert glass.fresnel and glass.ior == pytest.approx(1.52)
    assert glass.kt == pytest.approx(0.9) and glass.kr == pytest.approx(0.5)
    assert faded.kt == pytest.approx(0.75) and faded_tr.kt == pytest.approx(0.5)
    assert isinstance(textured.texture, ImageTexture)
    assert textured.texture.file == str((tmp_path / "tex" / "wood.png").resolve())
    assert textured.texture.scale == (4.0, 2.0) and textured.texture.offset == (0.5, 0.25)
    assert textured.texture.wrap == "clamp" and textured.color == (1.0, 1.0, 1.0)
    assert mesh.texture_files == [textured.texture.file]
    assert missing.texture is None and missing.color == (0.3, 0.3, 0.3)
    assert nothing.color == (0.8, 0.8, 0.8)
    assert any("texture image 'nowhere.png' not found" in w for w in mesh.warnings)
    assert any(":19: material 'nothing' is not defined" in w for w in mesh.warnings)
    assert not any("Ke" in w for w in mesh.warnings)


def test_mtllib_with_several_names_and_latin1(tmp_path):
    (tmp_path / "b lib.mtl").write_bytes(b"newmtl caf\xe9\nKd 0.1 0.2 0.3\nnewmtl red\nKd 1 0 0\n")
    mesh = _load_text("mtllib a.mtl b\\ lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\n"
                      "f 1 2 3\n", tmp_path)
    assert mesh.materials[0].color == (1.0, 0.0, 0.0)
    assert any("material library 'a.mtl' not found" in w for w in mesh.warnings)
    spaced = _load_text("mtllib b lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
                        tmp_path, "spaced.obj")
    assert spaced.warnings == [] and spaced.materials[0].color == (1.0, 0.0, 0.0)


def test_faces_before_and_between_materials(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n")
    mesh = _load_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl a\nf 1 2 3\n"
                      "usemtl b\nusemtl a\nf 1 2 3 1\nusemtl b\nf 1 2 3\n", tmp_path)
    colours = [mesh.materials[i].color for i in mesh.face_material]
    assert colours == [(0.8, 0.8, 0.8), (1, 0, 0), (1, 0, 0), (1, 0, 0), (0, 1, 0)]
    assert len(mesh.materials) == 3


# ---------------------------------------------------------------------------------------------
# Cache


def test_cache_returns_the_same_object_and_reads_once(tmp_path, monkeypatch):
    path = tmp_path / "cached.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    clear_mesh_cache()
    reads = []
    from whitted import files

    original = files.map_limited

    def counting_read(file_path, *args, **kwargs):
        reads.append(file_path)
        return original(file_path, *args, **kwargs)

    monkeypatch.setattr(files, "map_limited", counting_read)
    first = load_mesh(path)
    assert load_mesh(str(path)) is first
    assert load_mesh(tmp_path / "." / "cached.obj") is first
    assert reads == [path]
    assert not first.vertices.flags.writeable and not first.faces.flags.writeable
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n")
    second = load_mesh(path)
    assert second is not first and second.triangle_records == 2


# ---------------------------------------------------------------------------------------------
# Formats through trimesh


def test_ply_stl_and_off_written_by_trimesh(tmp_path):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=1)
    for suffix, vertices in ((".ply", 42), (".stl", 240), (".off", 42)):
        path = tmp_path / f"sphere{suffix}"
        sphere.export(path)
        mesh = load_mesh(path)
        assert (mesh.vertex_records, mesh.triangle_records) == (vertices, 80)
        assert mesh.faces.dtype == np.int32 and mesh.vertices.dtype == np.float64
        assert len(mesh.materials) == 1 and mesh.face_material.tolist() == [0] * 80
        assert mesh.normals is None
        assert np.allclose(np.linalg.norm(mesh.vertices, axis=1), 1.0)


def test_ply_with_normals_keeps_them(tmp_path):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=1)
    normals = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1)[:, None]
    with_normals = trimesh.Trimesh(sphere.vertices, sphere.faces, vertex_normals=normals,
                                   process=False)
    path = tmp_path / "normals.ply"
    path.write_bytes(trimesh.exchange.ply.export_ply(with_normals, vertex_normal=True))
    mesh = load_mesh(path)
    assert mesh.normals is not None and np.allclose(mesh.normals, normals)


def test_glb_scene_applies_transforms(tmp_path):
    import trimesh

    box = trimesh.creation.box()
    scene = trimesh.Scene()
    scene.add_geometry(box, node_name="a")
    moved = np.eye(4)
    moved[:3, 3] = (10, 0, 0)
    scene.add_geometry(box, node_name="b", transform=moved)
    path = tmp_path / "boxes.glb"
    path.write_bytes(scene.export(file_type="glb"))
    mesh = load_mesh(path)
    assert mesh.triangle_records == 24
    assert mesh.vertices[:, 0].max() == pytest.approx(10.5)
    assert len(mesh.materials) == 2


def test_glb_embedded_texture_becomes_an_image_file(tmp_path, monkeypatch):
    import trimesh
    from PIL import Image

    monkeypatch.setenv("WHITTED_CACHE_DIR", str(tmp_path / "cache"))
    box = trimesh.creation.box()
    uv = np.random.default_rng(0).random((len(box.vertices), 2))
    material = trimesh.visual.material.PBRMaterial(
        name="red", baseColorTexture=Image.new("RGB", (8, 8), (255, 0, 0)),
        baseColorFactor=[255, 255, 255, 255])
    box.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    path = tmp_path / "textured.glb"
    path.write_bytes(trimesh.Scene(box).export(file_type="glb"))
    mesh = load_mesh(path)
    assert mesh.uvs is not None and mesh.warnings == []
    (texture_file,) = mesh.texture_files
    assert Path(texture_file).parent == tmp_path / "cache" / "textures"
    assert Image.open(texture_file).getpixel((3, 3)) == (255, 0, 0)
    assert mesh.materials[0].texture.file == texture_file


def test_broken_ply_is_a_scene_error(tmp_path):
    path = tmp_path / "broken.ply"
    path.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 10\n" + bytes(7))
    with pytest.raises(SceneError):
        load_mesh(path)


# ---------------------------------------------------------------------------------------------
# Generated meshes (hypothesis)


@st.composite
def obj_meshes(draw):
    vertex_count = draw(st.integers(3, 12))
    coordinates = draw(st.lists(
        st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False, width=64),
        min_size=3 * vertex_count, max_size=3 * vertex_count))
    polygons = draw(st.lists(
        st.lists(st.integers(0, vertex_count - 1), min_size=3, max_size=7), min_size=0,
        max_size=10))
    negative = draw(st.lists(st.booleans(), min_size=len(polygons), max_size=len(polygons)))
    return vertex_count, coordinates, polygons, negative


def _obj_text(vertex_count, coordinates, polygons, negative):
    lines = [f"v {coordinates[3 * k]!r} {coordinates[3 * k + 1]!r} {coordinates[3 * k + 2]!r}"
             for k in range(vertex_count)]
    for polygon, relative in zip(polygons, negative, strict=True):
        corners = [str(k - vertex_count) if relative else str(k + 1) for k in polygon]
        lines.append("f " + " ".join(corners))
    return "\n".join(lines) + "\n", len(lines)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(obj_meshes())
def test_generated_meshes_round_trip(mesh_parts):
    vertex_count, coordinates, polygons, negative = mesh_parts
    text, _ = _obj_text(*mesh_parts)
    mesh = load_obj_bytes(text.encode(), "generated.obj", Path("."))
    assert mesh.vertex_records == vertex_count
    assert mesh.vertices.tolist() == np.array(coordinates).reshape(-1, 3).tolist()
    expected = [[p[0], p[i], p[i + 1]] for p in polygons for i in range(1, len(p) - 1)]
    assert mesh.triangle_records == len(expected)
    assert mesh.faces.tolist() == expected


@settings(max_examples=60, deadline=None)
@given(obj_meshes(), st.data())
def test_one_corrupted_index_names_its_line(mesh_parts, data):
    vertex_count, coordinates, polygons, negative = mesh_parts
    if not polygons:
        polygons = [[0, 1, 2]]
        negative = [False]
    text, _ = _obj_text(vertex_count, coordinates, polygons, negative)
    lines = text.splitlines()
    face = data.draw(st.integers(0, len(polygons) - 1))
    line_index = vertex_count + face
    corners = lines[line_index].split()[1:]
    corner = data.draw(st.integers(0, len(corners) - 1))
    bad = data.draw(st.sampled_from(
        ["0", str(vertex_count + 1), str(vertex_count + 1000), str(-vertex_count - 1)]))
    corners[corner] = bad
    lines[line_index] = "f " + " ".join(corners)
    with pytest.raises(SceneError) as caught:
        load_obj_bytes(("\n".join(lines) + "\n").encode(), "corrupt.obj", Path("."))
    assert caught.value.line == line_index + 1
    assert f"'{bad}'" in caught.value.message


_NUMBER_FORMATS = ("{!r}", "{:.17g}", "{:.6f}", "{:e}", "{:.3E}", "{:.20e}", "{:.9g}")


@settings(max_examples=150, deadline=None)
@given(st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=3,
                max_size=3), st.sampled_from(_NUMBER_FORMATS))
def test_numbers_parse_exactly_like_float(values, number_format):
    tokens = [number_format.format(v) for v in values]
    written = [float(t) for t in tokens]
    if not all(math.isfinite(w) for w in written):
        return
    mesh = load_obj_bytes(("v " + " ".join(tokens) + "\n").encode(), "n.obj", Path("."))
    parsed = mesh.vertices[0].tolist()
    assert [struct.pack("<d", p) for p in parsed] == [struct.pack("<d", w) for w in written]


@pytest.mark.parametrize("token", ["2.", "+1", ".5", "-.7e+2", "1e2", "2.e01", "1E-2", "-0",
                                   "0.000000000000000000000000123456789", "123456789012345678901",
                                   "4.9406564584124654e-324", "2.2250738585072014e-308",
                                   "1.7976931348623157e308", "0.1", "9007199254740993"])
def test_number_syntax(token):
    mesh = load_obj_bytes(f"v {token} 0 0\n".encode(), "n.obj", Path("."))
    assert struct.pack("<d", mesh.vertices[0, 0]) == struct.pack("<d", float(token))
