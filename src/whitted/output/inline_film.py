"""A film to watch in a notebook: an MP4 plays as an HTML5 ``<video>``, a GIF as an image.

:class:`Film` is what ``whitted.render_film`` returns, and what :meth:`Film.from_frames`
makes of a folder of frames already rendered (encoded in memory: nothing is written unless
:meth:`Film.save` is asked to). Where no MP4 encoder can be found (imageio-ffmpeg's ffmpeg),
the frames become a GIF, which every notebook shows too. Its text form names the frame
count, the frame rate and the size: ``<Film orbit.mp4: 48 frames at 24 fps, 640x360, 2.0 s>``.
"""

from __future__ import annotations

import base64
import html
import os
import re
import tempfile
from pathlib import Path

from ..errors import OutputError

__all__ = ["EMBED_LIMIT", "Film", "frame_files", "mp4_encoder"]

#: Films up to this many bytes are embedded in the notebook (base64); a bigger one is linked
#: by its path (the notebook stays small; the browser reads the file beside it).
EMBED_LIMIT = 25 * 1024 * 1024
_NUMBERED = re.compile(r"(\d+)\.png$", re.IGNORECASE)


def mp4_encoder() -> bool:
    """An MP4 encoder is there: imageio-ffmpeg's ffmpeg (``whitted[film]``), or an
    ``ffmpeg`` on the PATH (:func:`whitted.output.video.ffmpeg_exe`)."""
    from ..errors import WhittedError
    from .video import ffmpeg_exe

    try:
        return bool(ffmpeg_exe())
    except (WhittedError, RuntimeError, OSError):
        return False


def frame_files(folder: str | os.PathLike[str]) -> list[Path]:
    """The numbered PNGs of a frames folder (``0000.png``, ``0001.png``, ...; whitted's
    names, or any name ending in a number), in the order of their numbers.
    :class:`OutputError` when the folder cannot be read or holds no such file."""
    folder = Path(folder)
    try:
        entries = list(folder.iterdir())
    except (OSError, ValueError) as exc:
        why = "is not a folder" if folder.is_file() else getattr(exc, "strerror", None) or exc
        raise OutputError(f"{folder}: cannot read the frames: {why}") from None
    numbered = []
    for path in entries:
        m = _NUMBERED.search(path.name)
        if m is not None and path.is_file():
            numbered.append((int(m.group(1)), path.name, path))
    if not numbered:
        raise OutputError(f"{folder}: no numbered PNG frames (0000.png, 0001.png, ...)")
    return [p for _, _, p in sorted(numbered)]


class Film:
    """A film file (``path``) or its bytes (``data``, with its ``kind``, "mp4" or "gif"),
    with what it is: ``frames``, ``fps`` and ``size`` (width, height)."""

    def __init__(self, path: str | os.PathLike[str] | None = None, *, frames: int, fps: float,
                 size: tuple[int, int], data: bytes | None = None, kind: str | None = None,
                 result: object = None, frames_folder: str | os.PathLike[str] | None = None
                 ) -> None:
        if path is None and data is None:
            raise ValueError("a Film needs a path or its data")
        self.path = None if path is None else Path(path)
        self.kind = kind or (self.path.suffix.lower().lstrip(".") if self.path else "mp4")
        self.frames = int(frames)
        self.fps = float(fps)
        self.size = (int(size[0]), int(size[1]))
        self._data = data
        #: what made it (``whitted.render_film``'s :class:`~whitted.animation.film.FilmResult`)
        self.result = result
        #: the folder of its frames (PNGs), where known
        self.frames_folder = None if frames_folder is None else Path(frames_folder)

    @classmethod
    def from_frames(cls, folder: str | os.PathLike[str] | list, fps: float = 24.0, *,
                    kind: str | None = None) -> Film:
        """The film of the numbered PNG frames in ``folder`` (or a list of PNG files, in
        order), encoded in memory: MP4 when an encoder is there, else GIF (``kind`` chooses).
        One-line :class:`OutputError` for a folder without frames, frames of different sizes
        or a frame rate the format does not take."""
        from PIL import Image as PILImage

        from .video import check_fps, encode_film

        files = frame_files(folder) if not isinstance(folder, list) else [Path(f) for f in folder]
        if not files:
            raise OutputError("no frames to make a film of")
        kind = kind or ("mp4" if mp4_encoder() else "gif")
        if kind not in ("mp4", "gif"):
            raise OutputError(f"a film is mp4 or gif, not {kind!r}")
        try:
            fps = check_fps(fps, kind)
        except ValueError as exc:
            raise OutputError(f"fps: {exc}") from None
        with PILImage.open(files[0]) as first:
            size = first.size
        with tempfile.TemporaryDirectory(prefix="whitted-film-") as tmp:
            out = Path(tmp) / f"film.{kind}"
            try:
                encode_film(files, out, fps)
            except (ValueError, OSError) as exc:
                where = files[0].parent if not isinstance(folder, list) else files[0]
                text = getattr(exc, "strerror", None) or str(exc)
                raise OutputError(f"{where}: cannot make a film of the frames: {text}") from None
            data = out.read_bytes()
        if kind == "mp4":
            size = (size[0] + size[0] % 2, size[1] + size[1] % 2)  # yuv420p: even sides
        return cls(None, frames=len(files), fps=fps, size=size, data=data, kind=kind,
                   frames_folder=None if isinstance(folder, list) else folder)

    # ------------------------------------------------------------------ bytes and files
    @property
    def data(self) -> bytes:
        """The film's bytes (read from ``path`` when it has one)."""
        if self._data is not None:
            return self._data
        assert self.path is not None
        return self.path.read_bytes()

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the film to ``path`` (atomically; its extension must be the film's kind)."""
        from ..files import atomic_write

        path = Path(path)
        if path.suffix.lower() != f".{self.kind}":
            raise OutputError(f"{path}: this film is {self.kind.upper()}: "
                              f"use a .{self.kind} name")
        data = self.data
        try:
            return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))
        except OSError as exc:
            raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None

    @property
    def seconds(self) -> float:
        return self.frames / self.fps if self.fps > 0 else 0.0

    # ------------------------------------------------------------------ display
    def __repr__(self) -> str:
        name = self.path.name if self.path is not None else f"in memory, {self.kind.upper()}"
        return (f"<Film {name}: {self.frames} frame{'s' if self.frames != 1 else ''} at "
                f"{self.fps:g} fps, {self.size[0]}x{self.size[1]}, {self.seconds:.1f} s>")

    def _repr_html_(self) -> str:
        w, h = self.size
        caption = html.escape(repr(self))
        size = self.path.stat().st_size if self._data is None and self.path else len(self.data)
        if size > EMBED_LIMIT and self.path is not None:
            src = html.escape(self.path.as_posix(), quote=True)
        else:
            mime = "video/mp4" if self.kind == "mp4" else "image/gif"
            src = f"data:{mime};base64,{base64.b64encode(self.data).decode('ascii')}"
        if self.kind == "mp4":
            body = (f'<video controls loop autoplay muted playsinline width="{w}" '
                    f'height="{h}" style="max-width:100%;height:auto" src="{src}">'
                    f"{caption}</video>")
        else:
            body = (f'<img src="{src}" width="{w}" height="{h}" '
                    f'style="max-width:100%;height:auto" alt="{caption}">')
        return f"<figure style=\"margin:0\">{body}<figcaption>{caption}</figcaption></figure>"
