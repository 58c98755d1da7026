"""Model files -> :class:`MeshData`: positions, fan triangles, per-vertex normals and uvs, and
materials, exactly as the file gives them.

OBJ files are read by whitted's own strict reader (:mod:`.obj_scan`, Numba): the bytes are
read from disk once, validated in one pass that stops at the first problem (with its line), and
then parsed by the same routine. Problems that make the geometry untrustworthy are errors
(:class:`~whitted.errors.SceneError`, ``path:line: problem``): an index that is 0 or out of
range, a face with fewer than 3 corners, a ``v`` with fewer than 3 coordinates, a malformed or
non-finite number, binary bytes. Problems that only cost appearance are warnings
(``MeshData.warnings``): a missing material library, a missing texture image, a ``usemtl``
naming an undefined material. Unknown statements are ignored.

Nothing is welded, repaired or reordered: ``faces`` is the fan triangulation ``(c0, ci, ci+1)``
of every polygon in file order, vertex k is the file's k-th ``v`` record. Where a position is
used with different texture coordinates or normals it is copied (bit-identical) to new vertices
after the file's ones, so that normals and uvs are per vertex.

PLY, STL, OFF and glTF/GLB files are read with trimesh (``process=False``, nothing merged).

:func:`load_mesh` keeps the results in an in-process cache keyed by (resolved path,
modification time, size), so a model used by several scene objects is read once; the arrays of
a cached result are read-only.
"""

from __future__ import annotations

import codecs
import os
import threading
from collections import OrderedDict
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..jit.python_twins import for_size
from ..scene.materials import Material
from . import obj_scan
from .mesh_data import MeshData
from .mtl import MtlRecord, read_mtl_file, split_escaped, to_material

OBJ_SUFFIXES = (".obj",)
TRIMESH_SUFFIXES = (".ply", ".stl", ".off", ".gltf", ".glb")
SUPPORTED_SUFFIXES = OBJ_SUFFIXES + TRIMESH_SUFFIXES
_CACHE_ENTRIES = 16


_cache: OrderedDict[tuple[str, int, int], MeshData] = OrderedDict()
_cache_lock = threading.Lock()
_load_locks: dict[tuple[str, int, int], threading.Lock] = {}


def clear_mesh_cache() -> None:
    """Forget every cached mesh."""
    with _cache_lock:
        _cache.clear()


def load_mesh(path: str | Path) -> MeshData:
    """Read a model file (OBJ + MTL, PLY, STL, OFF, glTF/GLB) into a :class:`MeshData`.

    Raises :class:`~whitted.errors.SceneError` (``path:line: problem``) for a missing,
    unreadable, unsupported or malformed file.
    """
    from ..files import path_problem

    name = os.fspath(path)
    file_path = Path(name)
    problem = path_problem(file_path)
    if problem is not None:
        raise SceneError(problem, file=name)
    try:
        status = file_path.stat()
    except OSError as error:
        raise SceneError(f"cannot read the file ({error.strerror or error})", file=name) from None
    suffix = file_path.suffix.lower()
    if suffix not in SUPPORTED_SUFFIXES:
        raise SceneError(
            f"unsupported model format '{file_path.suffix or '(no extension)'}' (supported: "
            f"{', '.join(SUPPORTED_SUFFIXES)})",
            file=name,
        )
    key = (str(file_path.resolve()), status.st_mtime_ns, status.st_size)
    with _cache_lock:
        cached = _cache.get(key)
        if cached is not None:
            _cache.move_to_end(key)
            return cached
        load_lock = _load_locks.setdefault(key, threading.Lock())
    try:
        with load_lock:  # two threads asking for one file: the second waits for the first
            with _cache_lock:
                cached = _cache.get(key)
            if cached is not None:
                return cached
            mesh = _read_model(file_path, name, suffix)
            _freeze(mesh)
            with _cache_lock:
                _cache[key] = mesh
                _cache.move_to_end(key)
                while len(_cache) > _CACHE_ENTRIES:
                    _cache.popitem(last=False)
    finally:
        with _cache_lock:
            _load_locks.pop(key, None)
    return mesh


