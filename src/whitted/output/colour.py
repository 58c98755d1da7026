"""Colour of a framebuffer on its way to an 8 or 16-bit file: tone mapping (clamp, Reinhard,
ACES), the sRGB transfer curve and its inverse, quantisation, and the checks of a pixel array.
Pure NumPy functions; the files themselves are :mod:`.formats`."""

from __future__ import annotations

import functools

import numpy as np

from ..errors import ArgumentError

#: Transfer functions applied to LDR output: "srgb" (IEC 61966-2-1) or "linear" (none).
TRANSFERS: tuple[str, ...] = ("srgb", "linear")
#: Tone-mapping operators, see :func:`tonemap`.
TONEMAPS: tuple[str, ...] = ("clamp", "reinhard", "aces")
#: File extension (lower case) -> format name.

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
