"""Texture lookup: the linear RGB colour of texture ``k`` at surface coordinates (u, v).

The table layout is in ``texture_layout.py``. Conventions:

- Placement first: ``(u', v') = M·(u, v) + offset`` with ``M = R(rotation)·diag(scale)``.
- Images: ``v = 0`` is the BOTTOM of the image and ``v = 1`` its top (OBJ / OpenGL); texel
  centres lie at ``u' = (col + 0.5) / W`` and ``v' = 1 - (row + 0.5) / H`` (row 0 = top row).
  In texel space ``x = u'·W - 0.5``, ``y = (1 - v')·H - 0.5``; bilinear blends the four texels
  around (x, y), nearest takes the texel that contains (u', v'). ``repeat`` tiles the image
  with period 1 in u' and v' (negative coordinates too); ``clamp`` extends the edge texels.
- Checker: ``color1`` where ``floor(u'·checks) + floor(v'·checks)`` is even, else ``color2``.
- Gradient: ``color1·(1 - t) + color2·t`` with ``t = clamp(u' or v', 0, 1)``.

Any finite (u, v) gives a colour from the texture and never reads outside it. Coordinates that
are not finite after placement (NaN, or overflow to infinity) give ``color1`` for checkers and
the first stored texel (top-left) for images; gradients clamp infinities and treat NaN as 0.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .texture_layout import (
    AXIS_U,
    FILTER_NEAREST,
    TEX_AXIS,
    TEX_CHECKER,
    TEX_CHECKS,
    TEX_COLOR1,
    TEX_COLOR2,
    TEX_FILTER,
    TEX_GRADIENT,
    TEX_HEIGHT,
    TEX_IMAGE,
    TEX_KIND,
    TEX_MATRIX,
    TEX_OFFSET,
    TEX_PIXEL_OFFSET,
    TEX_WIDTH,
    TEX_WRAP,
    WRAP_CLAMP,
)


@kernel
def _unit_coordinate(t, wrap):
    """A finite texture coordinate brought into [0, 1]: its fractional part (repeat, period 1)
    or clamped (clamp). Both keep every later texel index small, whatever the size of t.

    (``np.floor`` throughout: Numba's ``math.floor`` returns an int64, which overflows.)"""
    if wrap == WRAP_CLAMP:
        return min(max(t, 0.0), 1.0)
    # t - floor(t) is in [0, 1), except that it rounds up to 1.0 for tiny negative t
    return min(t - np.floor(t), 1.0)


@kernel
def _texel_index(i, n, wrap):
    """Texel index i (may be -1 or n) made valid for a row or column of n texels."""
    if wrap == WRAP_CLAMP:
        return min(max(i, 0), n - 1)
    r = i % n
    if r < 0:
        r += n
    return r


@kernel
def _texel(tex_pixels, base, width, row, col):
    i = base + 3 * (row * width + col)
    return (float(tex_pixels[i]), float(tex_pixels[i + 1]), float(tex_pixels[i + 2]))


@kernel
def _lerp3(a, b, t):
    s = 1.0 - t
    return (a[0] * s + b[0] * t, a[1] * s + b[1] * t, a[2] * s + b[2] * t)


@kernel
def _image_color(tex_info, tex_pixels, k, us, vs):
    width = int(tex_info[k, TEX_WIDTH])
    height = int(tex_info[k, TEX_HEIGHT])
    base = int(tex_info[k, TEX_PIXEL_OFFSET])
    wrap = int(tex_info[k, TEX_WRAP])
    if not (math.isfinite(us) and math.isfinite(vs)):
        return _texel(tex_pixels, base, width, 0, 0)
    s = _unit_coordinate(us, wrap)
    t = 1.0 - _unit_coordinate(vs, wrap)  # measured down from the top row
    if int(tex_info[k, TEX_FILTER]) == FILTER_NEAREST:
        col = _texel_index(int(np.floor(s * width)), width, wrap)
        row = _texel_index(int(np.floor(t * height)), height, wrap)
        return _texel(tex_pixels, base, width, row, col)
    x = s * width - 0.5
    y = t * height - 0.5
    x_floor = np.floor(x)
    y_floor = np.floor(y)
    fx = x - x_floor
    fy = y - y_floor
    col0 = _texel_index(int(x_floor), width, wrap)
    col1 = _texel_index(int(x_floor) + 1, width, wrap)
    row0 = _texel_index(int(y_floor), height, wrap)
    row1 = _texel_index(int(y_floor) + 1, height, wrap)
    upper = _lerp3(
        _texel(tex_pixels, base, width, row0, col0),
        _texel(tex_pixels, base, width, row0, col1),
        fx,
    )
    lower = _lerp3(
        _texel(tex_pixels, base, width, row1, col0),
        _texel(tex_pixels, base, width, row1, col1),
        fx,
    )
    return _lerp3(upper, lower, fy)


@kernel
def _parity(f):
    """0.0 for an even integer-valued float, 1.0 for an odd one (exact for any finite f)."""
    return f - 2.0 * np.floor(f * 0.5)


@kernel
def _color(tex_info, k, column):
    return (tex_info[k, column], tex_info[k, column + 1], tex_info[k, column + 2])


@kernel
def texture_color(tex_info, tex_pixels, k, u, v):
    """Linear RGB (r, g, b) of texture row ``k`` of ``tex_info`` at surface coordinates (u, v)."""
    us = tex_info[k, TEX_MATRIX] * u + tex_info[k, TEX_MATRIX + 1] * v + tex_info[k, TEX_OFFSET]
    vs = (
        tex_info[k, TEX_MATRIX + 2] * u
        + tex_info[k, TEX_MATRIX + 3] * v
        + tex_info[k, TEX_OFFSET + 1]
    )
    kind = int(tex_info[k, TEX_KIND])
    if kind == TEX_IMAGE:
        return _image_color(tex_info, tex_pixels, k, us, vs)
    if kind == TEX_CHECKER:
        checks = tex_info[k, TEX_CHECKS]
        a = us * checks
        b = vs * checks
        if not (math.isfinite(a) and math.isfinite(b)):
            return _color(tex_info, k, TEX_COLOR1)
        if _parity(np.floor(a)) != _parity(np.floor(b)):
            return _color(tex_info, k, TEX_COLOR2)
        return _color(tex_info, k, TEX_COLOR1)
    if kind == TEX_GRADIENT:
        t = us if int(tex_info[k, TEX_AXIS]) == AXIS_U else vs
        if t != t:
            t = 0.0
        t = min(max(t, 0.0), 1.0)
        return _lerp3(_color(tex_info, k, TEX_COLOR1), _color(tex_info, k, TEX_COLOR2), t)
    return (1.0, 1.0, 1.0)