#: Largest OBJ file read. Large files are memory-mapped, not read whole.
MAX_OBJ_BYTES = 8 << 30


#: Share of the first bytes that may be control bytes or invalid UTF-8 before a file is taken
#: for binary data: random bytes and binary formats have about half, a damaged text file (the
#: fuzzed OBJ files of the shared corpus) about a tenth, and those are reported by the scanner
#: on the line where the damage is.
BINARY_SHARE = 0.25


def _check_obj_head(head: bytes, name: str) -> None:
    """Refuse binary data from the first bytes, before the rest of the file is touched."""
    if not head or head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return
    control = sum(1 for byte in head if byte < 32 and byte not in (9, 10, 11, 12, 13))
    invalid = head.decode("utf-8", "replace").count("\ufffd")
    if control + invalid > BINARY_SHARE * len(head):
        k = next((i for i, byte in enumerate(head) if byte < 32 and byte not in
                  (9, 10, 11, 12, 13)), 0)
        raise SceneError(f"binary data (byte 0x{head[k]:02x}): not an OBJ text file",
                         file=name, line=head.count(b"\n", 0, k) + 1)


def _read_model(file_path: Path, name: str, suffix: str) -> MeshData:
    if suffix in OBJ_SUFFIXES:
        from ..files import head_bytes, map_limited

        _check_obj_head(head_bytes(file_path, 65536, MAX_OBJ_BYTES, "OBJ file", name), name)
        data = map_limited(file_path, MAX_OBJ_BYTES, "OBJ file", name)
        return load_obj_bytes(data, name, file_path.parent)
    from .trimesh_formats import load_with_trimesh

    return load_with_trimesh(file_path, name)


def _freeze(mesh: MeshData) -> None:
    for array in (mesh.vertices, mesh.faces, mesh.normals, mesh.uvs, mesh.face_material):
        if array is not None:
            array.flags.writeable = False


# ---------------------------------------------------------------------------------------------
# OBJ

_KIND_NAMES = {
    obj_scan.KIND_POSITION: "vertex",
    obj_scan.KIND_TEXCOORD: "texture coordinate",
    obj_scan.KIND_NORMAL: "normal",
}
_RECORD_NAMES = {
    obj_scan.KIND_POSITION: ("vertex position", "v", 3),
    obj_scan.KIND_TEXCOORD: ("texture coordinate", "vt", 1),
    obj_scan.KIND_NORMAL: ("normal", "vn", 3),
}


def obj_text_bytes(data, name: str):
    """The OBJ text as 8-bit bytes: UTF-16 (by its BOM) is re-encoded as UTF-8, a UTF-8 BOM is
    dropped; other bytes pass unchanged (names may be Latin-1). ``data`` is bytes or a memory
    map (large files); the result is bytes or a view of it."""
    head = bytes(data[:3])
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:
            return bytes(data).decode("utf-16").encode("utf-8")
        except UnicodeDecodeError as error:
            raise SceneError(f"invalid UTF-16 text ({error.reason})", file=name) from None
    if head == codecs.BOM_UTF8:
        return memoryview(data)[3:]
    return data


def _token_text(text: np.ndarray, start: int, end: int) -> str:
    raw = text[start:end].tobytes()
    if len(raw) > 60:
        raw = raw[:60] + b"..."
    try:
        shown = raw.decode("utf-8")
    except UnicodeDecodeError:
        shown = raw.decode("latin-1")
    return repr(shown)


