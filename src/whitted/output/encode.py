"""Pure encoding functions and file writers/readers for framebuffers.

The renderer hands over a float32 *linear* HDR framebuffer of shape (H, W, 3), row 0 at the
top of the picture. This module turns it into files:

* HDR formats (``.exr``, ``.pfm``, ``.npy``) always store the raw linear float32 data: no tone
  mapping, no transfer curve, NaN and infinities kept as they are.
* LDR formats (``.png``, ``.jpg``/``.jpeg``) go through tonemap -> transfer -> quantize.

Every file is written atomically (see :func:`atomic_write`): a reader never sees a partial file.
"""

from __future__ import annotations

import contextlib
import functools
import os
import pathlib
import tempfile
from collections.abc import Callable

import numpy as np

from ..errors import ArgumentError

__all__ = [
    "FORMATS",
    "HDR_FORMATS",
    "LDR_FORMATS",
    "TONEMAPS",
    "TRANSFERS",
    "atomic_write",
    "check_bit_depth",
    "check_pixels",
    "check_tonemap",
    "check_transfer",
    "encode_ldr",
    "image_format",
    "linear_to_srgb",
    "quantize",
    "read_image",
    "srgb_to_linear",
    "tonemap",
    "write_image",
]

PathLike = str | os.PathLike[str]

#: Transfer functions applied to LDR output: "srgb" (IEC 61966-2-1) or "linear" (none).
TRANSFERS: tuple[str, ...] = ("srgb", "linear")
#: Tone-mapping operators, see :func:`tonemap`.
TONEMAPS: tuple[str, ...] = ("clamp", "reinhard", "aces")
#: File extension (lower case) -> format name.
FORMATS: dict[str, str] = {
    ".png": "png",
    ".jpg": "jpeg",
    ".jpeg": "jpeg",
    ".exr": "exr",
    ".pfm": "pfm",
    ".npy": "npy",
}
HDR_FORMATS: frozenset[str] = frozenset({"exr", "pfm", "npy"})
LDR_FORMATS: frozenset[str] = frozenset({"png", "jpeg"})

JPEG_QUALITY = 95  # written with 4:4:4 chroma (no subsampling): renders have sharp colour edges
#: zlib level of PNG stills (output/png.py). Measured on renders (809x817 seed000, 800x300,
#: 400x300, with Pillow): level 4 writes in about half the time of the default 6 (34 vs 86 ms,
#: 6.9 vs 14.9 ms, 4.2 vs 11.5 ms) for files 6-25 % larger, and is both faster and smaller
#: than 3. With output/png.py's Up filter, seed000: 14.9 ms against 43.8 ms at 6 on one
#: thread, 222 KB against 205 KB. The pixels are the same at every level (zlib is lossless).
PNG_COMPRESS_LEVEL = 4

# sRGB (IEC 61966-2-1) constants.
_SRGB_LINEAR_CUTOFF = 0.0031308  # in linear light
_SRGB_ENCODED_CUTOFF = 0.04045  # in encoded values
_SRGB_SLOPE = 12.92
_SRGB_A = 0.055
_SRGB_GAMMA = 2.4

# Rec. 709 luminance weights (linear RGB).
_REC709 = (0.2126, 0.7152, 0.0722)

# Narkowicz 2015 ACES filmic fit: x(ax + b) / (x(cx + d) + e).
_ACES_A, _ACES_B, _ACES_C, _ACES_D, _ACES_E = 2.51, 0.03, 2.43, 0.59, 0.14

# Stand-in for +inf in the tone mappers: large enough to saturate, small enough not to overflow
# float64 arithmetic (x * x stays finite).
_HUGE = 1e30


# --------------------------------------------------------------------------------------------
# validation helpers


def check_transfer(name: str) -> str:
    """Return ``name`` if it is a known transfer function, else raise ValueError."""
    if name not in TRANSFERS:
        raise ArgumentError(f"unknown transfer {name!r} (use 'srgb' or 'linear')")
    return name


