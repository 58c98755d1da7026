"""PLY, STL, OFF and glTF/GLB files through trimesh, with nothing merged or repaired.

Every geometry of the file's scene is placed by its node transform and the results are
concatenated in scene-graph order; each geometry gets one material from its PBR base colour (or
its simple diffuse colour). A base-colour texture becomes an :class:`ImageTexture` when it is an
image file next to a ``.gltf`` (matched through the material's name); an image embedded in the
file is written once, as PNG named by its content hash, to ``textures/`` in whitted's cache folder
(``$WHITTED_CACHE_DIR``, default ``~/.cache/whitted``) so that it has a file to name. A texture
without texture coordinates is a warning (the base colour is used).
"""

from __future__ import annotations

import hashlib
import io
import json
import logging
import os
import tempfile
import warnings as python_warnings
from pathlib import Path
from struct import error as struct_error

import numpy as np

from ..errors import SceneError
from ..jit.cache import cache_root
from ..scene.materials import Material
from ..scene.textures import ImageTexture
from .mesh_data import MeshData


def _external_base_colour_images(path: Path) -> dict[str, Path]:
    """Material name -> base colour image file, for a .gltf whose images are files."""
    if path.suffix.lower() != ".gltf":
        return {}
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
        images = document.get("images", [])
        textures = document.get("textures", [])
        found: dict[str, Path] = {}
        for material in document.get("materials", []):
            info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture")
            if not info:
                continue
            source = textures[info["index"]].get("source")
            uri = images[source].get("uri", "") if source is not None else ""
            if uri and not uri.startswith("data:"):
                from urllib.parse import unquote

                image_path = path.parent / unquote(uri)
                if image_path.is_file() and material.get("name"):
                    found[material["name"]] = image_path.resolve()
        return found
    except (OSError, ValueError, KeyError, IndexError, TypeError, AttributeError):
        return {}


def _embedded_image_file(image: object) -> Path | None:
    """A PNG file holding an image trimesh decoded from the model (None if it cannot be made)."""
    try:
        buffer = io.BytesIO()
        image.save(buffer, format="PNG")  # type: ignore[attr-defined]
        data = buffer.getvalue()
        folder = cache_root() / "textures"
        path = folder / f"{hashlib.sha256(data).hexdigest()[:32]}.png"
        if not path.is_file():
            folder.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(dir=folder, suffix=".part")
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
            os.replace(temporary, path)
        return path
    except (OSError, ValueError, AttributeError):
        return None


def _linear_colour(values: object) -> tuple[float, float, float] | None:
    if values is None:
        return None
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    if array.size < 3 or not np.all(np.isfinite(array[:3])):
        return None
    if np.asarray(values).dtype == np.uint8 or array[:3].max() > 1.0:
        array = array / 255.0
    r, g, b = (float(min(max(v, 0.0), 1.0)) for v in array[:3])
    return (r, g, b)


def _material_of(geometry: object, images: dict[str, Path], name: str, warnings: list[str],
                 texture_files: list[str], has_uvs: bool) -> Material:
    visual = getattr(geometry, "visual", None)
    material = getattr(visual, "material", None)
    if material is None:
        return Material()
    fields: dict[str, object] = {}
    colour = _linear_colour(getattr(material, "baseColorFactor", None))
    if colour is None:
        colour = _linear_colour(getattr(material, "diffuse", None))
    if colour is not None:
        fields["color"] = colour
    image = getattr(material, "baseColorTexture", None)
    if image is None:
        image = getattr(material, "image", None)
    label = getattr(material, "name", None) or ""
    # an image file next to a .gltf counts also when trimesh could not read it (it does
    # not decode the URI: "wood%20grain.png" names "wood grain.png")
    if image is not None or label in images:
        image_path = images.get(label) or _embedded_image_file(image)
        if image_path is None:
            warnings.append(f"{name}: material '{label}': its texture image cannot be stored "
                            "(base colour used)")
        elif not has_uvs:
            warnings.append(f"{name}: material '{label}' has a texture but the mesh has no "
                            "texture coordinates (base colour used)")
        else:
            fields["texture"] = ImageTexture(file=str(image_path))
            if str(image_path) not in texture_files:
                texture_files.append(str(image_path))
    return Material.model_validate(fields)


#: Largest PLY/STL/OFF/glTF file read (trimesh holds the whole file and more in memory).
MAX_TRIMESH_BYTES = 2 << 30


def check_header(path: Path, name: str) -> None:
    """Refuse at once, from its first bytes, a file that is not of the format its extension
    says (before trimesh reads all of it)."""
    from ..files import head_bytes

    suffix = path.suffix.lower()
    kind = suffix[1:].upper()
    head = head_bytes(path, 4096, MAX_TRIMESH_BYTES, f"{kind} file", name)
    size = path.stat().st_size
    text = head.lstrip(b"\xef\xbb\xbf").lstrip()
    ok = True
    if suffix == ".ply":
        ok = head.startswith(b"ply") and head[3:4] in (b"\n", b"\r")
    elif suffix == ".stl":
        binary = size >= 84 and 84 + 50 * int.from_bytes(head[80:84], "little") == size
        ok = binary or text[:5].lower() == b"solid"
    elif suffix == ".off":
        first = text.split(None, 1)[0] if text.split(None, 1) else b""
        ok = first.upper().endswith(b"OFF") and len(first) <= 8
    elif suffix == ".glb":
        ok = head[:4] == b"glTF"
    elif suffix == ".gltf":
        ok = text[:1] == b"{"
    if not ok:
        raise SceneError(f"not a {kind} file (its first bytes are not a {kind} header)",
                         file=name)


