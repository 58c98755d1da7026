"""Analytic shapes -> primitive rows, transforms baked in: one function per shape (its
parameters and its bounds), reached through :data:`ROWS` (kernels/shapes/ names each one as
that shape's ``rows`` piece).

Transforms are baked into the shape's numbers wherever the shape family is closed under them
(planes, rectangles, triangles and boxes under any affine map; spheres, disks, cylinders and
cones under similarities). Only a quadric under a non-uniform scale or shear keeps a
world-to-object matrix and is intersected in its own space.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..kernels.layout import (
    SHAPE_BOX,
    SHAPE_DISK,
    SHAPE_FRUSTUM,
    SHAPE_PLANE,
    SHAPE_RECTANGLE,
    SHAPE_SPHERE,
    SHAPE_TORUS,
    SHAPE_TRIANGLE,
)
from ..scene.shapes import Box, Cone, Cylinder, Disk, Plane, Rectangle, Sphere, Torus, Triangle
from .geometry import (
    box_corners,
    corners_bounds,
    disk_bounds,
    similarity_scale,
    tangent,
    unit,
    world_tangent,
)
from .primitives import PrimitiveRows


@dataclass
class Placement:
    """An object's 4x4 object-to-world matrix ``m`` and what the shapes derive from it: its
    linear part, its inverse and its uniform scale (None: not a similarity)."""

    m: np.ndarray
    lin: np.ndarray = field(init=False)
    inv: np.ndarray = field(init=False)
    s: float | None = field(init=False)

    def __post_init__(self) -> None:
        self.lin = self.m[:3, :3]
        self.inv = np.linalg.inv(self.m)
        self.s = similarity_scale(self.lin)

    def point(self, p) -> np.ndarray:
        return self.lin @ np.asarray(p, dtype=np.float64) + self.m[:3, 3]

    def normal(self, n) -> np.ndarray:
        return unit(self.inv[:3, :3].T @ np.asarray(n, dtype=np.float64))


def sphere_rows(b: PrimitiveRows, shape: Sphere, x: Placement, material: int, obj: int) -> None:
    c, r, s, lin = np.array(shape.center), shape.radius, x.s, x.lin
    if s is not None:
        cw = x.point(c)
        frame = (lin / s).T.reshape(-1)  # rows: the object's x, y, z axes in the world
        b.add(SHAPE_SPHERE, [*cw, r * s, *frame], cw - r * s, cw + r * s,
              material=material, obj=obj, solid=True)
    else:
        cw = x.point(c)
        ext = r * np.linalg.norm(lin, axis=1)
        b.add(SHAPE_SPHERE, [*c, r, *np.eye(3).reshape(-1)], cw - ext, cw + ext,
              material=material, obj=obj, solid=True, world_to_object=x.inv)


def plane_rows(b: PrimitiveRows, shape: Plane, x: Placement, material: int, obj: int) -> None:
    nw = x.normal(shape.normal)
    b.add(SHAPE_PLANE, [*x.point(shape.point), *nw, *world_tangent(x.lin, shape.normal, nw)],
          [-np.inf] * 3, [np.inf] * 3, material=material, obj=obj, solid=False)


def rectangle_rows(b: PrimitiveRows, shape: Rectangle, x: Placement, material: int,
                   obj: int) -> None:
    corner = x.point(shape.corner)
    e1, e2 = x.lin @ np.array(shape.edge1), x.lin @ np.array(shape.edge2)
    n = unit(np.cross(e1, e2))
    du = np.cross(e2, n) / np.dot(e1, np.cross(e2, n))
    dv = np.cross(n, e1) / np.dot(e2, np.cross(n, e1))
    lo, hi = corners_bounds([corner, corner + e1, corner + e2, corner + e1 + e2])
    b.add(SHAPE_RECTANGLE, [*corner, *e1, *e2, *n, *du, *dv], lo, hi, material=material,
          obj=obj, solid=False)


def triangle_rows(b: PrimitiveRows, shape: Triangle, x: Placement, material: int,
                  obj: int) -> None:
    v0, v1, v2 = (x.point(v) for v in shape.vertices)
    e1, e2 = v1 - v0, v2 - v0
    n = unit(np.cross(e1, e2))
    lo, hi = corners_bounds([v0, v1, v2])
    uvs = np.array(shape.uvs, dtype=np.float64).reshape(-1)
    b.add(SHAPE_TRIANGLE, [*v0, *e1, *e2, *n, *uvs, -1.0], lo, hi, material=material,
          obj=obj, solid=False)


def disk_rows(b: PrimitiveRows, shape: Disk, x: Placement, material: int, obj: int) -> None:
    c, n, r, s = np.array(shape.center), unit(shape.normal), shape.radius, x.s
    if s is not None:
        cw, nw = x.point(c), x.normal(n)
        lo, hi = disk_bounds(cw, nw, r * s)
        b.add(SHAPE_DISK, [*cw, *nw, r * s, *world_tangent(x.lin, n, nw)], lo, hi,
              material=material, obj=obj, solid=False)
    else:
        lo, hi = disk_bounds(c, n, r)
        lo, hi = corners_bounds(box_corners(lo, hi), x.m)
        b.add(SHAPE_DISK, [*c, *n, r, *tangent(n)], lo, hi, material=material, obj=obj,
              solid=False, world_to_object=x.inv)


def box_rows(b: PrimitiveRows, shape: Box, x: Placement, material: int, obj: int) -> None:
    corner, edges = shape.corner_and_edges()
    corner_w = x.point(corner)
    edges_w = (x.lin @ edges.T).T  # rows are the three edge vectors
    inv_e = np.linalg.inv(edges_w.T)  # local = inv_e @ (p - corner)
    pts = [corner_w + i * edges_w[0] + j * edges_w[1] + k * edges_w[2]
           for i in (0, 1) for j in (0, 1) for k in (0, 1)]
    lo, hi = corners_bounds(pts)
    b.add(SHAPE_BOX, [*corner_w, *inv_e.reshape(-1)], lo, hi, material=material, obj=obj,
          solid=True)


def frustum_rows(b: PrimitiveRows, shape: Cylinder | Cone, x: Placement, material: int,
                 obj: int) -> None:
    """A cylinder or a cone: both are frustum rows (a cylinder's radii are equal)."""
    base, top = np.array(shape.base), np.array(shape.top)
    r0 = shape.radius
    r1 = shape.radius if isinstance(shape, Cylinder) else shape.top_radius
    capped = shape.capped
    xf = None
    u_dir = tangent(top - base)
    s = x.s
    if s is not None:
        u_dir = world_tangent(x.lin, top - base, x.lin @ (top - base))
        base, top, r0, r1 = x.point(base), x.point(top), r0 * s, r1 * s
    else:
        xf = x.inv
    axis = top - base
    h = float(np.linalg.norm(axis))
    axis = axis / h
    lo0, hi0 = disk_bounds(base, axis, r0) if r0 > 0 else (base, base)
    lo1, hi1 = disk_bounds(top, axis, r1) if r1 > 0 else (top, top)
    lo, hi = np.minimum(lo0, lo1), np.maximum(hi0, hi1)
    if xf is not None:
        lo, hi = corners_bounds(box_corners(lo, hi), x.m)
    b.add(SHAPE_FRUSTUM, [*base, *axis, h, r0, r1, float(capped), *u_dir], lo, hi,
          material=material, obj=obj, solid=capped, world_to_object=xf)


def torus_rows(b: PrimitiveRows, shape: Torus, x: Placement, material: int, obj: int) -> None:
    big, small, s = shape.major_radius, shape.minor_radius, x.s
    outer = big + small
    lo, hi = corners_bounds(box_corners(np.array([-outer, -small, -outer]),
                                        np.array([outer, small, outer])), x.m)
    if s is not None:  # rows: the object's x, y, z axes in the world
        b.add(SHAPE_TORUS, [*x.point((0.0, 0.0, 0.0)), *(x.lin / s).T.reshape(-1), big * s,
                            small * s], lo, hi, material=material, obj=obj, solid=True)
    else:
        b.add(SHAPE_TORUS, [0.0, 0.0, 0.0, *np.eye(3).reshape(-1), big, small], lo, hi,
              material=material, obj=obj, solid=True, world_to_object=x.inv)


#: scene shape class -> the function writing its rows and bounds
ROWS: dict[type, Callable[[PrimitiveRows, object, Placement, int, int], None]] = {
    Sphere: sphere_rows, Plane: plane_rows, Rectangle: rectangle_rows, Triangle: triangle_rows,
    Disk: disk_rows, Box: box_rows, Cylinder: frustum_rows, Cone: frustum_rows,
    Torus: torus_rows,
}


def add_shape(b: PrimitiveRows, shape, m: np.ndarray, material: int, obj: int) -> None:
    """Rows (and world bounds) of analytic ``shape`` under object-to-world matrix ``m``."""
    rows = ROWS.get(type(shape))
    if rows is None:  # pragma: no cover - the scene model admits no other shape
        raise TypeError(f"cannot compile {type(shape).__name__}")
    rows(b, shape, Placement(m), material, obj)
