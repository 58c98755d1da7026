"""The triangle of a mesh kept whole (an instance, or a big CSG leaf): the watertight
ray/triangle test the BVH walks of mesh.py make, and its normals and uv.

A mesh is stored once in its own space (``mesh_vertices``, ``mesh_faces``, the walks'
``mesh_leaf_corners``; layout.py's ``MESH_*`` columns); a hit on it is (t, triangle, b1, b2),
the barycentric weights of corners 1 and 2.

Triangles are intersected with the watertight algorithm of Woop, Benthin and Wald (JCGT
2013): the ray is sheared so it runs along +z, and each edge's 2D edge function is evaluated
from the same two vertices whichever triangle it belongs to. Two triangles sharing an edge
therefore compute exactly opposite values there and a ray through the edge (or a shared
vertex) hits at least one of them: no cracks, whatever the floating-point rounding.
"""

from __future__ import annotations

import numpy as np

from ...jit import kernel
from ..layout import MESH_NORMALS, MESH_TRI_OFFSET, MESH_UVS
from ..vec import cross, normalize
from . import INF


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