def _obj_error(info: np.ndarray, text: np.ndarray, name: str) -> SceneError:
    code = int(info[obj_scan.INFO_CODE])
    line = int(info[obj_scan.INFO_LINE])
    token = _token_text(text, int(info[obj_scan.INFO_TOKEN_START]),
                        int(info[obj_scan.INFO_TOKEN_END]))
    kind = int(info[obj_scan.INFO_AUX1])
    aux2 = int(info[obj_scan.INFO_AUX2])
    aux3 = int(info[obj_scan.INFO_AUX3])
    if code == obj_scan.ERR_INVALID_NUMBER:
        message = f"invalid number {token} in {_RECORD_NAMES[kind][0]}"
    elif code == obj_scan.ERR_NOT_FINITE:
        message = f"{_RECORD_NAMES[kind][0]} value {token} is not finite"
    elif code == obj_scan.ERR_TOO_FEW_VALUES:
        what, keyword, needed = _RECORD_NAMES[kind]
        message = f"'{keyword}' has {aux2} values, needs at least {needed}"
    elif code == obj_scan.ERR_FACE_TOO_FEW_CORNERS:
        message = f"face has {aux2} corner{'s' if aux2 != 1 else ''}, needs at least 3"
    elif code == obj_scan.ERR_INDEX_ZERO:
        message = f"{_KIND_NAMES[kind]} index 0 (OBJ indices are 1-based) in {token}"
    elif code == obj_scan.ERR_INDEX_OUT_OF_RANGE:
        shown = str(aux2) if abs(aux2) < 10**15 else ("-" if aux2 < 0 else "") + "huge"
        message = (f"{_KIND_NAMES[kind]} index {shown} out of range ({aux3} defined so far) "
                   f"in {token}")
    elif code == obj_scan.ERR_INVALID_CORNER:
        message = f"invalid face corner {token} (expected v, v/vt, v//vn or v/vt/vn)"
    elif code == obj_scan.ERR_MISSING_VERTEX_INDEX:
        message = f"face corner {token} has no vertex index"
    elif code == obj_scan.ERR_CONTROL_BYTE:
        message = f"binary data (byte 0x{aux2:02x}): not an OBJ text file"
    else:
        message = f"unreadable OBJ data (code {code})"
    return SceneError(message, file=name, line=line or None)


def check_obj(text: np.ndarray, name: str) -> np.ndarray:
    """The validating walk: the counts (``info`` array) or a SceneError for the first problem."""
    info = np.zeros(obj_scan.INFO_SIZE, np.int64)
    empty2 = np.zeros((0, 2), np.float64)
    empty3 = np.zeros((0, 3), np.float64)
    no_corners = np.zeros((0, 3), np.int32)
    scan = for_size(obj_scan.scan_obj, len(text), obj_scan.PYTHON_LIMIT_BYTES)
    scan(text, False, info, empty3, empty2, empty3, no_corners, no_corners,
         no_corners, np.zeros((0, 4), np.int64), np.zeros((0, 3), np.int64),
         np.zeros((0, 5), np.int64))
    if info[obj_scan.INFO_CODE] != obj_scan.OK:
        raise _obj_error(info, text, name)
    return info


def _decode_name(text: np.ndarray, start: int, end: int) -> str:
    raw = text[start:end].tobytes()
    try:
        return raw.decode("utf-8").strip()
    except UnicodeDecodeError:
        return raw.decode("latin-1").strip()


