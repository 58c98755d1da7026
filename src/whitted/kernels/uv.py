"""Texture coordinates (u, v) of a surface point, one mapping per shape.

- sphere: spherical, in the sphere's own frame: u = 0.5 + atan2(x, z)/2π (u = 0.5 faces +z,
  and grows to the right seen from there), v = 0.5 + asin(y)/π (v = 1 at the +y pole);
- plane: planar, in scene units from the plane's point: u along its tangent, v along
  normal × tangent;
- rectangle: u, v in 0..1 along edge1 and edge2;
- disk: planar, the disk inscribed in the unit square (centre at (0.5, 0.5));
- triangle: the corners' uvs (default (0,0), (1,0), (0,1)) blended by barycentric weight;
- box: per face, the two in-face box coordinates in 0..1;
- cylinder, cone: u = angle about the axis / 2π from the tangent, v = height / length;
- mesh: the corners' ``vt`` blended by barycentric weight, else the barycentric (b1, b2).
"""

from __future__ import annotations

import math

from ..jit import kernel, overload
from .accel import to_object
from .extras import extra_uv_if_extras
from .features import has_extras, instances_possible
from .layout import (
    DISK_TANGENT,
    FIRST_EXTRA_SHAPE,
    FRUSTUM_TANGENT,
    PLANE_TANGENT,
    PRIM_TYPE,
    PRIM_XFORM,
    SHAPE_BOX,
    SHAPE_DISK,
    SHAPE_FRUSTUM,
    SHAPE_MESH,
    SHAPE_PLANE,
    SHAPE_RECTANGLE,
    SHAPE_SPHERE,
    SHAPE_TRIANGLE,
)
from .shapes.box import box_uv
from .shapes.mesh import mesh_uv
from .shapes.sphere import sphere_uv
from .shapes.triangle import triangle_uv
from .vec import cross, dot, sub, vload

INV_TWO_PI = 0.5 / math.pi


@kernel
def _frustum_uv(P, i, p):
    q = sub(p, vload(P, i, 0))
    axis = vload(P, i, 3)
    z = dot(q, axis)
    qp = (q[0] - z * axis[0], q[1] - z * axis[1], q[2] - z * axis[2])
    t = vload(P, i, FRUSTUM_TANGENT)
    b = cross(axis, t)
    angle = math.atan2(dot(qp, b), dot(qp, t))
    return angle * INV_TWO_PI + 0.5, z / P[i, 6]


def mesh_uv_if_instances(geo, mesh, tri, b1, b2):
    """:func:`.mesh.mesh_uv`, never compiled for scenes without instances (see features.py)."""
    return mesh_uv(geo, mesh, tri, b1, b2)


@overload(mesh_uv_if_instances)
def _mesh_uv_if_instances(geo, mesh, tri, b1, b2):
    if not instances_possible(geo):
        return lambda geo, mesh, tri, b1, b2: (b1, b2)
    return lambda geo, mesh, tri, b1, b2: mesh_uv(geo, mesh, tri, b1, b2)


@kernel(inline="always")
def surface_uv(geo, prim, tri, b1, b2, p):
    """Texture coordinates of the hit at world point ``p`` (see the module docstring)."""
    typ = geo.prim_info[prim, PRIM_TYPE]
    if typ == SHAPE_MESH:
        return mesh_uv_if_instances(geo, int(geo.prim_params[prim, 0]), tri, b1, b2)
    xf = geo.prim_info[prim, PRIM_XFORM]
    if xf >= 0:
        p, _ = to_object(geo.xforms, xf, p, p)
    P = geo.prim_params
    if typ == SHAPE_SPHERE:
        return sphere_uv(P, prim, p)
    if typ == SHAPE_RECTANGLE:
        q = sub(p, vload(P, prim, 0))
        return dot(q, vload(P, prim, 12)), dot(q, vload(P, prim, 15))
    if typ == SHAPE_PLANE:
        q = sub(p, vload(P, prim, 0))
        t = vload(P, prim, PLANE_TANGENT)
        return dot(q, t), dot(q, cross(vload(P, prim, 3), t))
    if typ == SHAPE_DISK:
        q = sub(p, vload(P, prim, 0))
        t = vload(P, prim, DISK_TANGENT)
        s = 0.5 / P[prim, 6]
        return 0.5 + dot(q, t) * s, 0.5 + dot(q, cross(vload(P, prim, 3), t)) * s
    if typ == SHAPE_TRIANGLE:
        return triangle_uv(P, prim, p)
    if typ == SHAPE_BOX:
        return box_uv(P, prim, p)
    if typ == SHAPE_FRUSTUM:
        return _frustum_uv(P, prim, p)
    if has_extras(geo) and typ >= FIRST_EXTRA_SHAPE:  # the torus (kernels/shapes/torus.py)
        return extra_uv_if_extras(geo, prim, p)
    return 0.0, 0.0
