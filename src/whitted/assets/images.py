"""Image files as linear RGB float32 arrays (texture maps).

:func:`load_image` decodes anything Pillow reads (PNG, JPEG, BMP, TGA, TIFF, GIF, WebP, ...):
8- and 16-bit, grey, palette, grey+alpha and RGBA (alpha is dropped) all become RGB. 16-bit PNGs
are read with pypng, because Pillow reduces 16-bit colour PNGs to 8 bits. ``colorspace="srgb"``
decodes with the exact IEC 61966-2-1 curve, ``"linear"`` only scales to [0, 1]; float images
(Pillow mode ``F``) are taken as already scaled to [0, 1].

Decoded images are kept in an in-process cache keyed by (resolved path, mtime_ns, size,
colorspace), so a scene that uses one image many times (or is rendered again) reads it once. A
changed file has a new key and is read again.
"""

from __future__ import annotations

import io
import os
import threading
import warnings
from collections import OrderedDict
from pathlib import Path

import numpy as np
import png
from PIL import Image, ImageOps, UnidentifiedImageError

from ..errors import SceneError

COLORSPACES = ("srgb", "linear")
#: Largest texture image decoded (8192 x 8192): checked from the file's header, before the
#: pixels are decoded, whatever the bit depth (a decoded pixel costs up to 20 bytes).
MAX_TEXTURE_PIXELS = 1 << 26
#: Largest image file read.
MAX_IMAGE_BYTES = 1 << 30
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_CACHE_ENTRIES = 32

_cache: OrderedDict[tuple[str, int, int, str], np.ndarray] = OrderedDict()
_cache_lock = threading.Lock()
_srgb_tables: dict[int, np.ndarray] = {}


def srgb_to_linear(values: np.ndarray | float) -> np.ndarray:
    """The IEC 61966-2-1 sRGB decoding of values in [0, 1] (float64, same shape)."""
    c = np.asarray(values, dtype=np.float64)
    low = c / 12.92
    high = ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4
    return np.where(c <= 0.04045, low, high)


def _srgb_table(levels: int) -> np.ndarray:
    """Lookup table: integer code 0..levels-1 -> linear float32 (256 or 65536 entries)."""
    table = _srgb_tables.get(levels)
    if table is None:
        table = srgb_to_linear(np.arange(levels) / (levels - 1)).astype(np.float32)
        _srgb_tables[levels] = table
    return table


def clear_image_cache() -> None:
    """Forget every decoded image."""
    with _cache_lock:
        _cache.clear()


def load_image(path: str | os.PathLike[str], colorspace: str = "srgb") -> np.ndarray:
    """The image at ``path`` as an (H, W, 3) float32 linear RGB array, row 0 = top of the image.

    ``colorspace`` is ``"srgb"`` (decode the sRGB curve) or ``"linear"`` (values as stored).
    The array is shared with the cache and read-only. Raises :class:`SceneError` (one line,
    naming the file) when the file is missing, is not an image or cannot be decoded.
    """
    if colorspace not in COLORSPACES:
        from ..errors import ArgumentError

        raise ArgumentError(f"colorspace must be one of {COLORSPACES}, not {colorspace!r}")
    name = str(path)
    try:
        resolved = Path(path).resolve()
        status = resolved.stat()
    except FileNotFoundError:
        raise SceneError("image file not found", file=name) from None
    except OSError as exc:
        raise SceneError(f"cannot read image file: {_one_line(exc)}", file=name) from None
    from ..files import kind_of

    kind = kind_of(status.st_mode)
    if kind is not None:
        raise SceneError(f"is {kind}, not an image file", file=name)

    key = (str(resolved), status.st_mtime_ns, status.st_size, colorspace)
    with _cache_lock:
        pixels = _cache.get(key)
        if pixels is not None:
            _cache.move_to_end(key)
            return pixels

    from ..files import read_limited

    data = read_limited(resolved, MAX_IMAGE_BYTES, "image file", name)
    pixels = _decode(data, colorspace, name)
    pixels.setflags(write=False)

    with _cache_lock:
        for old in [k for k in _cache if k[0] == key[0] and k[3] == colorspace]:
            del _cache[old]  # an earlier version of the same file
        _cache[key] = pixels
        while len(_cache) > _CACHE_ENTRIES:
            _cache.popitem(last=False)
    return pixels


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(getattr(exc, "strerror", None) or exc).split())
    return text or type(exc).__name__


