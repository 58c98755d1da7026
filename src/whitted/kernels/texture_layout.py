"""The flat texture table written by ``compile/textures.py`` and read by ``kernels/texture.py``.

``tex_info[k]`` (float64, ``N_TEX_PARAMS`` columns) describes texture ``k``; ``tex_pixels``
(float32, 1-D) holds the linear RGB texels of every image texture, one image after another,
each stored row-major with row 0 at the TOP of the image: texel (row, col) of texture ``k`` is
``tex_pixels[o + 3*(row*W + col) : o + 3*(row*W + col) + 3]`` with ``o = tex_info[k,
TEX_PIXEL_OFFSET]``. Integer-valued columns (kind, sizes, offsets, codes) are stored as exact
float64 integers.

Placement (every kind): ``(u', v') = M·(u, v) + offset`` with the row-major 2x2 matrix
``M = R(rotation)·diag(scale)`` in ``TEX_MATRIX`` (m00, m01, m10, m11) and the offset in
``TEX_OFFSET``.
"""

from __future__ import annotations

# texture kinds (column TEX_KIND)
TEX_IMAGE = 0
TEX_CHECKER = 1
TEX_GRADIENT = 2

# columns of tex_info
TEX_KIND = 0
TEX_MATRIX = 1  # 1:5, M = R(rotation)·diag(scale) row-major: m00, m01, m10, m11
TEX_OFFSET = 5  # 5:7, (offset u, offset v)
TEX_COLOR1 = 7  # 7:10, checker / gradient: linear RGB colour 1
TEX_COLOR2 = 10  # 10:13, checker / gradient: linear RGB colour 2
TEX_CHECKS = 13  # checker: squares per unit of u' and v'
TEX_AXIS = 14  # gradient: 0 along u', 1 along v'
TEX_WIDTH = 15  # image: W texels
TEX_HEIGHT = 16  # image: H texels
TEX_PIXEL_OFFSET = 17  # image: index in tex_pixels of the first float of the image
TEX_WRAP = 18  # image: WRAP_REPEAT or WRAP_CLAMP
TEX_FILTER = 19  # image: FILTER_BILINEAR or FILTER_NEAREST

N_TEX_PARAMS = 20

WRAP_REPEAT = 0
WRAP_CLAMP = 1
FILTER_BILINEAR = 0
FILTER_NEAREST = 1
AXIS_U = 0
AXIS_V = 1

WRAP_CODES = {"repeat": WRAP_REPEAT, "clamp": WRAP_CLAMP}
FILTER_CODES = {"bilinear": FILTER_BILINEAR, "nearest": FILTER_NEAREST}
AXIS_CODES = {"u": AXIS_U, "v": AXIS_V}
