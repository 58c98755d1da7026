"""Texture coordinates (u, v) of a hit: a mesh instance's corners' uvs (its ``vt``, else the
barycentric (b1, b2)), or the shape's own mapping (shapes/dispatch.py ``uv_local``; each
shape's file says its mapping, docs/scene-format.md tabulates them all).
"""

from __future__ import annotations

from ..jit import body, kernel, overload
from .accel import to_object
from .extras import extra_uv_if_extras
from .features import has_extras, instances_possible
from .layout import PRIM_TYPE, PRIM_XFORM
from .shapes.dispatch import is_extra, is_mesh_instance, uv_local
from .shapes.mesh import mesh_uv


def mesh_uv_if_instances(geo, mesh, tri, b1, b2):
    """:func:`.shapes.mesh.mesh_uv`, never compiled for scenes without instances (see
    features.py)."""
    return mesh_uv(geo, mesh, tri, b1, b2)


@overload(mesh_uv_if_instances)
def _mesh_uv_if_instances(geo, mesh, tri, b1, b2):
    if not instances_possible(geo):
        return lambda geo, mesh, tri, b1, b2: (b1, b2)
    return body(mesh_uv)


@kernel(inline="always")
def surface_uv(geo, prim, tri, b1, b2, p):
    """Texture coordinates of the hit at world point ``p`` (see the module docstring)."""
    typ = geo.prim_info[prim, PRIM_TYPE]
    if is_mesh_instance(typ):
        return mesh_uv_if_instances(geo, int(geo.prim_params[prim, 0]), tri, b1, b2)
    xf = geo.prim_info[prim, PRIM_XFORM]
    if xf >= 0:
        p, _ = to_object(geo.xforms, xf, p, p)
    if has_extras(geo) and is_extra(typ):  # the torus
        return extra_uv_if_extras(geo, prim, p)
    return uv_local(typ, geo.prim_params, prim, p)
