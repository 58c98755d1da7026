"""Light sources: ambient, point, directional and disk (area) lights."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from .types import Colour, Direction, Strict, Vec3

Falloff = Literal["none", "linear", "inverse_square"]


class _Light(Strict):
    name: str | None = None
    color: Colour = (1.0, 1.0, 1.0)
    intensity: float = Field(default=1.0, ge=0.0, le=1e9)


class AmbientLight(_Light):
    """Uniform light from everywhere: contributes ``ka·Ia·ambient_color`` at every hit."""

    type: Literal["ambient"] = "ambient"


class PointLight(_Light):
    """A point light. ``falloff``: ``none`` (the coursework), ``linear`` (the lecture:
    ``intensity·dist_scale/dist``) or ``inverse_square`` (``intensity/dist²``)."""

    type: Literal["point"] = "point"
    position: Vec3
    falloff: Falloff = "none"
    dist_scale: float = Field(default=1.0, gt=0.0)


class DirectionalLight(_Light):
    """Parallel light travelling along ``direction`` (e.g. ``[0, -1, 0]`` shines straight down)."""

    type: Literal["directional"] = "directional"
    direction: Direction


class DiskLight(_Light):
    """A disk of light: soft shadows from ``samples`` stratified points on the disk, each
    treated as a point light carrying ``1/samples`` of the intensity. ``normal`` defaults to
    +y (the disk is parallel to the Oxz plane, as in the coursework). ``samples`` falls back
    to the render setting ``shadow_samples``."""

    type: Literal["disk"] = "disk"
    center: Vec3
    normal: Direction = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)
    samples: int | None = Field(default=None, ge=1, le=4096)
    falloff: Falloff = "none"
    dist_scale: float = Field(default=1.0, gt=0.0)


Light = Annotated[
    AmbientLight | PointLight | DirectionalLight | DiskLight, Field(discriminator="type")
]
