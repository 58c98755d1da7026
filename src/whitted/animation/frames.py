"""Render frames of an animated scene to PNG files that say what they are a picture of.

Each frame PNG carries, in a text chunk, a hash of everything its pixels depend on: the still of
that frame (every scene value, its seed, image size, samples, ...), the frame number, the
renderer's kernel sources, and the size and modification time of every file the frame reads: the
model and texture files the still names, and each model's own material libraries (MTL) and the
textures those name (:func:`model_files`); and the fingerprint of the renderer that made it
(:mod:`whitted.fingerprint`, recorded by whichever process rendered it: a farm's worker). A later
run compares both with its own and skips the frame when they match: films resume where they
stopped, and a change to the scene renders again exactly the frames it changes. Thread counts
are not part of the hash (images do not depend on them).

:func:`render_frame` is the plain function a render farm calls per frame; a
:class:`FrameRenderer` renders many frames in one process and reuses what it can between them
(kernels, and compiled geometry when only camera, lights or material values change)."""

from __future__ import annotations

import functools
import hashlib
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel

if TYPE_CHECKING:
    from ..render.api import CancelToken, Progress, RenderStats
    from ..scene.scene import Scene

__all__ = ["FRAME_HASH_KEY", "FrameRenderer", "FrameResult", "frame_digest", "frame_is_current",
           "is_whitted_frame", "model_files", "read_frame_digest", "render_frame",
           "still_for_frame", "write_frame_png"]

FRAME_HASH_KEY = "whitted:frame-hash"
FRAME_NUMBER_KEY = "whitted:frame"
_HASH_VERSION = b"whitted-frame-v2"  # v2: a model's MTL files and their textures counted
FRAME_PNG_LEVEL = 1


# ------------------------------------------------------------------------------ hashing


def _feed(h: Any, value: Any, scene: Scene) -> None:
    """Feed a canonical encoding of a scene value to hash ``h``."""
    from ..scene.shapes import ArrayData

    if isinstance(value, BaseModel):
        h.update(b"{" + type(value).__name__.encode())
        for name in type(value).model_fields:
            h.update(b"|" + name.encode() + b"=")
            item = getattr(value, name)
            _feed(h, item, scene)
            if name == "file" and isinstance(item, str):
                path = scene.resolve_path(item)
                _feed_file(h, path)
                if type(value).__name__ == "Mesh":  # what the model file itself reads
                    for extra in model_files(path):
                        _feed_file(h, extra)
        h.update(b"}")
    elif isinstance(value, ArrayData):
        h.update(f"<array {value.array.dtype} {value.array.shape}>".encode())
        h.update(np.ascontiguousarray(value.array).tobytes())
    elif isinstance(value, list | tuple):
        h.update(b"[")
        for item in value:
            _feed(h, item, scene)
            h.update(b",")
        h.update(b"]")
    elif isinstance(value, dict):
        h.update(b"(")
        for key in sorted(value):
            h.update(json.dumps(str(key)).encode() + b":")
            _feed(h, value[key], scene)
        h.update(b")")
    elif isinstance(value, float):
        h.update(b"f" + (repr(value) if math.isfinite(value) else str(value)).encode())
    else:
        h.update(type(value).__name__.encode() + b":" + repr(value).encode())


def _feed_file(h: Any, path: Path) -> None:
    try:
        st = path.stat()
        h.update(f"<file {path} {st.st_size} {st.st_mtime_ns}>".encode())
    except OSError:
        h.update(f"<missing {path}>".encode())


def model_files(path: Path) -> list[Path]:
    """The files a render reads for the model file ``path`` besides ``path`` itself: its
    material libraries (MTL) and the texture images they (or the model) name, as
    :func:`whitted.assets.mesh.load_mesh` reads them (the same in-process cache, so the render
    that follows reads nothing twice). A model that cannot be read gives none: the render
    reports it."""
    from ..assets.mesh import load_mesh
    from ..errors import WhittedError

    try:
        mesh = load_mesh(path)
    except (WhittedError, OSError, ValueError):
        return []
    return [Path(f) for f in (*mesh.library_files, *mesh.texture_files)]


@functools.cache
def _kernel_sources() -> str:
    from ..jit.cache import kernel_source_hash

    return kernel_source_hash()