def _detail(error: BaseException) -> str:
    """A bad file's problem in words, not the reader library's internals."""
    if isinstance(error, ImportError | UnicodeDecodeError):
        return "the text is not UTF-8"
    if isinstance(error, KeyError):
        return f"missing element or property {error.args[0]!r}" if error.args else "incomplete"
    if isinstance(error, IndexError | ValueError | TypeError | AttributeError | struct_error):
        text = " ".join(str(error).split())
        return f"malformed or truncated data ({text[:80]})" if text else "malformed data"
    if isinstance(error, MemoryError):
        return "too large to load"
    text = " ".join(str(error).split())
    return text[:120] if text else type(error).__name__


def load_with_trimesh(path: Path, name: str) -> MeshData:
    """A MeshData for a PLY, STL, OFF or glTF/GLB file."""
    import trimesh

    check_header(path, name)
    logging.getLogger("trimesh").setLevel(logging.ERROR)
    try:
        with python_warnings.catch_warnings():
            python_warnings.simplefilter("ignore")
            with np.errstate(all="ignore"):
                scene = trimesh.load_scene(os.fspath(path), process=False)
    except Exception as error:  # noqa: BLE001 - trimesh raises many kinds for a bad file
        raise SceneError(f"cannot read the {path.suffix.lower()[1:].upper()} file: "
                         f"{_detail(error)}", file=name) from None
    images = _external_base_colour_images(path)
    warnings: list[str] = []
    texture_files: list[str] = []
    vertex_blocks: list[np.ndarray] = []
    face_blocks: list[np.ndarray] = []
    normal_blocks: list[np.ndarray | None] = []
    uv_blocks: list[np.ndarray | None] = []
    material_blocks: list[np.ndarray] = []
    materials: list[Material] = []
    offset = 0
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        geometry = scene.geometry.get(geometry_name)
        if not isinstance(geometry, trimesh.Trimesh):
            continue  # point clouds and paths have no triangles
        vertices = np.asarray(geometry.vertices, dtype=np.float64)
        faces = np.asarray(geometry.faces, dtype=np.int64).reshape(-1, 3)
        transform = np.asarray(transform, dtype=np.float64)
        identity = np.array_equal(transform, np.eye(4))
        if not identity:
            vertices = vertices @ transform[:3, :3].T + transform[:3, 3]
        normals = None
        if "vertex_normals" in geometry._cache:
            normals = np.asarray(geometry.vertex_normals, dtype=np.float64)
            if not identity:
                normals = normals @ np.linalg.inv(transform[:3, :3])
            lengths = np.linalg.norm(normals, axis=1)
            lengths[lengths == 0.0] = 1.0
            normals = normals / lengths[:, None]
        uv = getattr(geometry.visual, "uv", None)
        uvs = None
        if uv is not None and len(uv) == len(vertices):
            uvs = np.asarray(uv, dtype=np.float64)[:, :2]
        materials.append(_material_of(geometry, images, name, warnings, texture_files,
                                      uvs is not None))
        vertex_blocks.append(vertices)
        face_blocks.append(faces + offset)
        normal_blocks.append(normals)
        uv_blocks.append(uvs)
        material_blocks.append(np.full(len(faces), len(materials) - 1, np.int32))
        offset += len(vertices)
    if not vertex_blocks:
        vertices = np.zeros((0, 3), np.float64)
        faces = np.zeros((0, 3), np.int64)
        materials = [Material()]
        face_material = np.zeros(0, np.int32)
    else:
        vertices = np.concatenate(vertex_blocks)
        faces = np.concatenate(face_blocks)
        face_material = np.concatenate(material_blocks)
    normals_out = None
    if normal_blocks and all(block is not None for block in normal_blocks):
        normals_out = np.concatenate(normal_blocks)
    elif any(block is not None for block in normal_blocks):
        warnings.append(f"{name}: only some geometries have normals: normals not used")
    uvs_out = None
    if uv_blocks and any(block is not None for block in uv_blocks):
        uvs_out = np.concatenate([
            block if block is not None else np.zeros((len(v), 2)) for block, v in
            zip(uv_blocks, vertex_blocks, strict=True)
        ])
    if not np.all(np.isfinite(vertices)):
        raise SceneError("vertex position is not finite (nan or inf)", file=name)
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise SceneError(f"face index out of range ({len(vertices)} vertices)", file=name)
    if len(vertices) > 2**31 - 1:
        raise SceneError("too many vertices", file=name)
    if not materials:
        materials = [Material()]
    return MeshData(
        vertices=np.ascontiguousarray(vertices),
        faces=np.ascontiguousarray(faces, dtype=np.int32),
        normals=normals_out,
        uvs=uvs_out,
        face_material=face_material,
        materials=materials,
        warnings=warnings,
        vertex_records=len(vertices),
        triangle_records=len(faces),
        source=name,
        texture_files=texture_files,
    )
