"""Scene-level ray queries: nearest hit through the BVH (plus the unbounded planes), and the
surface normals of a hit in world space.

Two levels: the scene BVH holds the analytic shapes; the mesh *instances* have a top-level
BVH of their own, walked after it (so scenes without meshes never run that code); an instance
maps the ray into its mesh's space and walks the mesh's own BVH (:mod:`.mesh`). A hit is
(t, primitive, triangle, b1, b2): ``triangle`` is -1 for analytic shapes, and (b1, b2) are
the barycentric coordinates on the triangle.
"""

from __future__ import annotations

import numpy as np

from ..jit import body, kernel, overload
from .extras import (
    extra_hit_if_extras,
    extra_normal_if_extras,
    flipped_if_extras,
)
from .features import has_extras, has_instances, instances_possible
from .layout import (
    MAT_KT,
    MESH_NORMALS,
    MESH_STACK_BASE,
    PRIM_MATERIAL,
    PRIM_TYPE,
    PRIM_XFORM,
)
from .mesh import (
    OPAQUE_KT,
    embree_closest_hit,
    embree_occlusion,
    mesh_closest_hit,
    mesh_occlusion,
    uses_embree,
)
from .shapes import INF
from .shapes.dispatch import (
    has_shading_normal,
    intersect_local,
    is_extra,
    normal_local,
)
from .shapes.mesh import mesh_normals
from .shapes.triangle import triangle_shading_normal
from .traverse import (
    box_entry,
    bvh_frame_ray,
    inverse_direction,
    next_scene_candidate,
    push_children,
    start_scene_walk,
)
from .xform import normal_to_world as _normal_to_world
from .xform import to_object


@kernel(inline="always")
def hit_analytic(geo, i, o, d, tmin, tmax):
    """t of the ray with analytic primitive ``i`` (INF on a miss). Inlined into the traversal
    loops (in kernels for scenes with tori or CSG it would otherwise be a call per candidate,
    and the torus and the CSG walk stay calls behind it, made only for them)."""
    typ = geo.prim_info[i, PRIM_TYPE]
    if has_extras(geo) and is_extra(typ):  # tori, CSG (compiled only where used)
        t, _ = extra_hit_if_extras(geo, i, o, d, inverse_direction(d), tmin, tmax)
        return t
    xf = geo.prim_info[i, PRIM_XFORM]
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
    return intersect_local(typ, geo.prim_params, i, o, d, tmin, tmax)


@kernel
def hit_instance(geo, i, o, d, inv, tmin, tmax, stack):
    """(t, triangle, b1, b2) of the ray with mesh instance ``i``; t = INF on a miss. ``inv``
    is the world ray's inverse direction (reused when the instance has no transform)."""
    xf = geo.prim_info[i, PRIM_XFORM]
    mesh = int(geo.prim_params[i, 0])
    if uses_embree(geo, mesh):  # straight to Embree: no inverse direction, one call less
        if xf >= 0:
            o, d = to_object(geo.xforms, xf, o, d)
        return embree_closest_hit(geo, mesh, o, d, tmin, tmax)
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
        inv = inverse_direction(d)
    return mesh_closest_hit(geo, mesh, o, d, inv, tmin, tmax, stack, MESH_STACK_BASE)


@kernel
def instance_occludes(geo, mats, i, o, d, inv, tmin, tmax, stack):
    """:func:`occludes` for a mesh instance (``inv`` as in :func:`hit_instance`)."""
    xf = geo.prim_info[i, PRIM_XFORM]
    mesh = int(geo.prim_params[i, 0])
    material = geo.prim_info[i, PRIM_MATERIAL]
    if uses_embree(geo, mesh):
        if xf >= 0:
            o, d = to_object(geo.xforms, xf, o, d)
        return embree_occlusion(geo, mats, mesh, material, o, d, tmin, tmax)
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
        inv = inverse_direction(d)
    return mesh_occlusion(geo, mats, mesh, material, o, d, inv, tmin, tmax, stack,
                          MESH_STACK_BASE)


@kernel
def occludes(geo, mats, i, o, d, tmin, tmax):
    """Does analytic primitive ``i`` block the segment (tmin, tmax)? 0: no; 1: opaquely;
    2: only through a transparent surface."""
    if hit_analytic(geo, i, o, d, tmin, tmax) == INF:
        return 0
    return 1 if mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT else 2


@kernel
def hit_material(geo, prim, tri):
    """Material row of a hit: the primitive's, or for meshes without an override the
    triangle's own."""
    m = geo.prim_info[prim, PRIM_MATERIAL]
    if m < 0 and tri >= 0:
        return geo.tri_material[tri]
    return m


@kernel
def world_normal(geo, i, p):
    """Outward unit geometric normal of analytic primitive ``i`` at world point ``p``."""
    xf = geo.prim_info[i, PRIM_XFORM]
    typ = geo.prim_info[i, PRIM_TYPE]
    lp = p
    if xf >= 0:
        lp, _ = to_object(geo.xforms, xf, p, p)
    n = normal_local(typ, geo.prim_params, i, lp)
    if has_extras(geo):  # tori; CSG cuts turned inside out
        if is_extra(typ):
            n = extra_normal_if_extras(geo, i, lp, n)
        if xf >= 0:
            n = _normal_to_world(geo.xforms, xf, n)
        return flipped_if_extras(geo, i, n)
    if xf < 0:
        return n
    return _normal_to_world(geo.xforms, xf, n)