def _decode(data: bytes, colorspace: str, name: str) -> np.ndarray:
    """Decode file bytes into (H, W, 3) float32 linear RGB."""
    try:
        if data[:8] == _PNG_SIGNATURE and len(data) > 24:
            # IHDR is the first chunk: width and height before any pixel is decoded
            _check_size(int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big"),
                        name)
        if data[:8] == _PNG_SIGNATURE and len(data) > 24 and data[24] == 16:
            codes, levels = _read_png16(data)
        else:
            codes, levels = _read_with_pillow(data, name)
    except SceneError:
        raise
    except UnidentifiedImageError:
        raise SceneError("not an image, or a format that cannot be read", file=name) from None
    except Image.DecompressionBombError as exc:
        raise SceneError(f"image too large: {_one_line(exc)}", file=name) from None
    except Exception as exc:  # noqa: BLE001 - any failure to decode is a corrupt file
        raise SceneError(
            f"corrupt or unreadable image ({type(exc).__name__}: {_one_line(exc)})", file=name
        ) from None
    if codes.size == 0:
        raise SceneError("image has no pixels", file=name)

    if codes.ndim == 2:
        codes = codes[:, :, None]
    if codes.shape[2] < 3:  # grey (alpha already dropped): the same value in R, G and B
        codes = codes[:, :, :1]

    if levels and colorspace == "srgb":
        rgb = _srgb_table(levels)[codes]
    elif levels:
        rgb = codes.astype(np.float32) / np.float32(levels - 1)
    else:  # float data, already in [0, 1]
        values = np.nan_to_num(codes.astype(np.float64), nan=0.0, posinf=1.0, neginf=0.0)
        rgb = srgb_to_linear(values) if colorspace == "srgb" else values
    rgb = np.asarray(rgb, dtype=np.float32)
    if rgb.shape[2] == 1:
        rgb = np.repeat(rgb, 3, axis=2)
    return np.ascontiguousarray(rgb[:, :, :3])


def _read_png16(data: bytes) -> tuple[np.ndarray, int]:
    """A 16-bit PNG as uint16 codes (H, W, 1 or 3), alpha dropped."""
    width, height, rows, info = png.Reader(bytes=data).asDirect()
    planes = info["planes"]
    codes = np.vstack([np.asarray(row, dtype=np.uint16) for row in rows])
    codes = codes.reshape(height, width, planes)
    colour_planes = 1 if info["greyscale"] else 3
    return codes[:, :, :colour_planes], 65536


def _check_size(width: int, height: int, name: str) -> None:
    if width * height > MAX_TEXTURE_PIXELS:
        raise SceneError(f"image too large: {width}x{height} pixels (the limit is "
                         f"{MAX_TEXTURE_PIXELS:,} pixels, 8192x8192)", file=name)


def _read_with_pillow(data: bytes, name: str = "image") -> tuple[np.ndarray, int]:
    """Integer codes and their number of levels (256 or 65536), or float data with levels 0."""
    with warnings.catch_warnings():
        # the size is checked below, against a limit under Pillow's own warning threshold
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        opened = Image.open(io.BytesIO(data))
    with opened:
        _check_size(opened.size[0], opened.size[1], name)
        opened.load()
        image = ImageOps.exif_transpose(opened)  # photos stored sideways, shown upright
        mode = image.mode
        if mode.startswith("I;16"):
            return np.asarray(image).astype(np.uint16), 65536
        if mode == "I":  # 32-bit integer grey: Pillow's form of 16-bit grey from some formats
            return np.clip(np.asarray(image), 0, 65535).astype(np.uint16), 65536
        if mode == "F":
            return np.asarray(image, dtype=np.float32), 0
        if mode in ("L", "LA", "La"):
            return np.asarray(image.convert("L"), dtype=np.uint8), 256
        return np.asarray(image.convert("RGB"), dtype=np.uint8), 256