def frame_digest(still: Scene, frame: int) -> str:
    """Hex SHA-256 of what the pixels of ``still`` (the scene of frame ``frame``) depend on;
    the render's thread count is left out."""
    h = hashlib.sha256(_HASH_VERSION)
    h.update(_kernel_sources().encode())
    h.update(f"frame={int(frame)}".encode())
    _feed(h, still.render.model_copy(update={"threads": 0}), still)
    for name in type(still).model_fields:
        if name != "render":
            h.update(b"|" + name.encode() + b"=")
            _feed(h, getattr(still, name), still)
    return h.hexdigest()


def _read_frame_record(path: str | Path) -> dict[str, Any]:
    import stat

    from PIL import Image as PILImage

    try:  # a regular file only: opening a pipe would wait for a writer
        if not stat.S_ISREG(Path(path).stat().st_mode):
            return {}
        with PILImage.open(path) as im:
            return dict(getattr(im, "text", None) or im.info)
    except (OSError, ValueError, SyntaxError):
        return {}


def read_frame_digest(path: str | Path) -> str | None:
    """The frame hash recorded in a PNG written by :func:`render_frame` (None when the file
    is missing, unreadable or has none)."""
    value = _read_frame_record(path).get(FRAME_HASH_KEY)
    return value if isinstance(value, str) else None


_RECORD_MARK = b"tEXt" + FRAME_HASH_KEY.encode() + b"\0"
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def is_whitted_frame(path: str | Path) -> bool:
    """Whether ``path`` is a frame PNG whitted wrote: a PNG whose head carries the frame
    record (its text chunk comes before the pixels, so a frame cut short is still known as
    whitted's, and rendered again). The only kind of file a film or a sweep may replace."""
    import stat

    try:
        if not stat.S_ISREG(Path(path).stat().st_mode):
            return False
        with open(path, "rb") as f:
            head = f.read(4096)
    except (OSError, ValueError):
        return False
    return head.startswith(_PNG_SIGNATURE) and _RECORD_MARK in head


def frame_is_current(path: str | Path, digest: str) -> bool:
    """Whether ``path`` is a finished frame PNG with hash ``digest``, rendered by this
    renderer (its recorded fingerprint, :mod:`whitted.fingerprint`, is this process's)."""
    from ..fingerprint import FINGERPRINT_KEY, renderer_fingerprint

    record = _read_frame_record(path)
    return (record.get(FRAME_HASH_KEY) == digest
            and record.get(FINGERPRINT_KEY) == renderer_fingerprint())


def _write_frame_png(path: Path, image: Any, digest: str, frame: int) -> None:
    from PIL import Image as PILImage
    from PIL.PngImagePlugin import PngInfo

    from ..files import atomic_write
    from ..fingerprint import FINGERPRINT_KEY, renderer_fingerprint
    from ..output.png import SOFTWARE

    data = image.to_srgb8()
    info = PngInfo()
    info.add_text("Software", SOFTWARE.decode())  # as every PNG whitted writes (output/png.py)
    info.add_text(FRAME_HASH_KEY, digest)
    info.add_text(FRAME_NUMBER_KEY, str(int(frame)))
    info.add_text(FINGERPRINT_KEY, renderer_fingerprint())  # the renderer that made it
    # zlib level 1: a film's frames are working files; 4x faster to write than level 6
    # (640x360: 6 vs 25 ms) for files about a third larger
    atomic_write(path, lambda tmp: PILImage.fromarray(data).save(
        tmp, format="PNG", pnginfo=info, compress_level=FRAME_PNG_LEVEL))


def write_frame_png(path: str | Path, image: Any, digest: str, frame: int) -> None:
    """Write ``image`` as the frame PNG ``path`` with its frame record (``digest``, the frame
    number), atomically."""
    _write_frame_png(Path(path), image, digest, frame)


# ------------------------------------------------------------------------------ rendering


def still_for_frame(scene: Scene, frame: int, **settings: Any) -> Scene:
    """The still of ``frame`` with render settings replaced (``width``, ``height``,
    ``samples``, ``max_depth``, ``seed``, ...; None keeps the scene's). The seed given is
    the film's: each frame derives its own from it."""
    if any(v is not None for v in settings.values()):
        scene = scene.with_settings(**settings)
    return scene.at_frame(frame)


