"""Triangle meshes: watertight ray/triangle intersection and the bottom-level BVH walk.

A mesh is stored once in its own space (``mesh_vertices``, ``mesh_faces``) with its own BVH;
the caller maps the ray into that space (instancing). The walks read each triangle's corners
from ``mesh_leaf_corners``, a copy laid out in the BVH's leaf order, so a leaf's triangles
lie side by side in memory (mesh1m: 0.720 -> 0.671 s CPU). The copy holds the same float32
values as ``mesh_vertices``, so edges shared by two triangles stay exactly shared.

The BVH is 4-wide (:mod:`..compile.wide_bvh`): each node is one 128-byte row holding its four
children's boxes as structure of arrays (4 lower x, 4 lower y, ...) and their links, so a
step of the walk tests four boxes in straight-line code and the tree is half as deep as the
binary SAH tree it is collapsed from. The leaves are the binary tree's, in the same order.

Triangles are intersected with the watertight algorithm of Woop, Benthin and Wald (JCGT
2013): the ray is sheared so it runs along +z, and each edge's 2D edge function is evaluated
from the same two vertices whichever triangle it belongs to. Two triangles sharing an edge
therefore compute exactly opposite values there and a ray through the edge (or a shared
vertex) hits at least one of them: no cracks, whatever the floating-point rounding.
"""

from __future__ import annotations

import numpy as np

from .intersect import INF
from .jit import kernel
from .layout import (
    MAT_KT,
    MESH_NODE_CHILD,
    MESH_NODE_COUNT,
    MESH_NODE_HI_X,
    MESH_NODE_HI_Y,
    MESH_NODE_HI_Z,
    MESH_NODE_LO_X,
    MESH_NODE_LO_Y,
    MESH_NODE_LO_Z,
    MESH_NORMALS,
    MESH_ROOT,
    MESH_TRI_OFFSET,
    MESH_UVS,
)
from .traverse import slab_entry
from .vec import cross, normalize

OPAQUE_KT = 0.01  # the lecture's rule: an occluder with kt below this blocks the light


@kernel(fastmath=False)
def shear_setup(d):
    """Per-ray constants of the watertight test: the axis permutation (kx, ky, kz) that makes
    |d[kz]| largest (and keeps the winding), and the shear (sx, sy, sz)."""
    ax = abs(d[0])
    ay = abs(d[1])
    az = abs(d[2])
    kz = 0
    if ay > ax and ay >= az:
        kz = 1
    elif az > ax and az > ay:
        kz = 2
    kx = kz + 1 if kz < 2 else 0
    ky = kx + 1 if kx < 2 else 0
    if d[kz] < 0.0:
        kx, ky = ky, kx
    dz = d[kz]
    return kx, ky, kz, d[kx] / dz, d[ky] / dz, 1.0 / dz


@kernel(fastmath=False)  # exact rounding: see the module docstring
def intersect_mesh_triangle(corners, j, o, kx, ky, kz, sx, sy, sz, tmin, tmax):
    """(t, b1, b2) of the ray with the triangle at leaf entry ``j`` (corners ``corners[j]``):
    hit point = (1-b1-b2)·v0 + b1·v1 + b2·v2; t = INF on a miss. ``kx..sz`` come from
    :func:`shear_setup` of the ray direction."""
    # unsigned indices: no negative-index wraparound code on the nine loads
    j = np.uint64(j)
    kx = np.uint64(kx)
    ky = np.uint64(ky)
    kz = np.uint64(kz)
    az = corners[j, 0, kz] - o[kz]
    bz = corners[j, 1, kz] - o[kz]
    cz = corners[j, 2, kz] - o[kz]
    ax = corners[j, 0, kx] - o[kx] - sx * az
    ay = corners[j, 0, ky] - o[ky] - sy * az
    bx = corners[j, 1, kx] - o[kx] - sx * bz
    by = corners[j, 1, ky] - o[ky] - sy * bz
    cx = corners[j, 2, kx] - o[kx] - sx * cz
    cy = corners[j, 2, ky] - o[ky] - sy * cz
    e0 = cx * by - cy * bx  # weight of v0
    e1 = ax * cy - ay * cx  # weight of v1
    e2 = bx * ay - by * ax  # weight of v2
    if (e0 < 0.0 or e1 < 0.0 or e2 < 0.0) and (e0 > 0.0 or e1 > 0.0 or e2 > 0.0):
        return INF, 0.0, 0.0
    det = e0 + e1 + e2
    if det == 0.0:
        return INF, 0.0, 0.0
    inv = 1.0 / det
    t = (e0 * az + e1 * bz + e2 * cz) * sz * inv
    if not (tmin < t < tmax):
        return INF, 0.0, 0.0
    return t, e1 * inv, e2 * inv


@kernel(inline="always")
def child_entry(nodes, node, k, o, inv, tmin, tmax):
    """Entry distance of the ray into box ``k`` of wide node ``node`` when it overlaps
    (tmin, tmax), else INF (:func:`.traverse.slab_entry` on one slot of the row)."""
    return slab_entry(nodes[node, MESH_NODE_LO_X + k], nodes[node, MESH_NODE_LO_Y + k],
                      nodes[node, MESH_NODE_LO_Z + k], nodes[node, MESH_NODE_HI_X + k],
                      nodes[node, MESH_NODE_HI_Y + k], nodes[node, MESH_NODE_HI_Z + k], o, inv,
                      tmin, tmax)