def load_obj_bytes(data: bytes, name: str, folder: Path) -> MeshData:
    """A MeshData from the bytes of an OBJ file; ``folder`` is where its MTL files are."""
    text = np.frombuffer(obj_text_bytes(data, name), dtype=np.uint8)
    info = check_obj(text, name)
    position_count = int(info[obj_scan.INFO_POSITIONS])
    texcoord_count = int(info[obj_scan.INFO_TEXCOORDS])
    normal_count = int(info[obj_scan.INFO_NORMALS])
    triangle_count = int(info[obj_scan.INFO_TRIANGLES])
    if max(position_count, texcoord_count, normal_count) >= 2**31 - 1:
        raise SceneError("more than 2^31 records of one kind: too large", file=name)
    positions = np.zeros((position_count, 3), np.float64)
    texcoords = np.zeros((texcoord_count, 2), np.float64)
    normals = np.zeros((normal_count, 3), np.float64)
    corner_v = np.empty((triangle_count, 3), np.int32)
    corner_vt = np.empty((triangle_count, 3), np.int32)
    corner_vn = np.empty((triangle_count, 3), np.int32)
    usemtl_spans = np.empty((int(info[obj_scan.INFO_USEMTL]), 4), np.int64)
    mtllib_spans = np.empty((int(info[obj_scan.INFO_MTLLIB]), 3), np.int64)
    hard_numbers = np.empty((int(info[obj_scan.INFO_HARD_NUMBERS]), 5), np.int64)
    filled = np.zeros(obj_scan.INFO_SIZE, np.int64)
    scan = for_size(obj_scan.scan_obj, len(text), obj_scan.PYTHON_LIMIT_BYTES)
    scan(text, True, filled, positions, texcoords, normals, corner_v, corner_vt, corner_vn,
         usemtl_spans, mtllib_spans, hard_numbers)
    if filled[obj_scan.INFO_CODE] != obj_scan.OK:  # cannot happen after a clean check
        raise _obj_error(filled, text, name)
    _convert_hard_numbers(text, hard_numbers, (positions, texcoords, normals), name)

    warnings: list[str] = []
    materials, face_material, texture_files, library_files = _obj_materials(
        text, name, folder, usemtl_spans, mtllib_spans, triangle_count, warnings
    )

    has_vt = corner_vt >= 0
    has_vn = corner_vn >= 0
    use_uvs = bool(has_vt.any())
    use_normals = bool(has_vn.any())
    if use_normals and not has_vn.all():
        first = int(np.argmin(has_vn.all(axis=1)))
        warnings.append(f"{name}: some faces have normals and some not (triangle {first} has "
                        "none): the file's normals are not used")
        use_normals = False
    if use_uvs and not has_vt.all():
        warnings.append(f"{name}: some faces have texture coordinates and some not: those get "
                        "(0, 0)")
    if not use_uvs and not use_normals:
        faces = corner_v
        vertices = positions
        uvs = None
        vertex_normals = None
    else:
        faces, source_position, texcoord_index, normal_index = obj_scan.split_corners(
            position_count, corner_v, corner_vt if use_uvs else _minus_one(corner_vt),
            corner_vn if use_normals else _minus_one(corner_vn),
        )
        vertices = positions[source_position]
        uvs = None
        if use_uvs:
            uvs = np.zeros((len(vertices), 2), np.float64)
            given = texcoord_index >= 0
            uvs[given] = texcoords[texcoord_index[given]]
        vertex_normals = None
        if use_normals:
            vertex_normals = np.zeros((len(vertices), 3), np.float64)
            vertex_normals[:, 2] = 1.0  # vertices no face uses
            given = normal_index >= 0
            vertex_normals[given] = normals[normal_index[given]]
            _normalise_rows(vertex_normals)
    return MeshData(
        vertices=vertices,
        faces=np.ascontiguousarray(faces, dtype=np.int32),
        normals=vertex_normals,
        uvs=uvs,
        face_material=face_material,
        materials=materials,
        warnings=warnings,
        vertex_records=position_count,
        triangle_records=triangle_count,
        source=name,
        texture_files=texture_files,
        library_files=library_files,
    )


def _normalise_rows(vectors: np.ndarray) -> None:
    """Scale each non-zero row to unit length in place (huge values do not overflow)."""
    largest = np.abs(vectors).max(axis=1)
    nonzero = largest > 0.0
    vectors[nonzero] /= largest[nonzero, None]
    lengths = np.linalg.norm(vectors, axis=1)
    vectors[nonzero] /= lengths[nonzero, None]


def _minus_one(like: np.ndarray) -> np.ndarray:
    return np.full(like.shape, -1, np.int32)


