"""Textures: what colours a surface point by its (u, v) texture coordinates. Pure data.

Every texture has a placement in texture space: the surface's (u, v) is mapped to
``R(rotation) · ((u, v) · scale) + offset`` before the lookup, so ``scale = [4, 4]`` repeats an
image four times across a face and ``rotation`` turns it (degrees, counter-clockwise).

Where (u, v) comes from depends on the shape: the mesh's own texture coordinates (``vt``),
barycentric for triangles, spherical (longitude, latitude) for spheres, planar for planes,
rectangles and disks, per face for boxes, cylindrical for cylinders and cones. A material's
texture multiplies its ``color`` (the MTL convention for ``map_Kd``).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator

from .types import Colour, Finite, Strict

Vec2 = tuple[Finite, Finite]


class _Texture(Strict):
    offset: Vec2 = (0.0, 0.0)
    scale: Vec2 = (1.0, 1.0)
    rotation: Finite = 0.0

    @field_validator("scale")
    @classmethod
    def _scale_nonzero(cls, v: tuple[float, float]) -> tuple[float, float]:
        if any(abs(s) < 1e-12 for s in v):
            raise ValueError("scale must not be zero (the texture would be one colour)")
        return v


class ImageTexture(_Texture):
    """An image file (PNG, JPEG, BMP, TGA, ...; 8 or 16 bits; grey, palette or RGB, alpha is
    ignored), path relative to the scene file. ``colorspace = "srgb"`` decodes the stored values
    with the sRGB curve to linear (right for photographs and painted maps), ``"linear"`` takes
    them as they are (data maps).

    ``v = 0`` is the bottom edge of the image and ``v = 1`` its top (the OBJ / OpenGL
    convention), ``u`` runs left to right. ``wrap = "repeat"`` tiles the image with period 1 in
    both directions, ``"clamp"`` extends its edge pixels. ``filter = "bilinear"`` blends the four
    nearest pixels, ``"nearest"`` takes the pixel under the point."""

    type: Literal["image"] = "image"
    file: str = Field(min_length=1)
    wrap: Literal["repeat", "clamp"] = "repeat"
    filter: Literal["bilinear", "nearest"] = "bilinear"
    colorspace: Literal["srgb", "linear"] = "srgb"


class CheckerTexture(_Texture):
    """Squares of ``color1`` and ``color2``; ``checks`` squares per unit of u and v."""

    type: Literal["checker"] = "checker"
    color1: Colour = (0.9, 0.9, 0.9)
    color2: Colour = (0.1, 0.1, 0.1)
    checks: Annotated[float, Field(gt=0.0, le=1e6)] = 8.0


class GradientTexture(_Texture):
    """A linear blend from ``color1`` (at 0) to ``color2`` (at 1) along u or v, clamped."""

    type: Literal["gradient"] = "gradient"
    color1: Colour = (0.0, 0.0, 0.0)
    color2: Colour = (1.0, 1.0, 1.0)
    axis: Literal["u", "v"] = "u"


Texture = Annotated[
    ImageTexture | CheckerTexture | GradientTexture, Field(discriminator="type")
]