@kernel(inline="always")
def child_entries(nodes, node, o, inv, tmin, tmax):
    """The entry distances (INF: missed) of the ray into the four boxes of wide node
    ``node``: four copies of one straight-line slab test on consecutive floats."""
    n = np.uint64(node)  # unsigned: no negative-index wraparound code
    return (child_entry(nodes, n, np.uint64(0), o, inv, tmin, tmax),
            child_entry(nodes, n, np.uint64(1), o, inv, tmin, tmax),
            child_entry(nodes, n, np.uint64(2), o, inv, tmin, tmax),
            child_entry(nodes, n, np.uint64(3), o, inv, tmin, tmax))


@kernel(inline="always")
def nearest_in_leaf(corners, first, count, o, kx, ky, kz, sx, sy, sz, tmin, best_t, best,
                    best_b1, best_b2):
    """The nearest of the running best and the leaf's triangles: (t, entry, b1, b2)."""
    for j in range(first, first + count):
        t, b1, b2 = intersect_mesh_triangle(corners, j, o, kx, ky, kz, sx, sy, sz, tmin,
                                            best_t)
        if t < best_t:
            best_t = t
            best = j
            best_b1 = b1
            best_b2 = b2
    return best_t, best, best_b1, best_b2


@kernel
def mesh_closest_hit(geo, mesh, o, d, inv, tmin, tmax, stack, base):
    """Nearest triangle of mesh ``mesh`` hit by the ray (mesh space) in (tmin, tmax):
    (t, triangle, b1, b2), t = INF on a miss. ``stack[base:]`` is scratch.

    At each wide node the four boxes are tested at once and the children the ray meets
    within the nearest hit so far are pushed, the nearest last so it is next: interior
    children as their row, leaves as ``-1 - (4 row + slot)``."""
    kx, ky, kz, sx, sy, sz = shear_setup(d)
    corners = geo.mesh_leaf_corners
    nodes = geo.mesh_nodes
    ints = geo.mesh_node_ints
    best_t = tmax
    best = -1
    best_b1 = 0.0
    best_b2 = 0.0
    top = base
    stack[top] = geo.mesh_info[mesh, MESH_ROOT]
    while top >= base:
        ref = stack[top]
        top -= 1
        if ref < 0:  # a leaf: row and slot
            ref = np.uint64(-1 - ref)
            n = ref >> np.uint64(2)
            s = ref & np.uint64(3)
            best_t, best, best_b1, best_b2 = nearest_in_leaf(
                corners, ints[n, MESH_NODE_CHILD + s], ints[n, MESH_NODE_COUNT + s], o,
                kx, ky, kz, sx, sy, sz, tmin, best_t, best, best_b1, best_b2)
            continue
        n = np.uint64(ref)
        k0, k1, k2, k3 = child_entries(nodes, n, o, inv, tmin, best_t)
        leaf = np.int32(-1 - 4 * ref)
        c0 = ints[n, MESH_NODE_CHILD] if ints[n, MESH_NODE_COUNT] == 0 else leaf
        c1 = ints[n, MESH_NODE_CHILD + 1] if ints[n, MESH_NODE_COUNT + 1] == 0 else leaf - 1
        c2 = ints[n, MESH_NODE_CHILD + 2] if ints[n, MESH_NODE_COUNT + 2] == 0 else leaf - 2
        c3 = ints[n, MESH_NODE_CHILD + 3] if ints[n, MESH_NODE_COUNT + 3] == 0 else leaf - 3
        # the nearest child goes last (visited next), the others in slot order
        km, cm = k0, c0
        if k1 < km:
            km, cm, k1, c1 = k1, c1, km, cm
        if k2 < km:
            km, cm, k2, c2 = k2, c2, km, cm
        if k3 < km:
            km, cm, k3, c3 = k3, c3, km, cm
        # branch-free pushes: each writes the next slot and keeps it only if the ray met it
        stack[np.uint64(top + 1)] = c1
        top += np.int64(k1 != INF)
        stack[np.uint64(top + 1)] = c2
        top += np.int64(k2 != INF)
        stack[np.uint64(top + 1)] = c3
        top += np.int64(k3 != INF)
        stack[np.uint64(top + 1)] = cm
        top += np.int64(km != INF)
    if best < 0:
        return INF, -1, 0.0, 0.0
    return best_t, geo.mesh_node_tris[best], best_b1, best_b2


