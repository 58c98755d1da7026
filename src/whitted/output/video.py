"""Films from frames: H.264 MP4 through imageio-ffmpeg's own ffmpeg, and GIF through Pillow.

No ffmpeg needs to be installed: imageio-ffmpeg ships a static one. MP4 files are H.264,
yuv420p (what every player plays), quality by an explicit CRF (18: visually lossless for
renders), with the index at the front (``+faststart``) so a browser starts playing before
the whole file has arrived. yuv420p needs even sizes: an odd width or height gets one more
column or row, a copy of the last one (the picture is never scaled).

Frame rates are bounded to what the formats hold (:func:`check_fps`): an MP4 takes
:data:`FPS_MIN` .. 1000 frames a second, a GIF :data:`FPS_MIN` .. 50 (its delays are whole
hundredths of a second, 2 at least: players show shorter ones at 10 fps). Files are written
atomically, as every output of whitted: ffmpeg writes a temporary file that replaces the film
only when ffmpeg says it succeeded, so a failed or cancelled encode never replaces a good
film. ffmpeg runs as a child process in a session of its own (a Ctrl-C on the terminal
reaches whitted only); it is stopped when the encode is cancelled (``cancel``) or fails.

Every film whitted encodes says so, as its PNGs do (``Software: whitted``): an MP4 carries the
comment ``whitted`` in its metadata (ffmpeg's ``-metadata comment=``), a GIF a comment
extension ``whitted`` (Pillow's ``comment``). :func:`film_written_by_whitted` reads it back
(ffmpeg's own metadata dump, ``-f ffmetadata``; Pillow for a GIF). A remux or re-encode
keeps such a comment, so whitted also records each film's bytes when it writes it
(output/ownership.py): a command may replace a film at a name the user did not give
(``whitted animate``'s film.mp4) only when it carries the mark and is byte for byte the film
whitted wrote there.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterable, Iterator
from fractions import Fraction
from pathlib import Path
from typing import Protocol

import numpy as np

from ..errors import ArgumentError, RenderCancelled
from ..files import atomic_write

__all__ = ["DEFAULT_CRF", "FILM_MARK", "FPS_MAX", "FPS_MIN", "VIDEO_FORMATS", "check_crf",
           "check_fps", "encode_film", "even_size", "film_written_by_whitted", "pad_to_even",
           "video_format"]

DEFAULT_CRF = 18
VIDEO_FORMATS = {".mp4": "mp4", ".gif": "gif"}
#: The slowest film: one frame every 100 s.
FPS_MIN = 0.01
#: The fastest film of each format (a GIF's delays are hundredths of a second, 2 at least).
FPS_MAX = {"mp4": 1000.0, "gif": 50.0}
#: What every film whitted encodes says of itself: an MP4's metadata comment, a GIF's comment.
FILM_MARK = "whitted"
#: Seconds ffmpeg may take to read a film's metadata (it reads the head only).
PROBE_SECONDS = 20


class Cancel(Protocol):
    """What ``cancel`` is: a :class:`~whitted.render.api.CancelToken` or the like."""

    @property
    def cancelled(self) -> bool: ...


def check_fps(fps: object, fmt: str) -> float:
    """``fps`` as a float when a film of format ``fmt`` (``mp4``, ``gif``) can show it;
    ValueError saying the range otherwise."""
    most = FPS_MAX[fmt]
    try:
        rate = float(fps)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"must be a number of frames a second, got {fps!r}") from None
    if not (math.isfinite(rate) and FPS_MIN <= rate <= most):
        why = (" (a GIF's delays are whole hundredths of a second, 2 at least)"
               if fmt == "gif" and rate > most else "")
        raise ValueError(f"must be {FPS_MIN:g} .. {most:g} frames a second for "
                         f"{fmt.upper()}{why}, got {rate:g}")
    return rate


def check_crf(crf: object) -> int:
    """``crf`` when it is an H.264 quality (0 best .. 51 worst); ValueError otherwise."""
    if isinstance(crf, bool) or not isinstance(crf, int) or not 0 <= crf <= 51:
        raise ValueError(f"must be 0 .. 51, got {crf!r}")
    return crf


def video_format(path: str | os.PathLike[str]) -> str:
    """``mp4`` or ``gif`` by the extension of ``path``; ValueError for any other."""
    suffix = Path(path).suffix.lower()
    try:
        return VIDEO_FORMATS[suffix]
    except KeyError:
        raise ValueError(f"unsupported film format {Path(path).suffix!r} (use .mp4 or .gif, "
                         "or a folder for the PNG frames only)") from None


def even_size(width: int, height: int) -> tuple[int, int]:
    """The frame size an MP4 of ``width`` x ``height`` images has (odd sides + 1)."""
    return width + width % 2, height + height % 2


def pad_to_even(frame: np.ndarray) -> np.ndarray:
    """An (H, W, 3) uint8 frame with odd sides extended by a copy of the last row/column."""
    h, w = frame.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return frame
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


def _read_rgb8(item: str | os.PathLike[str] | np.ndarray) -> np.ndarray:
    if isinstance(item, np.ndarray):
        frame = item
    else:
        from PIL import Image as PILImage

        with PILImage.open(item) as im:
            frame = np.asarray(im.convert("RGB"))
    if frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] != 3:
        raise ValueError(f"frames must be (H, W, 3) uint8 images, got {frame.dtype} "
                         f"{frame.shape}")
    return frame


def _frames(items: Iterable[str | os.PathLike[str] | np.ndarray]) -> Iterator[np.ndarray]:
    size = None
    for item in items:
        frame = _read_rgb8(item)
        if size is None:
            size = frame.shape
        elif frame.shape != size:
            raise ValueError(f"frame {item if not isinstance(item, np.ndarray) else ''} is "
                             f"{frame.shape[1]}x{frame.shape[0]}, the first was "
                             f"{size[1]}x{size[0]}")
        yield frame


def encode_film(
    frames: Iterable[str | os.PathLike[str] | np.ndarray],
    path: str | os.PathLike[str],
    fps: float,
    *,
    crf: int = DEFAULT_CRF,
    cancel: Cancel | None = None,
) -> Path:
    """Encode ``frames`` (PNG file names or (H, W, 3) uint8 arrays, all one size) into the
    film ``path``: ``.mp4`` (H.264, yuv420p, ``crf``, +faststart) or ``.gif`` (looping,
    an adaptive 256-colour palette per frame). Written atomically: a failed encode raises
    (ValueError or OSError) and leaves ``path`` as it was. ``cancel``: checked between
    frames; once set, ffmpeg is stopped, nothing is written and
    :class:`~whitted.errors.RenderCancelled` is raised. Returns ``path``."""
    fmt = video_format(path)
    fps = check_fps(fps, fmt)
    crf = check_crf(crf)
    items = list(frames)
    if not items:
        raise ValueError("no frames to encode")
    if fmt == "gif":
        written = atomic_write(path, lambda tmp: _write_gif(tmp, _frames(items), fps, cancel))
    else:
        written = atomic_write(path, lambda tmp: _write_mp4(tmp, _frames(items), fps, crf,
                                                            cancel))
    from .ownership import record_written

    record_written(written)  # the mark alone survives a user's remux or re-encode
    return written


def _check(cancel: Cancel | None) -> None:
    if cancel is not None and cancel.cancelled:
        raise RenderCancelled("the encode was cancelled")


def ffmpeg_exe() -> str:
    """The ffmpeg that encodes MP4 films: imageio-ffmpeg's (``pip install 'whitted[film]'``),
    else an ``ffmpeg`` on the PATH. ArgumentError (one line) when there is neither."""
    try:
        import imageio_ffmpeg
    except ImportError:
        found = shutil.which("ffmpeg")
        if found is None:
            raise ArgumentError("MP4 films need ffmpeg, which is not installed: install "
                                "whitted[film] (pip install 'whitted[film]'), or write a .gif"
                                ) from None
        return found
    return imageio_ffmpeg.get_ffmpeg_exe()


def _ffmpeg_command(tmp: str, width: int, height: int, fps: float, crf: int) -> list[str]:
    rate = Fraction(fps).limit_denominator(100_000)  # exact for 24000/1001 and the like
    return [ffmpeg_exe(), "-y", "-hide_banner", "-loglevel", "error",
            "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}", "-r", str(rate),
            "-i", "-", "-an", "-vcodec", "libx264", "-pix_fmt", "yuv420p",
            "-crf", str(int(crf)), "-preset", "medium", "-movflags", "+faststart",
            "-metadata", f"comment={FILM_MARK}", "-f", "mp4", tmp]


def _write_mp4(tmp: str, frames: Iterator[np.ndarray], fps: float, crf: int,
               cancel: Cancel | None = None) -> None:
    _check(cancel)
    first = pad_to_even(next(frames))
    h, w = first.shape[:2]
    with tempfile.TemporaryFile() as log:
        # a session of its own: a terminal's Ctrl-C reaches whitted, which stops ffmpeg
        proc = subprocess.Popen(_ffmpeg_command(tmp, w, h, fps, crf), stdin=subprocess.PIPE,
                                stdout=subprocess.DEVNULL, stderr=log, start_new_session=True)
        assert proc.stdin is not None
        try:
            try:
                for frame in itertools.chain([first], (pad_to_even(f) for f in frames)):
                    _check(cancel)
                    proc.stdin.write(np.ascontiguousarray(frame).tobytes())
                proc.stdin.close()
            except BrokenPipeError:  # ffmpeg ended early: its own words say why
                pass
            while True:
                try:
                    code = proc.wait(timeout=0.1)
                    break
                except subprocess.TimeoutExpired:
                    _check(cancel)
        finally:
            if proc.poll() is None:  # cancelled, or an error on this side: stop ffmpeg
                proc.kill()
                proc.wait()
            if proc.stdin is not None and not proc.stdin.closed:
                with contextlib.suppress(OSError):
                    proc.stdin.close()
        if code != 0:
            log.seek(0)
            said = [ln for ln in log.read().decode("utf-8", "replace").splitlines() if ln.strip()]
            raise ValueError(f"ffmpeg failed (exit status {code})"
                             + (f": {said[-1].strip()}" if said else ""))
    if os.path.getsize(tmp) == 0:
        raise ValueError("ffmpeg wrote an empty film")


def _write_gif(tmp: str, frames: Iterator[np.ndarray], fps: float,
               cancel: Cancel | None = None) -> None:
    from PIL import Image as PILImage

    images = []
    for f in frames:
        _check(cancel)
        images.append(PILImage.fromarray(f).quantize(
            colors=256, method=PILImage.Quantize.MEDIANCUT, dither=PILImage.Dither.FLOYDSTEINBERG))
    duration = max(20, round(1000 / fps / 10) * 10)  # GIF delays are in 1/100 s
    images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], loop=0,
                   duration=duration, optimize=True, disposal=1, comment=FILM_MARK.encode())


def film_written_by_whitted(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a film whitted encoded: an MP4 whose metadata comment, or a GIF
    whose comment, is :data:`FILM_MARK`, with the very bytes whitted recorded when it wrote
    it (output/ownership.py). False for anything else: another file, one changed since, one
    that cannot be read, an MP4 when no ffmpeg is there to read it."""
    path = Path(path)
    try:
        if not path.is_file():
            return False
        with open(path, "rb") as f:
            head = f.read(12)
    except (OSError, ValueError):
        return False
    from .ownership import recorded_by_whitted

    # the mark and whitted's record of the very bytes: a user's edit of a film whitted made
    # (a remux, a cut, a re-encode) keeps the mark, and is the user's
    if head[:6] in (b"GIF87a", b"GIF89a"):
        return _gif_comment(path) == FILM_MARK.encode() and recorded_by_whitted(path)
    if head[4:8] != b"ftyp":  # not an MP4 (ISO base media) file: ffmpeg is not asked
        return False
    return recorded_by_whitted(path) and _mp4_comment(path) == FILM_MARK


def _gif_comment(path: Path) -> bytes | None:
    from PIL import Image as PILImage

    try:
        with PILImage.open(path) as im:
            comment = im.info.get("comment")
    except (OSError, ValueError, PILImage.DecompressionBombError):
        return None  # UnidentifiedImageError is an OSError
    return comment if isinstance(comment, bytes) else None


def _mp4_comment(path: Path) -> str | None:
    """The ``comment`` of the film's global metadata, as ffmpeg's ``ffmetadata`` dump
    gives it (None: no ffmpeg, or ffmpeg could not read the file)."""
    try:
        exe = ffmpeg_exe()
    except ArgumentError:
        return None
    command = [exe, "-nostdin", "-hide_banner", "-loglevel", "error", "-i", os.fspath(path),
               "-vn", "-an", "-sn", "-dn", "-f", "ffmetadata", "-"]
    try:
        done = subprocess.run(command, stdin=subprocess.DEVNULL, capture_output=True,
                              timeout=PROBE_SECONDS, start_new_session=True)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if done.returncode != 0:
        return None
    for line in done.stdout.decode("utf-8", "replace").splitlines():
        key, sep, value = line.partition("=")
        if sep and key == "comment":
            return value
    return None