@dataclass
class FrameResult:
    """What :func:`render_frame` did for one frame."""

    frame: int
    path: Path
    digest: str
    rendered: bool  # False: the file was already current and was kept
    cancelled: bool = False  # stopped part way: nothing was written
    seconds: float = 0.0
    stats: RenderStats | None = field(default=None, repr=False)
    #: what the compile reused from the frame before: all, geometry, bvh, none ('' if skipped)
    reuse: str = ""


class FrameRenderer:
    """Renders frames one after another in this process. Kernels load once; the compiled
    scene of the previous frame is reused when this frame's geometry is the same
    (see :mod:`whitted.animation.reuse`). ``threads``: render threads (None: the scene's)."""

    def __init__(self, threads: int | None = None) -> None:
        self.threads = threads
        self._cache: Any = None  # reuse.CompileCache, created on first use
        self.frames_rendered = 0

    def compile(self, still: Scene) -> tuple[Any, str]:
        """The compiled scene of ``still`` and what was reused (see :mod:`.reuse`), its light
        buffers built on the frame's render threads."""
        from ..render.api import available_threads

        threads = self.threads if self.threads is not None else still.render.threads
        return self.cache.compile(still, threads=max(1, threads or available_threads()))

    @property
    def cache(self) -> Any:
        """The :class:`~whitted.animation.reuse.CompileCache` (its ``stats`` say what was
        reused)."""
        from .reuse import CompileCache

        if self._cache is None:
            self._cache = CompileCache()
        return self._cache

    def render(
        self,
        still: Scene,
        frame: int,
        path: str | Path,
        *,
        force: bool = False,
        progress: Callable[[Progress], None] | None = None,
        cancel: CancelToken | None = None,
        digest: str | None = None,
    ) -> FrameResult:
        """Render ``still`` (a scene from ``scene.at_frame(frame)``) to the PNG ``path``,
        unless ``path`` already holds this frame (its hash matches) and ``force`` is off.
        ``digest``: the frame's hash when the caller made it already."""
        from ..render.api import RenderJob

        path = Path(path)
        digest = digest or frame_digest(still, frame)
        if not force and frame_is_current(path, digest):
            return FrameResult(frame, path, digest, rendered=False)
        start = time.perf_counter()
        compiled, reuse = self.compile(still)
        job = RenderJob(still, progress=progress, cancel=cancel, threads=self.threads,
                        compiled=compiled)
        image = job.run()
        seconds = time.perf_counter() - start
        if job.stats.cancelled:
            return FrameResult(frame, path, digest, rendered=False, cancelled=True,
                               seconds=seconds, stats=job.stats, reuse=reuse)
        _write_frame_png(path, image, digest, frame)
        self.frames_rendered += 1
        return FrameResult(frame, path, digest, rendered=True, seconds=seconds,
                           stats=job.stats, reuse=reuse)


def render_frame(
    scene: Scene,
    frame: int,
    path: str | Path,
    *,
    width: int | None = None,
    height: int | None = None,
    samples: int | None = None,
    max_depth: int | None = None,
    seed: int | None = None,
    threads: int | None = None,
    overrides: list[tuple[str, Any]] | dict[str, Any] | None = None,
    force: bool = False,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    renderer: FrameRenderer | None = None,
) -> FrameResult:
    """Render frame ``frame`` of ``scene`` (animated or not) to the 8-bit PNG ``path``.

    The frame is ``scene`` with ``overrides`` applied (``[(path, value)]`` as in ``--set``),
    its render settings replaced by the keyword values given, then taken at ``frame``
    (``scene.at_frame``). The PNG records a hash of all that (:func:`frame_digest`); when
    ``path`` already holds a PNG with the same hash it is kept and not rendered again
    (``force=True`` renders anyway). The image does not depend on ``threads`` nor on the
    process or machine that renders it, so frames may be rendered anywhere, in any order.
    Written atomically; a cancelled frame writes nothing. Pass the same ``renderer`` to
    consecutive calls in one process to reuse compiled geometry between frames.

    Returns a :class:`FrameResult` (``rendered`` False when the file was already current).
    Raises :class:`~whitted.SceneError` for an unusable scene, override or frame number.
    """
    if overrides:
        from .overrides import apply_overrides

        scene = apply_overrides(scene, overrides)
    still = still_for_frame(scene, frame, width=width, height=height, samples=samples,
                            max_depth=max_depth, seed=seed)
    renderer = renderer or FrameRenderer(threads)
    if threads is not None:
        renderer.threads = threads
    return renderer.render(still, frame, path, force=force, progress=progress, cancel=cancel)