@kernel(inline="always")
def _occluders_in_slot(geo, mats, corners, ints, n, s, entry, material, o, kx, ky, kz, sx, sy,
                       sz, tmin, tmax, stack, top, seen):
    """One child of a wide node in the any-hit walk: pushed (interior), or its triangles
    tested (leaf). Returns (top, seen), seen 1 when an opaque triangle blocks the segment."""
    if entry == INF:
        return top, seen
    child = ints[n, MESH_NODE_CHILD + s]
    count = ints[n, MESH_NODE_COUNT + s]
    if count == 0:
        top += 1
        stack[top] = child
        return top, seen
    for j in range(child, child + count):
        t, _, _ = intersect_mesh_triangle(corners, j, o, kx, ky, kz, sx, sy, sz, tmin, tmax)
        if t < INF:
            m = material if material >= 0 else geo.tri_material[geo.mesh_node_tris[j]]
            if mats[m, MAT_KT] < OPAQUE_KT:
                return top, 1
            seen = 2
    return top, seen


@kernel
def mesh_occlusion(geo, mats, mesh, material, o, d, inv, tmin, tmax, stack, base):
    """Any triangle of the mesh on the segment (tmin, tmax)? 0: none; 1: an opaque one (the
    walk stops there); 2: only transparent ones. ``material`` >= 0 overrides the triangles'.
    Leaf children are tested as soon as their parent is reached, interior ones pushed."""
    if material >= 0 and mats[material, MAT_KT] >= OPAQUE_KT:
        # one transparent material: any hit is a transparent one
        t, tri, _, _ = mesh_closest_hit(geo, mesh, o, d, inv, tmin, tmax, stack, base)
        return 2 if tri >= 0 else 0
    kx, ky, kz, sx, sy, sz = shear_setup(d)
    corners = geo.mesh_leaf_corners
    nodes = geo.mesh_nodes
    ints = geo.mesh_node_ints
    seen = 0
    top = base
    stack[top] = geo.mesh_info[mesh, MESH_ROOT]
    while top >= base:
        n = np.uint64(stack[top])
        top -= 1
        t0, t1, t2, t3 = child_entries(nodes, n, o, inv, tmin, tmax)
        top, seen = _occluders_in_slot(geo, mats, corners, ints, n, np.uint64(0), t0, material,
                                       o, kx, ky, kz, sx, sy, sz, tmin, tmax, stack, top, seen)
        if seen == 1:
            return 1
        top, seen = _occluders_in_slot(geo, mats, corners, ints, n, np.uint64(1), t1, material,
                                       o, kx, ky, kz, sx, sy, sz, tmin, tmax, stack, top, seen)
        if seen == 1:
            return 1
        top, seen = _occluders_in_slot(geo, mats, corners, ints, n, np.uint64(2), t2, material,
                                       o, kx, ky, kz, sx, sy, sz, tmin, tmax, stack, top, seen)
        if seen == 1:
            return 1
        top, seen = _occluders_in_slot(geo, mats, corners, ints, n, np.uint64(3), t3, material,
                                       o, kx, ky, kz, sx, sy, sz, tmin, tmax, stack, top, seen)
        if seen == 1:
            return 1
    return seen


@kernel
def mesh_normals(geo, mesh, tri, b1, b2):
    """(geometric, shading) unit normals of triangle ``tri`` in mesh space at barycentric
    (b1, b2). The geometric normal follows the winding (v1 - v0) x (v2 - v0); the shading one
    interpolates the corner normals of smooth meshes (else it is the geometric one)."""
    verts = geo.mesh_vertices
    i0 = geo.mesh_faces[tri, 0]
    i1 = geo.mesh_faces[tri, 1]
    i2 = geo.mesh_faces[tri, 2]
    e1 = (verts[i1, 0] - verts[i0, 0], verts[i1, 1] - verts[i0, 1], verts[i1, 2] - verts[i0, 2])
    e2 = (verts[i2, 0] - verts[i0, 0], verts[i2, 1] - verts[i0, 1], verts[i2, 2] - verts[i0, 2])
    ng = normalize(cross(e1, e2))
    row = geo.mesh_info[mesh, MESH_NORMALS]
    if row < 0:
        return ng, ng
    r = row + tri - geo.mesh_info[mesh, MESH_TRI_OFFSET]
    n = geo.tri_normals
    b0 = 1.0 - b1 - b2
    ns = (
        b0 * n[r, 0, 0] + b1 * n[r, 1, 0] + b2 * n[r, 2, 0],
        b0 * n[r, 0, 1] + b1 * n[r, 1, 1] + b2 * n[r, 2, 1],
        b0 * n[r, 0, 2] + b1 * n[r, 1, 2] + b2 * n[r, 2, 2],
    )
    if ns[0] == 0.0 and ns[1] == 0.0 and ns[2] == 0.0:
        return ng, ng
    return ng, normalize(ns)


@kernel
def mesh_uv(geo, mesh, tri, b1, b2):
    """Texture coordinates at barycentric (b1, b2): the corners' uvs interpolated, or (b1, b2)
    itself when the mesh has none."""
    row = geo.mesh_info[mesh, MESH_UVS]
    if row < 0:
        return b1, b2
    r = row + tri - geo.mesh_info[mesh, MESH_TRI_OFFSET]
    t = geo.tri_uvs
    b0 = 1.0 - b1 - b2
    return (
        b0 * t[r, 0, 0] + b1 * t[r, 1, 0] + b2 * t[r, 2, 0],
        b0 * t[r, 0, 1] + b1 * t[r, 1, 1] + b2 * t[r, 2, 1],
    )
