"""Scene textures -> the flat texture table the kernels read (``kernels/texture_layout.py``).

The caller collects the distinct textures of the scene's materials in a list and refers to
them by their position; row ``k`` of ``tex_info`` is ``textures[k]``. Image files are decoded
by :func:`whitted.assets.load_image` (cached) and concatenated into one float32 array; the same
file with the same colorspace is stored once however many textures use it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..kernels.texture_layout import (
    AXIS_CODES,
    FILTER_CODES,
    N_TEX_PARAMS,
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
    WRAP_CODES,
)
from ..scene.textures import CheckerTexture, GradientTexture, ImageTexture, Texture


class TextureArrays(NamedTuple):
    """The texture table: never empty, so the kernels always get arrays of the same types."""

    tex_info: np.ndarray  # (K, N_TEX_PARAMS) float64, one row per texture
    tex_pixels: np.ndarray  # (P,) float32 linear RGB texels of all images, row 0 = image top


def placement_matrix(scale: Sequence[float], rotation_degrees: float) -> np.ndarray:
    """``R(rotation)·diag(scale)`` as a 2x2 array; quarter turns are exact (no 6e-17 residue)."""
    turns = rotation_degrees / 90.0
    if turns == math.floor(turns):
        cos_sin = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(turns % 4)]
        c, s = cos_sin
    else:
        angle = math.radians(rotation_degrees)
        c, s = math.cos(angle), math.sin(angle)
    su, sv = scale
    return np.array([[c * su, -s * sv], [s * su, c * sv]], dtype=np.float64)


def compile_textures(
    textures: Sequence[Texture], resolve: Callable[[str], Path]
) -> TextureArrays:
    """One ``tex_info`` row per texture, in list order; ``resolve`` maps an image texture's
    ``file`` to the path to read. Unreadable images raise :class:`whitted.errors.SceneError`.
    An empty list gives one placeholder row (a white gradient) and one white texel."""
    if not textures:
        info = np.zeros((1, N_TEX_PARAMS), dtype=np.float64)
        info[0, TEX_KIND] = TEX_GRADIENT
        info[0, TEX_MATRIX : TEX_MATRIX + 4] = (1.0, 0.0, 0.0, 1.0)
        info[0, TEX_COLOR1 : TEX_COLOR1 + 3] = 1.0
        info[0, TEX_COLOR2 : TEX_COLOR2 + 3] = 1.0
        return TextureArrays(info, np.ones(3, dtype=np.float32))

    info = np.zeros((len(textures), N_TEX_PARAMS), dtype=np.float64)
    chunks: list[np.ndarray] = []
    pixel_offsets: dict[tuple[Path, str], int] = {}
    n_floats = 0
    for k, texture in enumerate(textures):
        row = info[k]
        row[TEX_MATRIX : TEX_MATRIX + 4] = placement_matrix(
            texture.scale, texture.rotation
        ).ravel()
        row[TEX_OFFSET : TEX_OFFSET + 2] = texture.offset
        if isinstance(texture, ImageTexture):
            from ..assets.images import load_image  # Pillow: only for scenes with images

            path = Path(resolve(texture.file))
            image = load_image(path, texture.colorspace)
            key = (path.resolve(), texture.colorspace)
            if key not in pixel_offsets:
                pixel_offsets[key] = n_floats
                chunks.append(image.reshape(-1))
                n_floats += image.size
            row[TEX_KIND] = TEX_IMAGE
            row[TEX_WIDTH] = image.shape[1]
            row[TEX_HEIGHT] = image.shape[0]
            row[TEX_PIXEL_OFFSET] = pixel_offsets[key]
            row[TEX_WRAP] = WRAP_CODES[texture.wrap]
            row[TEX_FILTER] = FILTER_CODES[texture.filter]
        elif isinstance(texture, CheckerTexture):
            row[TEX_KIND] = TEX_CHECKER
            row[TEX_COLOR1 : TEX_COLOR1 + 3] = texture.color1
            row[TEX_COLOR2 : TEX_COLOR2 + 3] = texture.color2
            row[TEX_CHECKS] = texture.checks
        elif isinstance(texture, GradientTexture):
            row[TEX_KIND] = TEX_GRADIENT
            row[TEX_COLOR1 : TEX_COLOR1 + 3] = texture.color1
            row[TEX_COLOR2 : TEX_COLOR2 + 3] = texture.color2
            row[TEX_AXIS] = AXIS_CODES[texture.axis]
        else:
            raise TypeError(f"not a texture: {texture!r}")

    if chunks:
        pixels = np.concatenate(chunks).astype(np.float32, copy=False)
    else:
        pixels = np.ones(3, dtype=np.float32)
    return TextureArrays(info, np.ascontiguousarray(pixels))
