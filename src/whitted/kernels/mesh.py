"""Triangle meshes: the bottom-level BVH walk (its watertight ray/triangle test, and a mesh
triangle's normals and uv, are in shapes/mesh.py), or Embree's where the mesh has an Embree
scene (``mesh_info`` columns from ``MESH_EMBREE``: see compile/embree.py).

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
"""

from __future__ import annotations

import numpy as np

from ..jit import kernel, numba_object
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
    MESH_ROOT,
    MESH_TRI_OFFSET,
)
from .shapes import INF
from .shapes.mesh import intersect_mesh_triangle, shear_setup
from .traverse import slab_entry

# kernels/embree.py's intrinsics are Numba extensions: imported with Numba (jit/decorators.py)
embree_intersect = numba_object(f"{__package__}.embree", "embree_intersect")
embree_occluded = numba_object(f"{__package__}.embree", "embree_occluded")
# Embree's closed float32 segment from whitted's open (tmin, tmax): the ends rounded inward
float32_above = numba_object(f"{__package__}.embree", "float32_above")
float32_below = numba_object(f"{__package__}.embree", "float32_below")

OPAQUE_KT = 0.01  # the lecture's rule: an occluder with kt below this blocks the light


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
def embree_address(geo, mesh, k):
    """Address ``k`` (EMBREE_ALL, ..., EMBREE_OCCLUDED) of mesh ``mesh``'s row: two int32
    columns, the low and the high half."""
    mesh = np.uint64(mesh)
    low = np.int64(geo.mesh_info[mesh, MESH_EMBREE + 2 * k]) & np.int64(0xFFFFFFFF)
    high = np.int64(geo.mesh_info[mesh, MESH_EMBREE + 2 * k + 1])
    return (high << np.int64(32)) | low


@kernel(inline="always")
def uses_embree(geo, mesh):
    """Is mesh ``mesh`` traced by Embree (it has an Embree scene)?"""
    return embree_address(geo, mesh, EMBREE_ALL) != 0


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
    if uses_embree(geo, mesh):
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
    if uses_embree(geo, mesh):
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