def check_tonemap(name: str) -> str:
    """Return ``name`` if it is a known tone-mapping mode, else raise ValueError."""
    if name not in TONEMAPS:
        raise ArgumentError(f"unknown tonemap {name!r} (use 'clamp', 'reinhard' or 'aces')")
    return name


def check_bit_depth(bit_depth: int, fmt: str | None = None) -> int:
    """Validate an output bit depth: 8, or 16 (PNG only). ``fmt`` is a format name."""
    if isinstance(bit_depth, bool) or bit_depth not in (8, 16):
        raise ArgumentError(f"bit_depth must be 8 or 16, got {bit_depth!r}")
    if bit_depth == 16 and fmt is not None and fmt != "png":
        raise ArgumentError(
            f"bit_depth=16 is only supported for .png (got {fmt} output; "
            ".exr, .pfm and .npy always store float32)"
        )
    return int(bit_depth)


def image_format(path: PathLike) -> str:
    """Format name ("png", "jpeg", "exr", "pfm", "npy") chosen by the (case-insensitive)
    extension of ``path``; ValueError for any other extension."""
    suffix = pathlib.Path(path).suffix
    try:
        return FORMATS[suffix.lower()]
    except KeyError:
        raise ArgumentError(
            f"unsupported image format '{suffix}' (use .png, .jpg, .exr, .pfm or .npy)"
        ) from None


