"""assets/trimesh_formats.py: PLY, STL, OFF and glTF files refused from their first bytes when
they are not what their extension says, their problems in words, glTF materials with base
colours and texture files next to the model (URIs percent-encoded, as glTF writes them),
nodes that move, scale and rotate normals, and meshes whose parts differ in what they have."""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np
import pytest

from whitted.assets import clear_mesh_cache, load_mesh
from whitted.assets import trimesh_formats as tf
from whitted.errors import SceneError

PLY_HEAD = (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            b"property float z\n")
PLY_FACES = b"element face 1\nproperty list uchar int vertex_indices\n"


@pytest.fixture(autouse=True)
def _fresh_cache():
    clear_mesh_cache()
    yield
    clear_mesh_cache()


def _gltf(path: Path, parts: list[dict], image_uri: str = "wood%20grain.png") -> None:
    """A glTF file of one triangle per part (a node each), its buffer inline. A part says
    whether it has ``uvs`` and ``normals`` and where its node puts it (``node``)."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32).tobytes()
    idx = np.array([0, 1, 2, 0], np.uint16).tobytes()  # padded to 4 bytes
    uv = np.array([[0, 0], [1, 0], [0, 1]], np.float32).tobytes()
    nrm = np.array([[0, 0, 2]] * 3, np.float32).tobytes()
    blob = pos + idx + uv + nrm
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
             {"buffer": 0, "byteOffset": 36, "byteLength": 6},
             {"buffer": 0, "byteOffset": 44, "byteLength": 24},
             {"buffer": 0, "byteOffset": 68, "byteLength": 36}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 0]},
                 {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
                 {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
                 {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC3"}]
    meshes, nodes = [], []
    for k, part in enumerate(parts):
        attributes = {"POSITION": 0}
        if part.get("uvs"):
            attributes["TEXCOORD_0"] = 2
        if part.get("normals"):
            attributes["NORMAL"] = 3
        meshes.append({"primitives": [{"attributes": attributes, "indices": 1,
                                       "material": 0}]})
        nodes.append({"mesh": k, **part.get("node", {})})
    doc = {"asset": {"version": "2.0"}, "scene": 0,
           "scenes": [{"nodes": list(range(len(parts)))}], "nodes": nodes, "meshes": meshes,
           "materials": [{"name": "wood", "pbrMetallicRoughness": {
               "baseColorFactor": [0.2, 0.4, 1.0, 1.0], "baseColorTexture": {"index": 0}}}],
           "textures": [{"source": 0}], "images": [{"uri": image_uri}],
           "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;"
                        "base64," + base64.b64encode(blob).decode()}],
           "bufferViews": views, "accessors": accessors}
    path.write_text(json.dumps(doc), encoding="utf-8")


def _wood(folder: Path) -> Path:
    from PIL import Image

    image = folder / "wood grain.png"
    Image.new("RGB", (4, 4), (0, 255, 0)).save(image)
    return image


def test_a_gltf_texture_file_with_a_percent_encoded_name(tmp_path):
    """glTF writes URIs percent-encoded: ``wood%20grain.png`` is the file ``wood grain.png``
    (trimesh does not decode it and read no image: the texture was lost, without a word)."""
    image = _wood(tmp_path)
    path = tmp_path / "tri.gltf"
    _gltf(path, [{"uvs": True, "node": {"translation": [0, 0, 5]}}])
    mesh = load_mesh(path)
    assert mesh.vertices.tolist() == [[0, 0, 5], [1, 0, 5], [0, 1, 5]]
    assert mesh.uvs.tolist() == [[0, 1], [1, 1], [0, 0]]  # glTF's v runs down the image
    (material,) = mesh.materials
    assert material.texture is not None and material.texture.file == str(image)
    # trimesh keeps the base colour as 8-bit: 0.2 -> 51/255
    assert material.color == pytest.approx((51 / 255, 102 / 255, 1.0))
    assert mesh.texture_files == [str(image)] and mesh.warnings == []


def test_a_texture_on_a_mesh_without_uvs_is_a_warning(tmp_path):
    _wood(tmp_path)
    path = tmp_path / "tri.gltf"
    _gltf(path, [{"uvs": False}])
    mesh = load_mesh(path)
    assert mesh.materials[0].texture is None and mesh.uvs is None
    assert mesh.warnings == [f"{path}: material 'wood' has a texture but the mesh has no "
                             "texture coordinates (base colour used)"]


def test_nodes_scale_and_rotate_normals_and_parts_without_them(tmp_path):
    _wood(tmp_path)
    path = tmp_path / "two.gltf"
    quarter = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # 90 degrees about z
    _gltf(path, [{"uvs": True, "normals": True,
                  "node": {"scale": [2, 2, 2], "rotation": quarter}},
                 {"uvs": False, "normals": False, "node": {"translation": [3, 0, 0]}}])
    mesh = load_mesh(path)
    assert mesh.faces.tolist() == [[0, 1, 2], [3, 4, 5]]
    assert mesh.face_material.tolist() == [0, 1]
    # in scene-graph order (trimesh's): find the turned part by its place
    turned = 0 if mesh.vertices[:3, 0].min() < 0 else 1
    moved = 1 - turned
    np.testing.assert_allclose(mesh.vertices[3 * turned:3 * turned + 3],
                               [[0, 0, 0], [0, 2, 0], [-2, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(mesh.vertices[3 * moved:3 * moved + 3],
                               [[3, 0, 0], [4, 0, 0], [3, 1, 0]], atol=1e-12)
    # normals on one part only are not used; uvs on one part: zeros for the other
    assert mesh.normals is None
    assert mesh.warnings == [
        f"{path}: material 'wood' has a texture but the mesh has no texture coordinates "
        "(base colour used)", f"{path}: only some geometries have normals: normals not used"]
    assert mesh.materials[turned].texture is not None and mesh.materials[moved].texture is None
    assert mesh.uvs[3 * turned:3 * turned + 3].tolist() == [[0, 1], [1, 1], [0, 0]]
    assert mesh.uvs[3 * moved:3 * moved + 3].tolist() == [[0, 0]] * 3
    clear_mesh_cache()
    _gltf(path, [{"normals": True, "node": {"scale": [2, 2, 2], "rotation": quarter}}])
    mesh = load_mesh(path)
    # (0, 0, 2) turned about z and made unit length
    np.testing.assert_allclose(mesh.normals, [[0, 0, 1]] * 3, atol=1e-12)


def test_an_embedded_texture_that_cannot_be_stored_is_a_warning(tmp_path, monkeypatch):
    import trimesh
    from PIL import Image

    box = trimesh.creation.box()
    material = trimesh.visual.material.PBRMaterial(
        name="red", baseColorTexture=Image.new("RGB", (8, 8), (255, 0, 0)))
    box.visual = trimesh.visual.TextureVisuals(uv=np.zeros((len(box.vertices), 2)),
                                               material=material)
    path = tmp_path / "textured.glb"
    path.write_bytes(trimesh.Scene(box).export(file_type="glb"))
    blocker = tmp_path / "a file"
    blocker.write_text("")
    monkeypatch.setattr(tf, "cache_root", lambda: blocker)  # textures/ under a file
    mesh = load_mesh(path)
    assert mesh.materials[0].texture is None
    assert mesh.warnings == [f"{path}: material 'red': its texture image cannot be stored "
                             "(base colour used)"]


def test_colours_in_any_range():
    assert tf._linear_colour(None) is None
    assert tf._linear_colour([1.0, 0.5]) is None  # too few
    assert tf._linear_colour([np.nan, 0.0, 0.0]) is None
    assert tf._linear_colour(np.array([255, 51, 0], np.uint8)) == (1.0, 0.2, 0.0)
    assert tf._linear_colour([510.0, 25.5, 0.0, 1.0]) == (1.0, 0.1, 0.0)  # above 1: 8-bit
    assert tf._linear_colour([0.5, -1.0, 0.25]) == (0.5, 0.0, 0.25)


@pytest.mark.parametrize(("name", "data"), [
    ("bad.ply", b"hello"), ("bad.stl", b"hello world"), ("bad.off", b"XYZ 1 2"),
    ("bad.glb", b"nope"), ("bad.gltf", b"nope"), ("empty.off", b""),
])
def test_a_file_that_is_not_its_format_is_refused_from_its_first_bytes(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    kind = name.split(".")[1].upper()
    with pytest.raises(SceneError) as info:
        load_mesh(path)
    assert str(info.value) == (f"{path}: not a {kind} file (its first bytes are not a "
                               f"{kind} header)")


def test_headers_that_pass():
    ok = {"m.ply": b"ply\r\nformat", "m.off": b"\xef\xbb\xbf  COFF\n", "m.stl": b"SOLID x",
          "m.glb": b"glTF\x02\x00", "m.gltf": b'  {"asset": {}}'}
    for name, head in ok.items():
        path = Path(name)
        try:
            path.write_bytes(head)
            tf.check_header(path, name)  # no error
        finally:
            path.unlink()


def test_a_binary_stl_is_known_by_its_size(tmp_path):
    path = tmp_path / "one.stl"
    triangle = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", 1) + triangle)
    mesh = load_mesh(path)
    assert mesh.triangle_records == 1 and mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0],
                                                                       [0, 1, 0]]
    path.write_bytes(b"\0" * 80 + struct.pack("<I", 2) + triangle)  # one triangle short
    with pytest.raises(SceneError, match="not a STL file"):
        load_mesh(path)


def test_bad_data_in_words(tmp_path):
    def refused(name: str, data: bytes) -> str:
        path = tmp_path / name
        path.write_bytes(data)
        with pytest.raises(SceneError) as info:
            load_mesh(path)
        return str(info.value)[len(str(path)) + 2:]

    assert refused("nan.ply", PLY_HEAD + PLY_FACES + b"end_header\n0 0 0\nnan 0 0\n0 1 0\n"
                   b"3 0 1 2\n") == "vertex position is not finite (nan or inf)"
    assert refused("range.ply", PLY_HEAD + PLY_FACES + b"end_header\n0 0 0\n1 0 0\n0 1 0\n"
                   b"3 0 1 5\n") == "face index out of range (3 vertices)"
    assert refused("short.off", b"OFF\n3 1 0\n0 0 0\n1 0\n").startswith(
        "cannot read the OFF file: malformed or truncated data (")


def test_a_file_of_points_has_no_triangles(tmp_path):
    path = tmp_path / "points.ply"
    path.write_bytes(PLY_HEAD + b"end_header\n0 0 0\n1 0 0\n0 1 0\n")
    mesh = load_mesh(path)
    assert mesh.vertices.shape == (0, 3) and mesh.faces.shape == (0, 3)
    assert len(mesh.materials) == 1 and mesh.face_material.tolist() == []


def test_problems_in_words():
    import struct as st

    assert tf._detail(UnicodeDecodeError("utf-8", b"\xff", 0, 1, "bad")) == \
        "the text is not UTF-8"
    assert tf._detail(KeyError("vertex")) == "missing element or property 'vertex'"
    assert tf._detail(KeyError()) == "incomplete"
    assert tf._detail(ValueError("bad   value\n here")) == \
        "malformed or truncated data (bad value here)"
    assert tf._detail(st.error("")) == "malformed data"
    assert tf._detail(MemoryError()) == "too large to load"
    assert tf._detail(RuntimeError("the  end")) == "the end"
    assert tf._detail(RuntimeError()) == "RuntimeError"


def test_unreadable_gltf_documents_name_no_texture_files(tmp_path):
    path = tmp_path / "x.gltf"
    path.write_text("{not json", encoding="utf-8")
    assert tf._external_base_colour_images(path) == {}
    path.write_text(json.dumps({"materials": [
        {"name": "a", "pbrMetallicRoughness": {"baseColorTexture": {"index": 3}}}],
        "textures": []}), encoding="utf-8")
    assert tf._external_base_colour_images(path) == {}
    (tmp_path / "b.png").write_bytes(b"")
    path.write_text(json.dumps({
        "materials": [{"name": "a", "pbrMetallicRoughness": {}},
                      {"name": "b", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
                      {"name": "c", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}},
                      {"name": "d", "pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}, {"source": 1}, {}],
        "images": [{"uri": "b.png"}, {"uri": "data:image/png;base64,AAAA"}]}),
        encoding="utf-8")
    assert tf._external_base_colour_images(path) == {"b": tmp_path / "b.png"}
    assert tf._external_base_colour_images(tmp_path / "x.glb") == {}