def mesh_normals_if_instances(geo, mesh, tri, b1, b2):
    """:func:`.shapes.mesh.mesh_normals`, never compiled for scenes without instances (see
    features.py)."""
    return mesh_normals(geo, mesh, tri, b1, b2)


@overload(mesh_normals_if_instances)
def _mesh_normals_if_instances(geo, mesh, tri, b1, b2):
    if not instances_possible(geo):
        return lambda geo, mesh, tri, b1, b2: ((0.0, 0.0, 1.0), (0.0, 0.0, 1.0))
    return body(mesh_normals)


@kernel(inline="always")
def surface_normals(geo, prim, tri, b1, b2, p):
    """(geometric, shading) unit normals in world space of a hit at ``p``. They differ only on
    smooth-shaded meshes; the geometric one decides which side a ray is on."""
    if tri < 0:
        n = world_normal(geo, prim, p)
        if has_shading_normal(geo.prim_info[prim, PRIM_TYPE], geo.prim_params, prim):
            ns = triangle_shading_normal(geo, prim, p, n)
            if has_extras(geo):  # a smooth mesh cutting a CSG difference: turned too
                ns = flipped_if_extras(geo, prim, ns)
            return n, ns
        return n, n
    mesh = int(geo.prim_params[prim, 0])
    ng, ns = mesh_normals_if_instances(geo, mesh, tri, b1, b2)
    xf = geo.prim_info[prim, PRIM_XFORM]
    if xf < 0:
        return ng, ns
    wg = _normal_to_world(geo.xforms, xf, ng)
    if geo.mesh_info[mesh, MESH_NORMALS] < 0:  # flat shading: ns is ng, mapped once
        return wg, wg
    return wg, _normal_to_world(geo.xforms, xf, ns)


@kernel(inline="always")
def geometric_normal(geo, prim, tri, b1, b2, p):
    """The geometric unit normal of :func:`surface_normals`, without the shading one: what
    decides whether a ray enters or leaves a body (a smooth triangle's blended normal is not
    computed)."""
    if tri < 0:
        return world_normal(geo, prim, p)
    n, _ = surface_normals(geo, prim, tri, b1, b2, p)
    return n


@kernel
def closest_instance_hit(geo, o, d, inv, tmin, tmax, stack):
    """Nearest mesh-instance hit in (tmin, tmax), as :func:`closest_hit` returns it
    (``inv``: the inverse direction)."""
    best_t = tmax
    best = -1
    best_tri = -1
    best_b1 = 0.0
    best_b2 = 0.0
    box = geo.inst_box
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        if box_entry(box, node, o, inv, tmin, best_t) == INF:
            continue
        count = geo.inst_link[node, 1]
        if count == 0:
            top = push_children(box, geo.inst_link, node, o, inv, tmin, best_t,
                                 stack, top)
            continue
        first = geo.inst_link[node, 0]
        for j in range(first, first + count):
            i = geo.inst_prims[j]
            t, tri, b1, b2 = hit_instance(geo, i, o, d, inv, tmin, best_t, stack)
            if t < best_t:
                best_t = t
                best = i
                best_tri = tri
                best_b1 = b1
                best_b2 = b2
    return best_t, best, best_tri, best_b1, best_b2


def closest_instance_hit_if_instances(geo, o, d, inv, tmin, tmax, stack):
    """:func:`closest_instance_hit`, never compiled for scenes without instances."""
    return closest_instance_hit(geo, o, d, inv, tmin, tmax, stack)


@overload(closest_instance_hit_if_instances)
def _closest_instance_hit_if_instances(geo, o, d, inv, tmin, tmax, stack):
    if not instances_possible(geo):
        return lambda geo, o, d, inv, tmin, tmax, stack: (tmax, -1, -1, 0.0, 0.0)
    return body(closest_instance_hit)


@kernel(inline="always")
def closest_hit(geo, o, d, tmin, tmax, stack):
    """Nearest hit in (tmin, tmax): (t, primitive, triangle, b1, b2), or (tmax, -1, -1, 0, 0).
    ``stack`` is caller-owned int32 scratch space (BVH_STACK entries: layout.py).

    First the analytic shapes (the unbounded ones, then the BVH's leaves, through one call
    site of the intersection routines), then, only when the scene has meshes, the mesh
    instances' own BVH up to the nearest hit so far."""
    best_t = tmax
    best = -1
    inv = inverse_direction(d)
    fo, finv = bvh_frame_ray(geo, o, d, inv)  # the ray the boxes see
    j, leaf, leaf_end, top = start_scene_walk(geo, stack, True)
    while True:
        i, j, leaf, leaf_end, top = next_scene_candidate(geo, fo, finv, tmin, best_t, stack,
                                                         j, leaf, leaf_end, top, True)
        if i < 0:
            break
        # (t, the primitive whose surface it is): ``i`` itself, or for a CSG object the leaf
        # whose surface shows; tori and CSG objects through the call hit_analytic makes, so
        # their code is linked in once
        if has_extras(geo) and is_extra(geo.prim_info[i, PRIM_TYPE]):
            t, part = extra_hit_if_extras(geo, i, o, d, inv, tmin, best_t)
        else:
            t = hit_analytic(geo, i, o, d, tmin, best_t)
            part = np.int64(i)
        if t < best_t:
            best_t = t
            best = part
    if has_instances(geo):
        t, prim, tri, b1, b2 = closest_instance_hit_if_instances(geo, o, d, inv, tmin, best_t,
                                                                 stack)
        if prim >= 0:
            return t, prim, tri, b1, b2
    return best_t, best, -1, 0.0, 0.0