def check_pixels(pixels: object) -> np.ndarray:
    """Return ``pixels`` as a float32 C-contiguous (H, W, 3) array (no copy when it already is
    one); ValueError for anything else (wrong shape, empty, non-numeric)."""
    try:
        arr = np.asarray(pixels)
    except (TypeError, ValueError) as exc:
        raise ArgumentError(f"pixels must be a numeric (H, W, 3) array: {exc}") from exc
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ArgumentError(
            f"pixels must be a numeric (integer or float) array, got dtype {arr.dtype}"
        )
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ArgumentError(f"pixels must have shape (H, W, 3), got {arr.shape}")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ArgumentError(f"pixels must not be empty, got shape {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float32)


# --------------------------------------------------------------------------------------------
# pure encoding functions


def _clean_unit(x: np.ndarray) -> np.ndarray:
    """float64 copy of ``x`` with NaN -> 0, clamped to [0, 1]."""
    a = np.array(x, dtype=np.float64)
    np.nan_to_num(a, copy=False, nan=0.0, posinf=1.0, neginf=0.0)
    np.clip(a, 0.0, 1.0, out=a)
    return a


def linear_to_srgb(x: np.ndarray) -> np.ndarray:
    """Encode linear values with the exact IEC 61966-2-1 sRGB curve.

    ``12.92 * x`` below 0.0031308, else ``1.055 * x ** (1/2.4) - 0.055``. The input is clamped
    to [0, 1] first and NaN is treated as 0. Evaluated in float64, returned as float32 (so 1
    maps to exactly 1).
    """
    a = _clean_unit(x)
    low = a * _SRGB_SLOPE
    high = (1.0 + _SRGB_A) * np.power(a, 1.0 / _SRGB_GAMMA) - _SRGB_A
    return np.where(a < _SRGB_LINEAR_CUTOFF, low, high).astype(np.float32)


def srgb_to_linear(x: np.ndarray) -> np.ndarray:
    """Decode sRGB-encoded values to linear light (inverse of :func:`linear_to_srgb`).

    ``x / 12.92`` up to 0.04045, else ``((x + 0.055) / 1.055) ** 2.4``. The input is clamped to
    [0, 1] first and NaN is treated as 0. Evaluated in float64, returned as float32.
    """
    a = _clean_unit(x)
    low = a / _SRGB_SLOPE
    high = np.power((a + _SRGB_A) / (1.0 + _SRGB_A), _SRGB_GAMMA)
    return np.where(a <= _SRGB_ENCODED_CUTOFF, low, high).astype(np.float32)


def _non_negative_finite(x: np.ndarray) -> np.ndarray:
    """float64 copy of ``x`` with NaN -> 0, -inf and negatives -> 0, +inf -> a huge value."""
    a = np.array(x, dtype=np.float64)
    np.nan_to_num(a, copy=False, nan=0.0, posinf=_HUGE, neginf=0.0)
    np.clip(a, 0.0, _HUGE, out=a)
    return a


def tonemap(x: np.ndarray, mode: str = "clamp") -> np.ndarray:
    """Map linear HDR values to display-referred [0, 1] (float32, same shape).

    In every mode NaN is treated as 0 and negative values as 0; +inf saturates to 1.

    * ``"clamp"`` (default): clip to [0, 1]; values above 1 are lost.
    * ``"reinhard"``: Reinhard's ``L / (1 + L)`` applied to the Rec. 709 luminance
      ``L = 0.2126 R + 0.7152 G + 0.0722 B``, keeping hue: every channel is scaled by
      ``L' / L = 1 / (1 + L)``. Grey values map [0, inf) into [0, 1) monotonically; a very
      bright saturated colour can still have one channel above 1 after the scale, which is then
      clipped to 1. Arrays whose last axis is not 3 are treated as luminance values.
    * ``"aces"``: the common Narkowicz (2015) fit of the ACES filmic curve, per channel,
      ``x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`` clipped to [0, 1] (no exposure
      pre-scale is applied). It is monotonic, maps [0, ~7.24) into [0, 1) and saturates to
      exactly 1 above x ~ 7.24, where the rational fit reaches 1.
    """
    check_tonemap(mode)
    if mode == "clamp":
        a = np.nan_to_num(np.asarray(x, dtype=np.float32), nan=0.0, posinf=1.0, neginf=0.0)
        return np.clip(a, 0.0, 1.0).astype(np.float32, copy=False)
    a = _non_negative_finite(x)
    if mode == "reinhard":
        if a.ndim >= 1 and a.shape[-1] == 3:
            lum = a[..., 0] * _REC709[0] + a[..., 1] * _REC709[1] + a[..., 2] * _REC709[2]
            out = a / (1.0 + lum)[..., None]
        else:
            out = a / (1.0 + a)
    else:  # "aces"
        out = (a * (_ACES_A * a + _ACES_B)) / (a * (_ACES_C * a + _ACES_D) + _ACES_E)
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def quantize(x: np.ndarray, bits: int) -> np.ndarray:
    """Quantize float values in [0, 1] to uint8 (``bits=8``) or uint16 (``bits=16``).

    Rounds half up, ``floor(x * maxv + 0.5)``, and clips to [0, maxv]; NaN becomes 0.
    """
    check_bit_depth(bits)
    maxv = (1 << bits) - 1
    a = np.nan_to_num(np.asarray(x, dtype=np.float64), nan=0.0, posinf=1.0, neginf=0.0)
    q = np.clip(np.floor(a * maxv + 0.5), 0, maxv)
    return q.astype(np.uint8 if bits == 8 else np.uint16)


def encode_ldr(
    pixels: np.ndarray, *, bits: int = 8, transfer: str = "srgb", tonemap: str = "clamp"
) -> np.ndarray:
    """tonemap -> transfer -> quantize: linear float pixels to uint8/uint16 display values."""
    check_transfer(transfer)
    check_tonemap(tonemap)
    check_bit_depth(bits)
    t = _apply_tonemap(pixels, tonemap)
    if transfer == "srgb" and bits == 8:
        return _srgb8(t)
    if transfer == "srgb":
        t = linear_to_srgb(t)
    return quantize(t, bits)


#: float32 values in [0, 1] are cut into this many equal buckets for the 8-bit sRGB table.
_SRGB8_BUCKETS = 1 << 16


def _srgb8_reference(t: np.ndarray) -> np.ndarray:
    return quantize(linear_to_srgb(t), 8)


@functools.cache
def _srgb8_thresholds() -> np.ndarray:
    """For each code c = 1..255: the smallest float32 in [0, 1] whose 8-bit sRGB code
    (:func:`_srgb8_reference`) is at least c. The code is monotone in the value, so one
    bisection over the float32 bit patterns of [0, 1] finds all 255 at once (31 steps)."""
    target = np.arange(1, 256)
    lo = np.zeros(255, np.int64)  # code(0.0) = 0 < c
    hi = np.full(255, np.float32(1.0).view(np.uint32), np.int64)  # code(1.0) = 255 >= c
    while np.any(hi - lo > 1):
        mid = (lo + hi) // 2
        reached = _srgb8_reference(mid.astype(np.uint32).view(np.float32)) >= target
        hi = np.where(reached, mid, hi)
        lo = np.where(reached, lo, mid)
    return hi.astype(np.uint32).view(np.float32)


@functools.cache
def _srgb8_table() -> tuple[np.ndarray, np.ndarray]:
    """For each bucket [k, k+1) / 65536 of [0, 1]: the 8-bit sRGB code at its start, and the
    smallest float32 in it whose code is one more (+inf when there is none). Consecutive
    codes are at least 3e-4 apart in linear light (the curve's steepest slope, 12.92, at 0),
    wider than a bucket (1.5e-5): a bucket holds at most one step, so the table gives exactly
    :func:`_srgb8_reference`'s codes. Built from the 255 thresholds (1 ms), not by
    evaluating the curve at every bucket (13 ms of every process that wrote a PNG)."""
    n = _SRGB8_BUCKETS
    starts = (np.arange(n + 1, dtype=np.float64) / n).astype(np.float32)
    thresholds = _srgb8_thresholds()
    code = np.searchsorted(thresholds, starts, side="right").astype(np.uint8)
    step = np.full(n + 1, np.inf, np.float32)
    nxt = np.append(thresholds, np.float32(np.inf))[code]  # where the next code begins
    inside = np.flatnonzero(nxt[:-1] < starts[1:])  # ... before the bucket's end
    step[inside] = nxt[inside]
    return code, step


def _srgb8(t: np.ndarray) -> np.ndarray:
    """8-bit sRGB codes of tonemapped values (float32 in [0, 1]) by table look-up: the same
    codes as ``quantize(linear_to_srgb(t), 8)`` at a fraction of the cost (no float64
    power per value)."""
    code, step = _srgb8_table()
    x = np.asarray(t, dtype=np.float32)
    index = (x * np.float32(_SRGB8_BUCKETS)).astype(np.int32)  # exact: scaled by 2**16
    out = code[index]
    out += x >= step[index]
    return out


_apply_tonemap = tonemap  # the name ``tonemap`` is shadowed by keyword parameters below


# --------------------------------------------------------------------------------------------
# atomic writing


def _current_umask() -> int:
    """The process umask, read without changing it where the platform allows."""
    with contextlib.suppress(OSError, ValueError), open("/proc/self/status") as f:
        for line in f:
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(directory: pathlib.Path) -> None:
    if os.name == "nt":
        return
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _temp_prefix(target: pathlib.Path) -> str:
    """Start of the names of ``target``'s temporary files (the name cut so that a temporary
    name stays within the 255-byte limit of file names)."""
    name = target.name
    while len(os.fsencode(name)) > 160:
        name = name[: len(name) * 3 // 4]
    return f".{name}.tmp-"


def _process_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # someone else's live process
    return True


def remove_stale_temporaries(path: PathLike) -> list[pathlib.Path]:
    """Delete the temporary files that writes of ``path`` left behind when their process was
    killed (their names carry the writer's process id; a live writer's file is kept).
    Returns the files removed."""
    target = pathlib.Path(path)
    prefix = _temp_prefix(target)
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    for entry in entries:
        if not (entry.name.startswith(prefix) and entry.name.endswith(target.suffix)):
            continue
        pid_text = entry.name[len(prefix):].split(".", 1)[0]
        if not pid_text.isdigit() or _process_alive(int(pid_text)):
            continue
        with contextlib.suppress(OSError):
            os.unlink(entry.path)
            removed.append(pathlib.Path(entry.path))
    return removed


def atomic_write(path: PathLike, write_fn: Callable[[str], object]) -> pathlib.Path:
    """Write a file atomically: ``path`` either keeps its old content or gets the complete new one.

    ``write_fn(tmp_path)`` is called with the path (str) of a fresh temporary file created with
    :func:`tempfile.mkstemp` in the same directory as ``path`` and with the same suffix, so a
    writer that picks its format from the extension still works. The temporary file is then
    fsynced, given the permissions of the file it replaces (or the umask default for a new
    file) and moved onto ``path`` with :func:`os.replace`. If anything raises, the temporary
    file is removed and the exception propagates. The temporary file's name carries the process
    id, so that temporary files of a writer that was killed (``kill -9``) are recognised and
    removed by the next write of the same path. Returns ``path`` as a :class:`pathlib.Path`.
    """
    target = pathlib.Path(path)
    directory = target.parent
    prefix = _temp_prefix(target)
    remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(suffix=target.suffix, prefix=f"{prefix}{os.getpid()}.",
                               dir=directory)
    os.close(fd)
    try:
        write_fn(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        try:
            mode = os.stat(target).st_mode & 0o7777
        except OSError:
            mode = 0o666 & ~_current_umask()
        with contextlib.suppress(OSError):
            os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(directory)
    return target


# --------------------------------------------------------------------------------------------
# writers (each takes the temporary path and already-encoded data)


#: Rows encoded at a time: the tonemap/transfer/quantize steps work in float64, so they run
#: on strips of rows and an 8-bit image costs a few bytes per pixel beyond its framebuffer.
STRIP_PIXELS = 1 << 16


def _strips(height: int, width: int):
    rows = max(1, STRIP_PIXELS // max(1, width))
    for y in range(0, height, rows):
        yield y, min(height, y + rows)


def _encoded_strips(pixels: np.ndarray, bits: int, transfer: str, tonemap: str):
    """(first row, encoded uint8/uint16 rows) for consecutive strips of ``pixels``."""
    for y0, y1 in _strips(pixels.shape[0], pixels.shape[1]):
        yield y0, encode_ldr(pixels[y0:y1], bits=bits, transfer=transfer, tonemap=tonemap)


def _pil_rgb(pixels: np.ndarray, transfer: str, tonemap: str):
    """A Pillow RGB image filled strip by strip (no full-size float64 or uint8 copy)."""
    from PIL import Image as PILImage

    h, w, _ = pixels.shape
    image = PILImage.new("RGB", (w, h))
    for y0, strip in _encoded_strips(pixels, 8, transfer, tonemap):
        image.paste(PILImage.fromarray(strip), (0, y0))
    return image


def _write_png(tmp: str, pixels: np.ndarray, transfer: str, tonemap: str, bits: int) -> None:
    from .png import write_png

    h, w, _ = pixels.shape

    def encode_rows(y0: int, y1: int) -> np.ndarray:  # in strips: no whole-unit float64
        rows = np.empty((y1 - y0, w, 3), np.uint8 if bits == 8 else np.uint16)
        for a, b in _strips(y1 - y0, w):
            rows[a:b] = encode_ldr(pixels[y0 + a:y0 + b], bits=bits, transfer=transfer,
                                   tonemap=tonemap)
        return rows

    with open(tmp, "wb") as f:
        write_png(f, h, w, bits, encode_rows, PNG_COMPRESS_LEVEL)


def _write_jpeg(tmp: str, pixels: np.ndarray, transfer: str, tonemap: str) -> None:
    _pil_rgb(pixels, transfer, tonemap).save(tmp, format="JPEG", quality=JPEG_QUALITY,
                                             subsampling=0)


def _write_exr(tmp: str, data: np.ndarray) -> None:
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": data}).write(tmp)


def _write_pfm(tmp: str, data: np.ndarray) -> None:
    h, w, _ = data.shape
    with open(tmp, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode("ascii"))
        # PFM stores scanlines bottom-to-top; a negative scale means little-endian.
        for y0, y1 in _strips(h, w):  # bottom strip first, each flipped: no full-size copy
            f.write(np.ascontiguousarray(data[h - y1:h - y0][::-1], dtype="<f4").tobytes())


def _write_npy(tmp: str, data: np.ndarray) -> None:
    # A file object, not a path: np.save would append ".npy" to a path ending in ".NPY".
    with open(tmp, "wb") as f:
        np.save(f, data, allow_pickle=False)


def write_image(
    path: PathLike,
    pixels: np.ndarray,
    *,
    bit_depth: int = 8,
    transfer: str = "srgb",
    tonemap: str = "clamp",
) -> pathlib.Path:
    """Write linear float pixels (H, W, 3) to ``path`` atomically, format by extension.

    ``.exr`` / ``.pfm`` / ``.npy`` get the raw linear float32 data (``transfer`` and
    ``tonemap`` are ignored); ``.png`` (8 or 16-bit, encoded on threads: output/png.py) and
    ``.jpg``/``.jpeg`` (8-bit, quality 95) get tonemap -> transfer -> quantize. Everything is
    validated before the disk is touched. Returns ``path`` as a :class:`pathlib.Path`.
    """
    fmt = image_format(path)
    check_transfer(transfer)
    check_tonemap(tonemap)
    check_bit_depth(bit_depth, fmt)
    data = check_pixels(pixels)

    if fmt in HDR_FORMATS:
        writer = {"exr": _write_exr, "pfm": _write_pfm, "npy": _write_npy}[fmt]
        return atomic_write(path, lambda tmp: writer(tmp, data))
    if fmt == "jpeg":
        return atomic_write(path, lambda tmp: _write_jpeg(tmp, data, transfer, tonemap))
    return atomic_write(path, lambda tmp: _write_png(tmp, data, transfer, tonemap, bit_depth))


# --------------------------------------------------------------------------------------------
# readers


def _to_rgb(arr: np.ndarray, source: object) -> np.ndarray:
    """(H, W), (H, W, 1), (H, W, 2) grey+alpha, (H, W, 3) or (H, W, 4) -> (H, W, 3)."""
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"{source}: cannot use image data of shape {arr.shape} as RGB")
    if arr.shape[2] in (1, 2):
        arr = np.repeat(arr[:, :, :1], 3, axis=2)
    return np.ascontiguousarray(arr[:, :, :3], dtype=np.float32)


def _read_exr(path: str) -> np.ndarray:
    import OpenEXR

    f = OpenEXR.File(path, separate_channels=True)
    channels = {name: np.asarray(ch.pixels) for name, ch in f.channels().items()}
    if all(c in channels for c in "RGB"):
        arr = np.stack([channels["R"], channels["G"], channels["B"]], axis=-1)
    elif "Y" in channels:
        arr = channels["Y"]
    elif len(channels) == 1:
        arr = next(iter(channels.values()))
    else:
        raise ValueError(f"{path}: no R, G, B or Y channels in EXR (has {sorted(channels)})")
    return _to_rgb(arr.astype(np.float32), path)


def _read_pfm(path: str) -> np.ndarray:
    with open(path, "rb") as f:
        raw = f.read()
    tokens: list[bytes] = []
    pos = 0
    while len(tokens) < 4:
        while pos < len(raw) and raw[pos : pos + 1].isspace():
            pos += 1
        start = pos
        while pos < len(raw) and not raw[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise ValueError(f"{path}: truncated PFM header")
        tokens.append(raw[start:pos])
    pos += 1  # exactly one whitespace character ends the header
    magic = tokens[0]
    if magic not in (b"PF", b"Pf"):
        raise ValueError(f"{path}: not a PFM file (magic {magic!r})")
    try:
        width, height, scale = int(tokens[1]), int(tokens[2]), float(tokens[3])
    except ValueError:
        raise ValueError(f"{path}: bad PFM header {b' '.join(tokens)!r}") from None
    if width <= 0 or height <= 0 or scale == 0.0:
        raise ValueError(f"{path}: bad PFM header {b' '.join(tokens)!r}")
    nchan = 3 if magic == b"PF" else 1
    count = width * height * nchan
    dtype = "<f4" if scale < 0 else ">f4"
    if len(raw) - pos < count * 4:
        raise ValueError(f"{path}: truncated PFM data")
    arr = np.frombuffer(raw, dtype=dtype, count=count, offset=pos)
    arr = arr.reshape(height, width, nchan)[::-1]  # stored bottom-to-top
    return _to_rgb(arr.astype(np.float32), path)


def _read_npy(path: str) -> np.ndarray:
    arr = np.load(path, allow_pickle=False)
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ValueError(f"{path}: not a numeric array (dtype {arr.dtype})")
    return _to_rgb(arr, path)


def _read_png(path: str) -> np.ndarray:
    with open(path, "rb") as f:
        head = f.read(26)
    # IHDR is the first chunk: signature (8), length (4), "IHDR" (4), width, height, bit depth.
    if len(head) < 26 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise ValueError(f"{path}: not a PNG file")
    if head[24] == 16:
        # Pillow cannot give 16-bit RGB, so 16-bit files go through pypng.
        import png

        with open(path, "rb") as f:
            width, height, rows, info = png.Reader(file=f).asDirect()
            arr = np.vstack([np.asarray(row, dtype=np.float32) for row in rows])
        arr = arr.reshape(height, width, info["planes"]) / np.float32(65535.0)
        return _to_rgb(arr, path)
    return _read_pillow(path)


def _read_pillow(path: str) -> np.ndarray:
    """8-bit (or lower) PNG or JPEG of any colour type, as float32 RGB in [0, 1]."""
    from PIL import Image as PILImage

    with PILImage.open(path) as im:
        arr = np.asarray(im.convert("RGB"), dtype=np.float32) / np.float32(255.0)
    return _to_rgb(arr, path)


def read_image(path: PathLike, *, transfer: str = "srgb") -> np.ndarray:
    """Read an image file as a float32 (H, W, 3) linear array, row 0 at the top.

    ``.exr``, ``.pfm`` and ``.npy`` are returned as stored. ``.png`` (8- or 16-bit, any colour
    type) and ``.jpg``/``.jpeg`` are normalised to [0, 1] and decoded with ``transfer``: the
    sRGB curve by default, or ``"linear"`` for files holding linear data (e.g. written with
    ``transfer="linear"``). Grey images are expanded to RGB and alpha is dropped.
    """
    check_transfer(transfer)
    fmt = image_format(path)
    p = os.fspath(path)
    from ..assets.files import path_problem

    problem = path_problem(p)
    if problem is not None:  # only regular files: a pipe or a device would hang or never end
        raise ArgumentError(f"{p}: {problem}")
    if fmt == "exr":
        return _read_exr(p)
    if fmt == "pfm":
        return _read_pfm(p)
    if fmt == "npy":
        return _read_npy(p)
    arr = _read_png(p) if fmt == "png" else _read_pillow(p)
    if transfer == "srgb":
        arr = srgb_to_linear(arr)
    return arr
