"""Embree (optional): Intel's BVH and triangle kernels for the big meshes.

When Embree 4 can be loaded, each mesh that is stored once and instanced (the big ones: see
``FLATTEN_LIMIT`` in :mod:`.mesh_objects`) gets an Embree scene of its triangles in the
mesh's own space, built here, and the kernels trace that mesh with ``rtcIntersect1`` /
``rtcOccluded1`` (:mod:`..kernels.embree`) instead of whitted's own mesh BVH, which is then
not built at all. Everything else, the analytic shapes, the scene and instance BVHs, the
shading, stays whitted's. The choice is ``[render] mesh_tracer`` in the scene (``auto``,
``whitted`` or ``embree``; see :func:`resolve_mesh_tracer`).

Where the library comes from, first found wins (an optional accelerator behind a try, as
trimesh keeps its own): the file ``$WHITTED_EMBREE_LIBRARY`` names; the ``libembree4`` inside
the ``embreex`` wheel (``pip install 'whitted[embree]'``), found without importing embreex;
the system's (Debian's ``libembree4-4``). Without any, ``auto`` is whitted's walk;
``WHITTED_EMBREE_LIBRARY=none`` switches Embree off.

Embree scenes are built in robust mode (watertight: no ray slips between two triangles that
share an edge). The high build quality is asked for too (spatial splits, where long thin
triangles gain), but Embree 4 gives a robust scene its standard builder whatever the quality
(``BVH8Triangle4v``); such a scene traced 14-17 % slower per ray than Embree's default, not
watertight one (docs/performance.md, "The Embree path, second round"). A mesh whose
triangles mix opaque and transparent materials gets two more Embree scenes, one of each, so
a shadow ray asks "anything opaque?" and "anything transparent?" with one ``rtcOccluded1``
each, exactly what whitted's own any-hit walk answers.

The handles, and the addresses of ``rtcIntersect1`` and ``rtcOccluded1``, go in the meshes'
``mesh_info`` rows (``MESH_EMBREE``); the scenes live as long as that array (its buffer owns
them), so kernels can never see a released one.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import hashlib
import importlib.util
import os
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..kernels.layout import (
    EMBREE_CLEAR,
    EMBREE_INTERSECT,
    EMBREE_OCCLUDED,
    MESH_EMBREE,
    N_EMBREE,
)

RTC_GEOMETRY_TYPE_TRIANGLE = 0
RTC_BUFFER_TYPE_INDEX = 0
RTC_BUFFER_TYPE_VERTEX = 1
RTC_FORMAT_UINT3 = 0x5003
RTC_FORMAT_FLOAT3 = 0x9003
RTC_SCENE_FLAG_ROBUST = 1 << 2
RTC_BUILD_QUALITY_HIGH = 2

MESH_TRACERS = ("auto", "whitted", "embree")
ENV_TRACER = "WHITTED_MESH_TRACER"  # overrides ``auto`` (tests, benchmarks)
ENV_LIBRARY = "WHITTED_EMBREE_LIBRARY"



def library_candidates() -> Iterator[str]:
    """Paths (or names) to try for libembree4, in order (none when ``$WHITTED_EMBREE_LIBRARY``
    is ``none``: Embree switched off). Lazily: the system's library search
    (``ctypes.util.find_library``, which may start the compiler and the linker: 20-35 ms) runs
    only when no candidate before it loaded."""
    named = os.environ.get(ENV_LIBRARY)
    if named == "none":
        return
    if named:
        yield named
    spec = importlib.util.find_spec("embreex")
    if spec is not None and spec.submodule_search_locations:
        for folder in spec.submodule_search_locations:
            libs = Path(folder).parent / "embreex.libs"
            for pattern in ("libembree4*.so*", "embree4*.dll", "libembree4*.dylib"):
                yield from (str(p) for p in sorted(libs.glob(pattern)))
    system = ctypes.util.find_library("embree4")
    if system:
        yield system


class EmbreeLibrary:
    """libembree4 through ctypes, with one device for the process."""

    def __init__(self, path: str) -> None:
        lib = ctypes.CDLL(path)
        vp, u32, i32 = ctypes.c_void_p, ctypes.c_uint, ctypes.c_int
        for name, restype, argtypes in (
            ("rtcNewDevice", vp, [ctypes.c_char_p]),
            ("rtcGetDeviceError", i32, [vp]),
            ("rtcNewScene", vp, [vp]),
            ("rtcSetSceneFlags", None, [vp, i32]),
            ("rtcSetSceneBuildQuality", None, [vp, i32]),
            ("rtcNewGeometry", vp, [vp, i32]),
            ("rtcSetNewGeometryBuffer", vp, [vp, i32, u32, i32, ctypes.c_size_t,
                                             ctypes.c_size_t]),
            ("rtcCommitGeometry", None, [vp]),
            ("rtcAttachGeometry", u32, [vp, vp]),
            ("rtcReleaseGeometry", None, [vp]),
            ("rtcCommitScene", None, [vp]),
            ("rtcReleaseScene", None, [vp]),
            ("rtcRetainScene", None, [vp]),
        ):
            fn = getattr(lib, name)
            fn.restype = restype
            fn.argtypes = argtypes
        self.lib = lib
        self.path = path
        self.device = lib.rtcNewDevice(None)
        if not self.device:
            raise OSError(f"{path}: rtcNewDevice failed")
        # the two entry points the kernels call, as plain addresses (kernels/embree.py)
        self.intersect1 = ctypes.cast(lib.rtcIntersect1, ctypes.c_void_p).value
        self.occluded1 = ctypes.cast(lib.rtcOccluded1, ctypes.c_void_p).value

    def check(self, what: str) -> None:
        code = self.lib.rtcGetDeviceError(self.device)
        if code:
            raise OSError(f"Embree error {code} while {what} ({self.path})")

    def triangle_scene(self, vertices: np.ndarray, faces: np.ndarray) -> int:
        """A committed Embree scene of one triangle mesh; returns its handle."""
        lib = self.lib
        vertices = np.ascontiguousarray(vertices, np.float32)
        faces = np.ascontiguousarray(faces, np.uint32)
        scene = lib.rtcNewScene(self.device)
        lib.rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST)
        lib.rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH)
        geom = lib.rtcNewGeometry(self.device, RTC_GEOMETRY_TYPE_TRIANGLE)
        vbuf = lib.rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           12, len(vertices))
        ibuf = lib.rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           12, len(faces))
        if not vbuf or not ibuf:
            lib.rtcReleaseGeometry(geom)
            lib.rtcReleaseScene(scene)
            self.check("allocating a mesh")
            raise MemoryError("Embree could not allocate a mesh's buffers")
        ctypes.memmove(vbuf, vertices.ctypes.data, vertices.nbytes)
        ctypes.memmove(ibuf, faces.ctypes.data, faces.nbytes)
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(scene, geom)
        lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(scene)
        self.check("building a mesh's BVH")
        return scene

    def release(self, scene: int) -> None:
        self.lib.rtcReleaseScene(ctypes.c_void_p(scene))

    def retain(self, scene: int) -> None:
        self.lib.rtcRetainScene(ctypes.c_void_p(scene))


_library: EmbreeLibrary | None = None
_library_error: str | None = None
_lock = threading.Lock()


def embree_library() -> EmbreeLibrary | None:
    """The loaded library, or None when no candidate loads (the reason: :func:`why_not`)."""
    global _library, _library_error
    with _lock:
        if _library is None and _library_error is None:
            errors = []
            for path in library_candidates():
                try:
                    _library = EmbreeLibrary(path)
                    break
                except (OSError, AttributeError) as exc:
                    errors.append(f"{path}: {exc}")
            else:
                _library_error = "; ".join(errors) or (
                    "no libembree4 found (pip install 'whitted[embree]', or set "
                    f"{ENV_LIBRARY})")
        return _library


def why_not() -> str | None:
    """Why Embree is not available, or None when it is."""
    embree_library()
    return _library_error


def resolve_mesh_tracer(setting: str = "auto") -> str:
    """``whitted`` or ``embree``: the scene's ``mesh_tracer`` with ``auto`` made concrete
    (``$WHITTED_MESH_TRACER`` first, then Embree when it loads). Asking for ``embree``
    where it cannot load is a :class:`~whitted.errors.SceneError`."""
    if setting == "auto":
        setting = os.environ.get(ENV_TRACER, "auto") or "auto"
        if setting not in MESH_TRACERS:
            raise SceneError(f"${ENV_TRACER}: {setting!r} is not one of "
                             f"{', '.join(MESH_TRACERS)}")
        if setting == "auto":
            return "embree" if embree_library() is not None else "whitted"
    if setting == "embree" and embree_library() is None:
        raise SceneError(f"render.mesh_tracer = 'embree': Embree is not available "
                         f"({why_not()})")
    return setting


def with_addresses(mesh_info: np.ndarray, library: EmbreeLibrary | None,
                   rows: list[list[int]]) -> np.ndarray:
    """``mesh_info`` with each mesh's Embree scenes (``rows[k]``: EMBREE_ALL, EMBREE_OPAQUE,
    EMBREE_CLEAR) and the library's entry points in its MESH_EMBREE columns, in memory that
    releases the scenes when the last array viewing it goes (the arrays' ``base`` chain ends
    at the owning ctypes buffer)."""
    import weakref

    k, width = mesh_info.shape
    block = (ctypes.c_int32 * max(k * width, 1))()
    info = np.frombuffer(block, dtype=np.int32)[:k * width].reshape(k, width)
    info[:] = mesh_info
    if library is not None and rows:
        addresses = np.zeros((k, N_EMBREE), np.int64)
        addresses[:, :EMBREE_CLEAR + 1] = rows
        addresses[:, EMBREE_INTERSECT] = library.intersect1
        addresses[:, EMBREE_OCCLUDED] = library.occluded1
        halves = addresses.view(np.uint64)
        info[:, MESH_EMBREE:MESH_EMBREE + 2 * N_EMBREE:2] = (
            halves & np.uint64(0xFFFFFFFF)).astype(np.uint32).view(np.int32)
        info[:, MESH_EMBREE + 1:MESH_EMBREE + 2 * N_EMBREE:2] = (
            halves >> np.uint64(32)).astype(np.uint32).view(np.int32)
        # one reference per distinct handle of each row (a row's parts may be its whole scene)
        held = [h for row in rows for h in sorted({x for x in row if x})]
        weakref.finalize(block, _release_all, library, held)
    return info


def embree_addresses(mesh_info: np.ndarray) -> np.ndarray:
    """(K, N_EMBREE) int64: the addresses in ``mesh_info``'s MESH_EMBREE columns (columns
    EMBREE_ALL, ..., EMBREE_OCCLUDED), for inspection and tests."""
    info = np.ascontiguousarray(mesh_info[:, MESH_EMBREE:MESH_EMBREE + 2 * N_EMBREE])
    low = info[:, 0::2].view(np.uint32).astype(np.uint64)
    high = info[:, 1::2].view(np.uint32).astype(np.uint64)
    return ((high << np.uint64(32)) | low).view(np.int64)


def _release_all(library: EmbreeLibrary, scenes: list[int]) -> None:
    for s in scenes:
        library.release(s)


def _mesh_row(library: EmbreeLibrary, v: np.ndarray, f: np.ndarray, op: np.ndarray) -> list[int]:
    """One mesh's Embree scenes (EMBREE_ALL, EMBREE_OPAQUE, EMBREE_CLEAR): its scene, and its
    opaque and transparent parts (the same scene where all its triangles are one or the
    other). Each distinct handle is
    one reference, released by whoever holds the row."""
    row = [library.triangle_scene(v, f), 0, 0]
    try:
        if op.all():
            row[1] = row[0]
        elif not op.any():
            row[2] = row[0]
        else:
            row[1] = library.triangle_scene(v, f[op])
            row[2] = library.triangle_scene(v, f[~op])
    except BaseException:
        for handle in {x for x in row if x}:
            library.release(handle)
        raise
    return row


def build_mesh_scenes(library: EmbreeLibrary, vertices: list[np.ndarray],
                      faces: list[np.ndarray], opaque: list[np.ndarray]) -> list[list[int]]:
    """Embree scenes for each mesh k (``vertices[k]`` (V, 3) float32, ``faces[k]`` (T, 3)
    indices into them, ``opaque[k]`` (T,) bool): a row (EMBREE_ALL, EMBREE_OPAQUE,
    EMBREE_CLEAR) per mesh, each distinct handle of a row one reference the caller owns."""
    from .reuse import active_memo

    memo = active_memo()
    rows: list[list[int]] = []
    try:
        for v, f, op in zip(vertices, faces, opaque, strict=True):
            if memo is None:
                rows.append(_mesh_row(library, v, f, op))
                continue
            h = hashlib.blake2b(digest_size=16)
            for part in (v, f, op):
                part = np.ascontiguousarray(part)
                h.update(repr((part.dtype.str, part.shape)).encode())
                h.update(part.tobytes())
            rows.append(memo.embree_row(h.digest(), library,
                                        lambda v=v, f=f, op=op: _mesh_row(library, v, f, op)))
    except BaseException:
        _release_all(library, [h for row in rows for h in sorted({x for x in row if x})])
        raise
    return rows


def attach_embree(tracer: str, mesh_info: np.ndarray, vertices: list[np.ndarray],
                  faces: list[np.ndarray], tri_material: list[np.ndarray],
                  materials: np.ndarray) -> np.ndarray:
    """``mesh_info`` for meshes k (``vertices[k]``, local ``faces[k]``, ``tri_material[k]``
    material-table rows of its triangles) with Embree's addresses when ``tracer`` is
    ``embree`` (else zeros there: whitted's walk)."""
    if tracer != "embree" or not vertices:
        return mesh_info
    from ..kernels.layout import MAT_KT
    from ..kernels.mesh import OPAQUE_KT

    library = embree_library()
    if library is None:
        raise SceneError(f"render.mesh_tracer = 'embree': Embree is not available "
                         f"({why_not()})")
    opaque = [materials[m, MAT_KT] < OPAQUE_KT for m in tri_material]
    rows = build_mesh_scenes(library, vertices, faces, opaque)
    try:
        return with_addresses(mesh_info, library, rows)
    except BaseException:
        _release_all(library, [h for row in rows for h in sorted({x for x in row if x})])
        raise


def with_concrete_mesh_tracer(scene):
    """``scene`` with ``render.mesh_tracer = "auto"`` made concrete here, so that machines
    that render parts of one image (the farm's workers) trace its meshes alike even where
    some have Embree and some not: a worker that lacks the tracer chosen says so."""
    if scene.render.mesh_tracer != "auto":
        return scene
    return scene.with_settings(mesh_tracer=resolve_mesh_tracer("auto"))
