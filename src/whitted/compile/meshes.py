"""Triangle meshes -> the bottom level of the two-level BVH.

Every distinct mesh (one model file with one normal setting, or one set of inline arrays) is
stored once, in its own space: float32 positions, int32 triangles, per-triangle material rows,
corner normals when it is smooth-shaded, corner uvs when it has texture coordinates, and a
binned-SAH BVH with float32 boxes rounded outward. Scene objects that use it become instances
(:data:`SHAPE_MESH` primitives, in a top-level BVH of the instances) with their own transform
and material.
Degenerate triangles (zero area, non-finite corners) are dropped here, with a warning that
counts them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kernels.layout import (
    MESH_NODE_COUNT,
    MESH_NODE_HI,
    MESH_NODE_LO,
    MESH_NODE_OFFSET,
    MESH_NODE_WIDTH,
    MESH_NORMALS,
    MESH_ROOT,
    MESH_TRI_COUNT,
    MESH_TRI_OFFSET,
    MESH_UVS,
    N_MESH_INFO,
)
from .normals import smooth_corner_normals
from .reuse import cached_build_bvh

# SAH cost of visiting a node, relative to one watertight triangle test (see compile/bvh.py)
MESH_TRAVERSAL_COST = 2.0  # measured: 28-55 % fewer nodes than 1.0, same speed


@dataclass
class MeshSource:
    """One mesh as read: what the compiler needs, from a model file or from arrays."""

    label: str  # file name or "objects[i]" for inline arrays
    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (T, 3) 0-based
    normals: np.ndarray | None  # (V, 3) per vertex
    uvs: np.ndarray | None  # (V, 2) per vertex
    face_material: np.ndarray  # (T,) index into materials
    materials: list  # whitted Material objects
    warnings: list[str] = field(default_factory=list)


@dataclass
class CompiledMesh:
    index: int  # row of mesh_info
    lo: np.ndarray  # (3,) bounds in mesh space
    hi: np.ndarray
    triangles: int


def _round_down32(a: np.ndarray) -> np.ndarray:
    out = a.astype(np.float32)
    over = out.astype(np.float64) > a
    out[over] = np.nextafter(out[over], np.float32(-np.inf))
    return out


def _round_up32(a: np.ndarray) -> np.ndarray:
    out = a.astype(np.float32)
    under = out.astype(np.float64) < a
    out[under] = np.nextafter(out[under], np.float32(np.inf))
    return out


def sibling_pairs(lo: np.ndarray, hi: np.ndarray, offset: np.ndarray, count: np.ndarray):
    """A mesh BVH from the builder's depth-first layout (left child ``i + 1``, right child
    ``offset[i]``) in the layout the mesh walks read: the two children of an interior node
    side by side, ``first`` and ``first + 1``, so one 64-byte cache line holds both boxes.
    Row 0 is the root, row 1 padding (an empty box) so every pair starts on an even row; the
    pairs follow in the depth-first order of their parents. Returns (box (N+1, 2, 3) float32,
    link (N+1, 2) int32: interior (first child, 0), leaf (first entry, count))."""
    n = len(count)
    interior = np.flatnonzero(count == 0)
    first = 2 + 2 * np.arange(len(interior))  # the pair of the k-th interior node
    where = np.zeros(n, np.int64)  # new row of every node
    where[interior + 1] = first
    where[offset[interior]] = first + 1
    rows = n + 1
    box = np.empty((rows, 2, 3), np.float32)
    box[:, 0] = np.inf
    box[:, 1] = -np.inf
    box[where, 0] = lo
    box[where, 1] = hi
    link = np.zeros((rows, 2), np.int32)
    link[where, 0] = offset
    link[where[interior], 0] = first
    link[where, 1] = count
    return box, link


class MeshTable:
    """Accumulates meshes; :meth:`arrays` returns the flat arrays for GeometryArrays."""

    def __init__(self, mesh_tracer: str = "whitted") -> None:
        # who traces these meshes (the scene's render.mesh_tracer), made concrete when the
        # first mesh comes (so a scene without meshes never loads Embree): with "embree",
        # whitted's own mesh BVHs are not built and the local faces are kept for Embree
        self.mesh_tracer_setting = mesh_tracer
        self.tracer: str | None = None
        self.local_faces: list[np.ndarray] = []
        self.info: list[list[int]] = []
        self.vertices: list[np.ndarray] = []
        self.faces: list[np.ndarray] = []
        self.tri_material: list[np.ndarray] = []
        self.tri_normals: list[np.ndarray] = []
        self.tri_uvs: list[np.ndarray] = []
        self.node_box: list[np.ndarray] = []
        self.node_link: list[np.ndarray] = []
        self.node_tris: list[np.ndarray] = []
        self.leaf_corners: list[np.ndarray] = []
        self.n_vertices = 0
        self.n_tris = 0
        self.n_nodes = 0
        self.n_normal_rows = 0
        self.n_uv_rows = 0
        self.warnings: list[str] = []

    def drawable(self, src: MeshSource, v: np.ndarray):
        """(faces, face_material, corners) of the triangles of ``src`` worth drawing, with
        positions ``v``: degenerate ones (zero area, not finite) dropped with a warning that
        counts them. None when nothing is left."""
        faces = np.ascontiguousarray(src.faces, dtype=np.int64).reshape(-1, 3)
        corners = v[faces]  # (T, 3, 3)
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        keep = np.einsum("ij,ij->i", normal, normal) > 0.0  # twice the area, squared
        finite = np.isfinite(v).all(axis=1)  # per vertex: a ninth of the work per corner
        if not finite.all():
            keep &= finite[faces].all(axis=1)
        dropped = int(len(faces) - keep.sum())
        if dropped:
            self.warnings.append(f"{src.label}: dropped {dropped} degenerate triangle"
                                 f"{'s' if dropped != 1 else ''} (zero area or not finite)")
        face_material = np.asarray(src.face_material)
        if not keep.all():
            faces = faces[keep]
            corners = corners[keep]
            face_material = face_material[keep]
        if len(faces) == 0:
            self.warnings.append(f"{src.label}: no triangles to draw")
            return None
        return faces, face_material, corners

    def corner_normals(self, src: MeshSource, v: np.ndarray, faces: np.ndarray,
                       smooth: bool | None, crease_angle: float) -> np.ndarray | None:
        """(T, 3, 3) corner normals in the mesh's space, or None for flat shading."""
        if smooth is False:
            return None
        if src.normals is not None:
            return np.asarray(src.normals, dtype=np.float32)[faces]
        if smooth:
            return smooth_corner_normals(v, faces, crease_angle)
        return None

    def add_normal_rows(self, normals: np.ndarray) -> int:
        """Append (T, 3, 3) corner normals to tri_normals; returns the first row."""
        row = self.n_normal_rows
        self.tri_normals.append(np.ascontiguousarray(normals, dtype=np.float32))
        self.n_normal_rows += len(normals)
        return row

    def add(self, src: MeshSource, material_rows: np.ndarray, smooth: bool | None,
            crease_angle: float) -> CompiledMesh | None:
        """Store ``src`` (``material_rows[k]`` = material-table row of ``src.materials[k]``).
        Returns None when no triangle is left to draw."""
        verts32 = np.ascontiguousarray(src.vertices, dtype=np.float32)
        v = verts32.astype(np.float64)  # exactly the positions the kernels will see
        kept = self.drawable(src, v)
        if kept is None:
            return None
        faces, face_material, corners = kept
        t = len(faces)
        # pairwise minimum/maximum: NumPy's reduction over an axis of three is 5x slower
        lo_tri = np.minimum(np.minimum(corners[:, 0], corners[:, 1]), corners[:, 2])
        hi_tri = np.maximum(np.maximum(corners[:, 0], corners[:, 1]), corners[:, 2])
        del corners
        if self.tracer is None:
            from .embree import resolve_mesh_tracer

            self.tracer = resolve_mesh_tracer(self.mesh_tracer_setting)
        if self.tracer == "embree":
            bvh = None
            lo, hi = lo_tri.min(axis=0), hi_tri.max(axis=0)  # the root box: all triangles
        else:
            bvh = cached_build_bvh(lo_tri, hi_tri, traversal_cost=MESH_TRAVERSAL_COST)
            lo = np.array(bvh.node_min[0], np.float64)
            hi = np.array(bvh.node_max[0], np.float64)
        del lo_tri, hi_tri

        normal_row = -1
        corner_normals = self.corner_normals(src, v, faces, smooth, crease_angle)
        if corner_normals is not None:
            normal_row = self.add_normal_rows(corner_normals)
        uv_row = -1
        if src.uvs is not None:
            uv_row = self.n_uv_rows
            self.tri_uvs.append(np.asarray(src.uvs, dtype=np.float32)[faces])
            self.n_uv_rows += t

        index = len(self.info)
        row = [0] * N_MESH_INFO
        row[MESH_ROOT] = self.n_nodes if bvh is not None else -1
        row[MESH_TRI_OFFSET] = self.n_tris
        row[MESH_TRI_COUNT] = t
        row[MESH_NORMALS] = normal_row
        row[MESH_UVS] = uv_row
        self.info.append(row)
        self.vertices.append(verts32)
        self.faces.append((faces + self.n_vertices).astype(np.int32))
        self.tri_material.append(np.asarray(material_rows, np.int32)[face_material])
        if bvh is None:
            self.local_faces.append(faces)
        else:
            box, link = sibling_pairs(_round_down32(bvh.node_min), _round_up32(bvh.node_max),
                                      bvh.node_offset, bvh.node_count)
            # global indices: interior nodes name their first child among all meshes' nodes,
            # leaves their first entry among all meshes' node_tris
            leaf = link[:, 1] > 0
            link[:, 0] += np.where(leaf, self.n_tris, self.n_nodes)
            self.node_box.append(box)
            self.node_link.append(link)
            self.node_tris.append((bvh.prim_order + self.n_tris).astype(np.int32))
            self.leaf_corners.append(verts32[faces[bvh.prim_order]])
            self.n_nodes += len(link)
        self.n_vertices += len(verts32)
        self.n_tris += t
        return CompiledMesh(index, lo, hi, t)

    def node_rows(self) -> dict[str, np.ndarray]:
        """The mesh BVH nodes as 32-byte rows (box, then link) starting on a 64-byte cache
        line: ``mesh_nodes`` and its int32 view ``mesh_node_ints``."""
        n = self.n_nodes
        raw = np.empty(n * MESH_NODE_WIDTH + 16, np.float32)
        skip = (-raw.ctypes.data % 64) // 4
        rows = raw[skip:skip + n * MESH_NODE_WIDTH].reshape(n, MESH_NODE_WIDTH)
        ints = rows.view(np.int32)
        if n:
            box = np.concatenate(self.node_box)
            rows[:, MESH_NODE_LO:MESH_NODE_LO + 3] = box[:, 0]
            rows[:, MESH_NODE_HI:MESH_NODE_HI + 3] = box[:, 1]
            link = np.concatenate(self.node_link)
            ints[:, MESH_NODE_OFFSET] = link[:, 0]
            ints[:, MESH_NODE_COUNT] = link[:, 1]
        return {"mesh_nodes": rows, "mesh_node_ints": ints}

    def arrays(self) -> dict[str, np.ndarray]:
        def cat(parts, shape, dtype):
            if not parts:
                return np.zeros(shape, dtype)
            if len(parts) == 1:  # one mesh: no copy
                return np.ascontiguousarray(parts[0], dtype=dtype)
            return np.ascontiguousarray(np.concatenate(parts), dtype=dtype)

        return {
            "mesh_info": np.array(self.info, np.int32).reshape(len(self.info), N_MESH_INFO),
            "mesh_vertices": cat(self.vertices, (0, 3), np.float32),
            "mesh_faces": cat(self.faces, (0, 3), np.int32),
            "tri_material": cat(self.tri_material, (0,), np.int32),
            "tri_normals": cat(self.tri_normals, (0, 3, 3), np.float32),
            "tri_uvs": cat(self.tri_uvs, (0, 3, 2), np.float32),
            **self.node_rows(),
            "mesh_node_tris": cat(self.node_tris, (0,), np.int32),
            "mesh_leaf_corners": cat(self.leaf_corners, (0, 3, 3), np.float32),
        }

