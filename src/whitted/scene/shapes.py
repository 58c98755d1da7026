"""Shapes. Every one is intersected exactly (no tessellation) and takes a ``transform``."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from .materials import Material
from .types import Direction, Strict, Transform, Vec3


class _Shape(Strict):
    name: str | None = None
    material: str | Material | None = None
    transform: Transform | None = None


class Sphere(_Shape):
    type: Literal["sphere"] = "sphere"
    center: Vec3 = (0.0, 0.0, 0.0)
    radius: float = Field(gt=0.0)


class Plane(_Shape):
    """An infinite plane through ``point`` with ``normal`` (both sides shade)."""

    type: Literal["plane"] = "plane"
    point: Vec3 = (0.0, 0.0, 0.0)
    normal: Direction = (0.0, 1.0, 0.0)


class Rectangle(_Shape):
    """A parallelogram: ``corner`` plus ``edge1`` and ``edge2`` (the lecture's Q1, Q2−Q1, Q3−Q1);
    points ``corner + u·edge1 + v·edge2`` with u, v in 0..1; normal ``edge1 × edge2``."""

    type: Literal["rectangle"] = "rectangle"
    corner: Vec3
    edge1: Direction
    edge2: Direction

    @model_validator(mode="after")
    def _not_degenerate(self) -> Rectangle:
        if np.linalg.norm(np.cross(self.edge1, self.edge2)) < 1e-12:
            raise ValueError("edge1 and edge2 are parallel: the rectangle has no area")
        return self


class Disk(_Shape):
    type: Literal["disk"] = "disk"
    center: Vec3 = (0.0, 0.0, 0.0)
    normal: Direction = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)


class Triangle(_Shape):
    type: Literal["triangle"] = "triangle"
    vertices: tuple[Vec3, Vec3, Vec3]

    @model_validator(mode="after")
    def _not_degenerate(self) -> Triangle:
        a, b, c = (np.array(v) for v in self.vertices)
        if np.linalg.norm(np.cross(b - a, c - a)) < 1e-12:
            raise ValueError("the three vertices are collinear: the triangle has no area")
        return self


class Box(_Shape):
    """A parallelepiped: ``corner`` plus three ``edges``; or axis-aligned from ``min``/``max``."""

    type: Literal["box"] = "box"
    corner: Vec3 | None = None
    edges: tuple[Direction, Direction, Direction] | None = None
    min: Vec3 | None = None
    max: Vec3 | None = None

    @model_validator(mode="after")
    def _one_form(self) -> Box:
        oriented = self.corner is not None or self.edges is not None
        aligned = self.min is not None or self.max is not None
        if oriented == aligned:
            raise ValueError("give either corner + edges, or min + max")
        if oriented and (self.corner is None or self.edges is None):
            raise ValueError("corner and edges go together")
        if aligned:
            if self.min is None or self.max is None:
                raise ValueError("min and max go together")
            if any(hi <= lo for lo, hi in zip(self.min, self.max, strict=True)):
                raise ValueError("max must be greater than min on every axis")
        else:
            assert self.edges is not None
            if abs(np.linalg.det(np.array(self.edges))) < 1e-12:
                raise ValueError("the three edges are coplanar: the box has no volume")
        return self

    def corner_and_edges(self) -> tuple[np.ndarray, np.ndarray]:
        if self.min is not None and self.max is not None:
            lo, hi = np.array(self.min), np.array(self.max)
            return lo, np.diag(hi - lo)
        assert self.corner is not None and self.edges is not None
        return np.array(self.corner), np.array(self.edges, dtype=np.float64)


class Cylinder(_Shape):
    """A finite cylinder from the centre of its ``base`` to the centre of its ``top``."""

    type: Literal["cylinder"] = "cylinder"
    base: Vec3 = (0.0, 0.0, 0.0)
    top: Vec3 = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)
    capped: bool = True

    @model_validator(mode="after")
    def _has_height(self) -> Cylinder:
        if np.linalg.norm(np.subtract(self.top, self.base)) < 1e-12:
            raise ValueError("base and top coincide: zero height")
        return self


class Cone(_Shape):
    """A finite cone (or frustum when ``top_radius`` > 0) from ``base`` to ``top``."""

    type: Literal["cone"] = "cone"
    base: Vec3 = (0.0, 0.0, 0.0)
    top: Vec3 = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)
    top_radius: float = Field(default=0.0, ge=0.0)
    capped: bool = True

    @model_validator(mode="after")
    def _has_height(self) -> Cone:
        if np.linalg.norm(np.subtract(self.top, self.base)) < 1e-12:
            raise ValueError("base and top coincide: zero height")
        return self


Shape = Annotated[
    Sphere | Plane | Rectangle | Disk | Triangle | Box | Cylinder | Cone,
    Field(discriminator="type"),
]
