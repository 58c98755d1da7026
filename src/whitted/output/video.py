"""Films from frames: H.264 MP4 through imageio-ffmpeg's own ffmpeg, and GIF through Pillow.

No ffmpeg needs to be installed: imageio-ffmpeg ships a static one. MP4 files are H.264,
yuv420p (what every player plays), quality by an explicit CRF (18: visually lossless for
renders), with the index at the front (``+faststart``) so a browser starts playing before
the whole file has arrived. yuv420p needs even sizes: an odd width or height gets one more
column or row, a copy of the last one (the picture is never scaled). Files are written
atomically, as every output of whitted.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from ..files import atomic_write

__all__ = ["DEFAULT_CRF", "VIDEO_FORMATS", "encode_film", "even_size", "pad_to_even",
           "video_format"]

DEFAULT_CRF = 18
VIDEO_FORMATS = {".mp4": "mp4", ".gif": "gif"}


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
) -> Path:
    """Encode ``frames`` (PNG file names or (H, W, 3) uint8 arrays, all one size) into the
    film ``path``: ``.mp4`` (H.264, yuv420p, ``crf``, +faststart) or ``.gif`` (looping,
    an adaptive 256-colour palette per frame). Written atomically; returns ``path``."""
    fmt = video_format(path)
    if not fps > 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    items = list(frames)
    if not items:
        raise ValueError("no frames to encode")
    if fmt == "gif":
        return atomic_write(path, lambda tmp: _write_gif(tmp, _frames(items), fps))
    return atomic_write(path, lambda tmp: _write_mp4(tmp, _frames(items), fps, crf))


def _write_mp4(tmp: str, frames: Iterator[np.ndarray], fps: float, crf: int) -> None:
    import imageio_ffmpeg

    first = pad_to_even(next(frames))
    h, w = first.shape[:2]
    writer = imageio_ffmpeg.write_frames(
        tmp, (w, h), fps=fps, codec="libx264", pix_fmt_in="rgb24", pix_fmt_out="yuv420p",
        quality=None, macro_block_size=1,  # never scaled to a multiple of 16
        output_params=["-crf", str(int(crf)), "-preset", "medium", "-movflags", "+faststart",
                       "-f", "mp4"],
        ffmpeg_log_level="error",
    )
    writer.send(None)  # start ffmpeg
    try:
        writer.send(np.ascontiguousarray(first))
        for frame in frames:
            writer.send(np.ascontiguousarray(pad_to_even(frame)))
    finally:
        writer.close()


def _write_gif(tmp: str, frames: Iterator[np.ndarray], fps: float) -> None:
    from PIL import Image as PILImage

    images = [PILImage.fromarray(f).quantize(colors=256, method=PILImage.Quantize.MEDIANCUT,
                                             dither=PILImage.Dither.FLOYDSTEINBERG)
              for f in frames]
    duration = max(20, round(1000 / fps / 10) * 10)  # GIF delays are in 1/100 s
    images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], loop=0,
                   duration=duration, optimize=True, disposal=1)
