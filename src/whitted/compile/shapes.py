"""Analytic shapes -> primitive rows, transforms baked in.

Transforms are baked into the shape's numbers wherever the shape family is closed under them
(planes, rectangles, triangles and boxes under any affine map; spheres, disks, cylinders and
cones under similarities). Only a quadric under a non-uniform scale or shear keeps a
world-to-object matrix and is intersected in its own space.
"""

from __future__ import annotations

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


def add_shape(b: PrimitiveRows, shape, m: np.ndarray, material: int, obj: int) -> None:
    lin = m[:3, :3]
    to_world = m
    inv = np.linalg.inv(m)
    s = similarity_scale(lin)

    def point(p):
        return lin @ np.asarray(p, dtype=np.float64) + m[:3, 3]

    def normal(n):
        return unit(inv[:3, :3].T @ np.asarray(n, dtype=np.float64))

    if isinstance(shape, Sphere):
        c, r = np.array(shape.center), shape.radius
        if s is not None:
            cw = point(c)
            frame = (lin / s).T.reshape(-1)  # rows: the object's x, y, z axes in the world
            b.add(SHAPE_SPHERE, [*cw, r * s, *frame], cw - r * s, cw + r * s,
                  material=material, obj=obj, solid=True)
        else:
            cw = point(c)
            ext = r * np.linalg.norm(lin, axis=1)
            b.add(SHAPE_SPHERE, [*c, r, *np.eye(3).reshape(-1)], cw - ext, cw + ext,
                  material=material, obj=obj, solid=True, world_to_object=inv)
    elif isinstance(shape, Plane):
        nw = normal(shape.normal)
        b.add(SHAPE_PLANE, [*point(shape.point), *nw, *world_tangent(lin, shape.normal, nw)],
              [-np.inf] * 3, [np.inf] * 3, material=material, obj=obj, solid=False)
    elif isinstance(shape, Rectangle):
        corner = point(shape.corner)
        e1, e2 = lin @ np.array(shape.edge1), lin @ np.array(shape.edge2)
        n = unit(np.cross(e1, e2))
        du = np.cross(e2, n) / np.dot(e1, np.cross(e2, n))
        dv = np.cross(n, e1) / np.dot(e2, np.cross(n, e1))
        lo, hi = corners_bounds([corner, corner + e1, corner + e2, corner + e1 + e2])
        b.add(SHAPE_RECTANGLE, [*corner, *e1, *e2, *n, *du, *dv], lo, hi, material=material,
              obj=obj, solid=False)
    elif isinstance(shape, Triangle):
        v0, v1, v2 = (point(v) for v in shape.vertices)
        e1, e2 = v1 - v0, v2 - v0
        n = unit(np.cross(e1, e2))
        lo, hi = corners_bounds([v0, v1, v2])
        uvs = np.array(shape.uvs, dtype=np.float64).reshape(-1)
        b.add(SHAPE_TRIANGLE, [*v0, *e1, *e2, *n, *uvs, -1.0], lo, hi, material=material,
              obj=obj, solid=False)
    elif isinstance(shape, Disk):
        c, n, r = np.array(shape.center), unit(shape.normal), shape.radius
        if s is not None:
            cw, nw = point(c), normal(n)
            lo, hi = disk_bounds(cw, nw, r * s)
            b.add(SHAPE_DISK, [*cw, *nw, r * s, *world_tangent(lin, n, nw)], lo, hi,
                  material=material, obj=obj, solid=False)
        else:
            lo, hi = disk_bounds(c, n, r)
            lo, hi = corners_bounds(box_corners(lo, hi), to_world)
            b.add(SHAPE_DISK, [*c, *n, r, *tangent(n)], lo, hi, material=material, obj=obj,
                  solid=False, world_to_object=inv)
    elif isinstance(shape, Box):
        corner, edges = shape.corner_and_edges()
        corner_w = point(corner)
        edges_w = (lin @ edges.T).T  # rows are the three edge vectors
        inv_e = np.linalg.inv(edges_w.T)  # local = inv_e @ (p - corner)
        pts = [corner_w + i * edges_w[0] + j * edges_w[1] + k * edges_w[2]
               for i in (0, 1) for j in (0, 1) for k in (0, 1)]
        lo, hi = corners_bounds(pts)
        b.add(SHAPE_BOX, [*corner_w, *inv_e.reshape(-1)], lo, hi, material=material, obj=obj,
              solid=True)
    elif isinstance(shape, Cylinder | Cone):
        base, top = np.array(shape.base), np.array(shape.top)
        r0 = shape.radius
        r1 = shape.radius if isinstance(shape, Cylinder) else shape.top_radius
        capped = shape.capped
        xf = None
        u_dir = tangent(top - base)
        if s is not None:
            u_dir = world_tangent(lin, top - base, lin @ (top - base))
            base, top, r0, r1 = point(base), point(top), r0 * s, r1 * s
        else:
            xf = inv
        axis = top - base
        h = float(np.linalg.norm(axis))
        axis = axis / h
        lo0, hi0 = disk_bounds(base, axis, r0) if r0 > 0 else (base, base)
        lo1, hi1 = disk_bounds(top, axis, r1) if r1 > 0 else (top, top)
        lo, hi = np.minimum(lo0, lo1), np.maximum(hi0, hi1)
        if xf is not None:
            lo, hi = corners_bounds(box_corners(lo, hi), to_world)
        b.add(SHAPE_FRUSTUM, [*base, *axis, h, r0, r1, float(capped), *u_dir], lo, hi,
              material=material, obj=obj, solid=capped, world_to_object=xf)
    elif isinstance(shape, Torus):
        big, small = shape.major_radius, shape.minor_radius
        outer = big + small
        lo, hi = corners_bounds(box_corners(np.array([-outer, -small, -outer]),
                                            np.array([outer, small, outer])), to_world)
        if s is not None:  # rows: the object's x, y, z axes in the world
            b.add(SHAPE_TORUS, [*point((0.0, 0.0, 0.0)), *(lin / s).T.reshape(-1), big * s,
                                small * s], lo, hi, material=material, obj=obj, solid=True)
        else:
            b.add(SHAPE_TORUS, [0.0, 0.0, 0.0, *np.eye(3).reshape(-1), big, small], lo, hi,
                  material=material, obj=obj, solid=True, world_to_object=inv)
    else:  # pragma: no cover - the scene model admits no other shape
        raise TypeError(f"cannot compile {type(shape).__name__}")