def _convert_hard_numbers(
    text: np.ndarray, hard_numbers: np.ndarray, targets: tuple[np.ndarray, ...], name: str
) -> None:
    """Numbers the fast path left out (many digits, large exponents): converted by NumPy's
    string-to-double cast (correctly rounded, like float()), all at once."""
    if len(hard_numbers) == 0:
        return
    starts, ends, lines, kinds, flat = (hard_numbers[:, k] for k in range(5))
    buffer = np.empty(int((ends - starts).sum()) + len(hard_numbers), np.uint8)
    gather = for_size(obj_scan.gather_tokens, len(buffer), obj_scan.PYTHON_LIMIT_BYTES)
    gather(text, hard_numbers, buffer)
    values = np.array(buffer.tobytes().split(), dtype=np.float64)
    bad = ~np.isfinite(values)
    if bad.any():
        k = int(np.argmax(bad))
        what = _RECORD_NAMES[int(kinds[k])][0]
        raise SceneError(
            f"{what} value {_token_text(text, int(starts[k]), int(ends[k]))} is not finite",
            file=name, line=int(lines[k]),
        )
    for kind, target in enumerate(targets):
        chosen = kinds == kind
        if chosen.any():
            target.reshape(-1)[flat[chosen]] = values[chosen]


def _library_names(argument: str, folder: Path) -> list[str]:
    """The file names an ``mtllib`` argument lists (a whole name with spaces, if it exists)."""
    whole = argument.strip()
    if whole and (folder / whole).is_file():
        return [whole]
    return split_escaped(whole)


def _obj_materials(
    text: np.ndarray,
    name: str,
    folder: Path,
    usemtl_spans: np.ndarray,
    mtllib_spans: np.ndarray,
    triangle_count: int,
    warnings: list[str],
) -> tuple[list[Material], np.ndarray, list[str], list[str]]:
    records: dict[str, tuple[MtlRecord, Path, str]] = {}
    seen_libraries: set[Path] = set()
    library_files: list[str] = []
    for start, end, line in mtllib_spans.tolist():
        argument = _decode_name(text, start, end)
        for library in _library_names(argument, folder):
            path = folder / library
            if not path.is_file():
                path = folder / library.replace("\\", "/")
            if not path.is_file():
                warnings.append(f"{name}:{line}: material library '{library}' not found "
                                "(default material used)")
                continue
            resolved = path.resolve()
            if resolved in seen_libraries:
                continue
            seen_libraries.add(resolved)
            library_files.append(os.fspath(path))
            parsed = read_mtl_file(path, warnings)
            if parsed is None:
                warnings.append(f"{name}:{line}: material library '{library}' cannot be read")
                continue
            for material_name, record in parsed.items():
                records.setdefault(material_name, (record, path.parent, os.fspath(path)))

    face_material = np.zeros(triangle_count, np.int32)
    materials: list[Material] = []
    texture_files: list[str] = []
    slot_of: dict[str | None, int] = {}
    warned: set[str] = set()

    def slot(material_name: str | None) -> int:
        key = material_name if material_name in records else None
        if key not in slot_of:
            if key is None:
                material = Material()
            else:
                record, mtl_folder, mtl_name = records[key]
                try:
                    material = to_material(record, mtl_folder, mtl_name, warnings,
                                           texture_files)
                except ValueError as error:  # pydantic's ValidationError is a ValueError
                    problem = str(error).splitlines()[0]
                    warnings.append(f"{mtl_name}:{record.line}: material '{record.name}' "
                                    f"cannot be used ({problem}); default material used")
                    material = Material()
            slot_of[key] = len(materials)
            materials.append(material)
        return slot_of[key]

    # triangle ranges between usemtl statements
    boundaries = [(0, None, 0)]
    for start, end, first_triangle, line in usemtl_spans.tolist():
        boundaries.append((first_triangle, _decode_name(text, start, end) or None, line))
    for k, (first_triangle, material_name, line) in enumerate(boundaries):
        last = boundaries[k + 1][0] if k + 1 < len(boundaries) else triangle_count
        if material_name and material_name not in records and material_name not in warned:
            warned.add(material_name)
            warnings.append(f"{name}:{line}: material '{material_name}' is not defined "
                            "(default material used)")
        if last > first_triangle:
            face_material[first_triangle:last] = slot(material_name)
    if not materials:
        materials.append(Material())
    return materials, face_material, texture_files, library_files
