"""Triangle meshes: watertight ray/triangle intersection and the bottom-level BVH walk, or
Embree's where the mesh has an Embree scene (``mesh_info`` columns from ``MESH_EMBREE``: see
compile/embree.py).

A mesh is stored once in its own space (``mesh_vertices``, ``mesh_faces``) with its own BVH;
the caller maps the ray into that space (instancing). The walks read each triangle's corners
from ``mesh_leaf_corners``, a copy laid out in the BVH's leaf order, so a leaf's triangles
lie side by side in memory (mesh1m: 0.720 -> 0.671 s CPU). The copy holds the same float32
values as ``mesh_vertices``, so edges shared by two triangles stay exactly shared.

The nodes are 32-byte rows (box and link together, ``mesh_nodes`` / ``mesh_node_ints``) and
the two children of a node sit side by side on one 64-byte cache line
(:func:`..compile.meshes.sibling_pairs`): testing both children costs one memory access where
separate box and link arrays in depth-first order cost up to four (mesh1m: 0.740 -> 0.681 s
CPU for the rows, -> 0.644 s for the pairs).

Triangles are intersected with the watertight algorithm of Woop, Benthin and Wald (JCGT
2013): the ray is sheared so it runs along +z, and each edge's 2D edge function is evaluated
from the same two vertices whichever triangle it belongs to. Two triangles sharing an edge
therefore compute exactly opposite values there and a ray through the edge (or a shared
vertex) hits at least one of them: no cracks, whatever the floating-point rounding.
"""

from __future__ import annotations

import numpy as np

from ..jit import kernel, numba_object
from .intersect import INF
from .layout import (
    EMBREE_ALL,
    EMBREE_CLEAR,
    EMBREE_INTERSECT,
    EMBREE_OCCLUDED,
    EMBREE_OPAQUE,
    MAT_KT,
    MESH_EMBREE,
    MESH_NODE_COUNT,
    MESH_NODE_HI,
    MESH_NODE_LO,
    MESH_NODE_OFFSET,
    MESH_NORMALS,
    MESH_ROOT,
    MESH_TRI_OFFSET,
    MESH_UVS,
)
from .traverse import slab_entry
from .vec import cross, normalize

# kernels/embree.py's intrinsics are Numba extensions: imported with Numba (jit/decorators.py)
embree_intersect = numba_object(f"{__package__}.embree", "embree_intersect")
embree_occluded = numba_object(f"{__package__}.embree", "embree_occluded")

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


@kernel
def node_entry(nodes, node, o, inv, tmin, tmax):
    """Entry distance of the ray into the box of mesh BVH node ``node`` when it overlaps
    (tmin, tmax), else INF (:func:`.traverse.slab_entry` on a node row)."""
    node = np.uint64(node)  # unsigned: no negative-index wraparound code
    return slab_entry(nodes[node, MESH_NODE_LO], nodes[node, MESH_NODE_LO + 1],
                      nodes[node, MESH_NODE_LO + 2], nodes[node, MESH_NODE_HI],
                      nodes[node, MESH_NODE_HI + 1], nodes[node, MESH_NODE_HI + 2], o, inv,
                      tmin, tmax)


@kernel(inline="always")
def push_mesh_children(nodes, ints, node, o, inv, tmin, tmax, stack, top):
    """Push the children of interior mesh node ``node`` that the ray meets, the farther one
    first so the nearer one is visited next; returns the new stack top."""
    left = ints[np.uint64(node), MESH_NODE_OFFSET]
    right = left + 1
    t_left = node_entry(nodes, left, o, inv, tmin, tmax)
    t_right = node_entry(nodes, right, o, inv, tmin, tmax)
    if t_left <= t_right:
        if t_right != INF:
            top += 1
            stack[top] = right
        if t_left != INF:
            top += 1
            stack[top] = left
    else:
        if t_left != INF:
            top += 1
            stack[top] = left
        if t_right != INF:
            top += 1
            stack[top] = right
    return top


@kernel(inline="always")
def float32_above(x):
    """The smallest float32 above ``x`` (as a float64): Embree's segment is closed and in
    float32, whitted's (tmin, tmax) open, so its ends are rounded inward."""
    y = np.float32(x)
    if np.float64(y) <= x:
        y = np.nextafter(y, np.float32(INF))
    return np.float64(y)


@kernel(inline="always")
def float32_below(x):
    """The largest float32 below ``x`` (as a float64; inf stays inf)."""
    if x == INF:
        return x
    y = np.float32(x)
    if np.float64(y) >= x:
        y = np.nextafter(y, np.float32(-INF))
    return np.float64(y)


@kernel(inline="always")
def embree_address(geo, mesh, k):
    """Address ``k`` (EMBREE_ALL, ..., EMBREE_OCCLUDED) of mesh ``mesh``'s row: two int32
    columns, the low and the high half."""
    mesh = np.uint64(mesh)
    low = np.int64(geo.mesh_info[mesh, MESH_EMBREE + 2 * k]) & np.int64(0xFFFFFFFF)
    high = np.int64(geo.mesh_info[mesh, MESH_EMBREE + 2 * k + 1])
    return (high << np.int64(32)) | low


@kernel
def embree_closest_hit(geo, mesh, o, d, tmin, tmax):
    """:func:`mesh_closest_hit` by Embree (the mesh has an Embree scene)."""
    t, prim, b1, b2 = embree_intersect(embree_address(geo, mesh, EMBREE_INTERSECT),
                                       embree_address(geo, mesh, EMBREE_ALL), o, d,
                                       float32_above(tmin), float32_below(tmax))
    if prim < 0 or not (tmin < t < tmax):
        return INF, -1, 0.0, 0.0
    return t, prim + geo.mesh_info[mesh, MESH_TRI_OFFSET], b1, b2


@kernel
def embree_occlusion(geo, mats, mesh, material, o, d, tmin, tmax):
    """:func:`mesh_occlusion` by Embree (the mesh has an Embree scene)."""
    fn = embree_address(geo, mesh, EMBREE_OCCLUDED)
    tmin = float32_above(tmin)
    tmax = float32_below(tmax)
    if material >= 0:  # one material for every triangle
        if not embree_occluded(fn, embree_address(geo, mesh, EMBREE_ALL), o, d, tmin, tmax):
            return 0
        return 1 if mats[material, MAT_KT] < OPAQUE_KT else 2
    opaque = embree_address(geo, mesh, EMBREE_OPAQUE)
    if opaque != 0 and embree_occluded(fn, opaque, o, d, tmin, tmax):
        return 1
    clear = embree_address(geo, mesh, EMBREE_CLEAR)
    if clear != 0 and embree_occluded(fn, clear, o, d, tmin, tmax):
        return 2
    return 0


@kernel
def mesh_closest_hit(geo, mesh, o, d, inv, tmin, tmax, stack, base):
    """Nearest triangle of mesh ``mesh`` hit by the ray (mesh space) in (tmin, tmax):
    (t, triangle, b1, b2), t = INF on a miss. ``stack[base:]`` is scratch."""
    if embree_address(geo, mesh, EMBREE_ALL) != 0:
        return embree_closest_hit(geo, mesh, o, d, tmin, tmax)
    kx, ky, kz, sx, sy, sz = shear_setup(d)
    corners = geo.mesh_leaf_corners
    nodes = geo.mesh_nodes
    ints = geo.mesh_node_ints
    best_t = tmax
    best = -1
    best_b1 = 0.0
    best_b2 = 0.0
    root = geo.mesh_info[mesh, MESH_ROOT]
    if node_entry(nodes, root, o, inv, tmin, best_t) == INF:
        return INF, -1, 0.0, 0.0
    top = base
    stack[top] = root
    while top >= base:
        node = stack[top]
        top -= 1
        count = ints[np.uint64(node), MESH_NODE_COUNT]
        if count > 0:
            first = ints[np.uint64(node), MESH_NODE_OFFSET]
            for j in range(first, first + count):
                t, b1, b2 = intersect_mesh_triangle(corners, j, o, kx, ky, kz, sx, sy, sz,
                                                    tmin, best_t)
                if t < best_t:
                    best_t = t
                    best = j
                    best_b1 = b1
                    best_b2 = b2
            continue
        top = push_mesh_children(nodes, ints, node, o, inv, tmin, best_t, stack, top)
    if best < 0:
        return INF, -1, 0.0, 0.0
    return best_t, geo.mesh_node_tris[best], best_b1, best_b2


@kernel
def mesh_occlusion(geo, mats, mesh, material, o, d, inv, tmin, tmax, stack, base):
    """Any triangle of the mesh on the segment (tmin, tmax)? 0: none; 1: an opaque one (the
    walk stops there); 2: only transparent ones. ``material`` >= 0 overrides the triangles'."""
    if embree_address(geo, mesh, EMBREE_ALL) != 0:
        return embree_occlusion(geo, mats, mesh, material, o, d, tmin, tmax)
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
        node = stack[top]
        top -= 1
        if node_entry(nodes, node, o, inv, tmin, tmax) == INF:
            continue
        count = ints[np.uint64(node), MESH_NODE_COUNT]
        if count > 0:
            first = ints[np.uint64(node), MESH_NODE_OFFSET]
            for j in range(first, first + count):
                t, _, _ = intersect_mesh_triangle(corners, j, o, kx, ky, kz, sx, sy, sz, tmin,
                                                  tmax)
                if t < INF:
                    m = material if material >= 0 else geo.tri_material[geo.mesh_node_tris[j]]
                    if mats[m, MAT_KT] < OPAQUE_KT:
                        return 1
                    seen = 2
            continue
        first = ints[np.uint64(node), MESH_NODE_OFFSET]
        top += 1
        stack[top] = first + 1
        top += 1
        stack[top] = first
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
