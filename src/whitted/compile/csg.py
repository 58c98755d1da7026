"""CSG objects -> primitive rows: the object's row (in the scene BVH, with the box of the
whole), then its tree in postfix order, leaves as ordinary solid rows and operations as
``SHAPE_CSG_OP`` rows (see kernels/csg.py for the walk that reads them).

Materials follow POV-Ray: a child without a material takes the nearest enclosing CSG
object's, and every surface shows its own leaf's material (so the cut of a difference shows
the material of the object that cut it). The whole object is one body for refraction and
absorption: its medium is its own material, or, when it has none, its first leaf's.

A mesh leaf's triangles are rows after the tree, placed in the scene (one copy per leaf: the
walk shades them); a big one's crossings come through the mesh stored for it, which
``store_mesh`` shares with every other use of the same mesh (compile/scene.py).
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..kernels.layout import (
    CSG_DIFFERENCE,
    CSG_INTERSECTION,
    CSG_MERGE,
    CSG_UNION,
    N_PRIM_PARAMS,
    SHAPE_CSG,
    SHAPE_CSG_MESH,
    SHAPE_CSG_OP,
)
from ..kernels.mesh import OPAQUE_KT
from ..scene.shapes import CSG, Mesh
from .csg_bounds import clipped_bounds
from .primitives import PrimitiveRows
from .shapes import add_shape

CSG_MESH_LIMIT = 2_000_000  # triangles of a mesh in CSG (each a row and in a BVH: ~300 B)
CSG_MESH_SCAN = 64  # up to this many triangles a mesh leaf's rows are each tested, no BVH
OPERATION_CODES = {"union": CSG_UNION, "intersection": CSG_INTERSECTION,
                   "difference": CSG_DIFFERENCE, "merge": CSG_MERGE}


def _transform(shape) -> np.ndarray:
    return shape.transform.matrix() if shape.transform is not None else np.eye(4)


def add_csg(b: PrimitiveRows, shape: CSG, m: np.ndarray, material_row, resolve, obj: int,
            default_material, mesh_source=None, emit_mesh=None, store_mesh=None) -> None:
    """Append CSG object ``shape`` (world matrix ``m``) as rows of ``b``. ``resolve`` maps a
    material reference to a Material, ``material_row`` a Material to its table row;
    ``default_material`` is the object's resolved material (used by children without).
    ``mesh_source(child, where)`` loads a mesh child (a ``MeshSource``);
    ``emit_mesh(source, child, matrix, material)`` appends its triangles as rows and returns
    (first row, count); ``store_mesh(source, child)`` stores a big one in the mesh table (in
    its own space, with its BVH) and returns (mesh_info row, triangles) or None. An open
    mesh, or one too big, is a SceneError naming it."""
    root = b.rows
    b.add(SHAPE_CSG, [0.0] * 8, np.zeros(3), np.zeros(3), material=0, obj=obj, solid=True)
    root_block = len(b.blocks) - 1
    leaves: list[tuple[int, object, int]] = []  # (row, Material, flip)

    meshes: list[tuple] = []
    leaf_boxes: list[tuple] = []  # (lo, hi) of each leaf, in the walk's order

    def walk(node: CSG, matrix: np.ndarray, inherited, flip: int, where: str):
        """Rows of ``node``'s subtree; returns its bounds (lo, hi), None when empty."""
        boxes = []
        for k, child in enumerate(node.objects):
            cm = matrix @ _transform(child)
            mat = resolve(child.material) if child.material is not None else inherited
            cflip = flip ^ (1 if node.operation == "difference" and k > 0 else 0)
            if isinstance(child, CSG):
                boxes.append(walk(child, cm, mat, cflip, f"{where}.objects[{k}]"))
                continue
            if isinstance(child, Mesh):  # its triangles go after the tree: see below
                row = b.rows
                src = _closed_mesh(mesh_source, child, f"{where}.objects[{k}]")
                big = store_mesh is not None and len(src.faces) > CSG_MESH_SCAN
                b.add(SHAPE_CSG_MESH, [0.0, 0.0, 0.0], np.zeros(3), np.zeros(3),
                      material=material_row(mat), obj=obj, solid=True,
                      world_to_object=np.linalg.inv(cm) if big else None)
                b.csg_rows[row] = (0, -1)
                meshes.append((row, len(b.blocks) - 1, src, child, cm, mat, big))
                leaves.append((row, mat, cflip))
                v = np.asarray(src.vertices, np.float64) @ cm[:3, :3].T + cm[:3, 3]
                boxes.append((v.min(axis=0), v.max(axis=0)))
                leaf_boxes.append(boxes[-1])
                continue
            row = b.rows
            add_shape(b, child, cm, material_row(mat), obj)
            blk = b.blocks[-1]
            leaves.append((row, mat, cflip))
            boxes.append((blk[6][0].copy(), blk[7][0].copy()))
            leaf_boxes.append(boxes[-1])
        b.add(SHAPE_CSG_OP, [float(OPERATION_CODES[node.operation]), float(len(node.objects))],
              np.zeros(3), np.zeros(3), material=0, obj=obj, solid=False)
        b.csg_rows[b.rows - 1] = (0, -1)
        los = np.array([box[0] for box in boxes])
        his = np.array([box[1] for box in boxes])
        if node.operation == "intersection":
            lo, hi = los.max(axis=0), his.min(axis=0)
            return lo, np.maximum(hi, lo)
        if node.operation == "difference":
            return los[0], his[0]
        return los.min(axis=0), his.max(axis=0)

    lo, hi = walk(shape, m, default_material, 0, f"objects[{obj}]")
    lo, hi = clipped_bounds(shape, m, lo, hi)  # box cutters take slabs off (csg_bounds.py)
    tree_rows = b.rows - root - 1  # the walk reads these; mesh leaves' triangles come after
    groups = []
    if shape.operation == "difference" and not any(isinstance(c, CSG) for c in shape.objects[1:]):
        n_first = first_leaves(shape)
        groups = cut_groups(leaf_boxes[n_first:], lo, hi, n_first)
    if groups:  # after the tree (the walk finds them from its size), as one block
        rows = np.zeros((len(groups), N_PRIM_PARAMS))
        for k, (first, end, glo, ghi) in enumerate(groups):
            rows[k, :8] = (first, end, *glo, *ghi)
        start = b.rows
        b.add_block(SHAPE_CSG_OP, rows, np.zeros((len(groups), 3)), np.zeros((len(groups), 3)),
                    0, obj, False)
        for row in range(start, b.rows):
            b.csg_rows[row] = (0, -1)
    body_material = default_material if shape.material is not None else leaves[0][1]
    body = material_row(body_material)
    for row, _, flip in leaves:
        b.csg_rows[row] = (flip, body)
    for row, block, src, child, cm, mat, big in meshes:
        first, count = emit_mesh(src, child, cm, mat)
        b.blocks[block][1][0, :2] = (first, count)
        if big:  # its crossings through the stored mesh's BVH: triangle k is row first + k
            stored = store_mesh(src, child)
            if stored is not None and stored[1] == count:
                b.blocks[block][1][0, 2] = stored[0] + 1
        flip = b.csg_rows[row][0]
        for r in range(first, first + count):
            b.csg_rows[r] = (flip, body)
    # the object's own row: opaque (for shadow rays) only when every leaf is
    clear = [mat for _, mat, _ in leaves if mat.kt >= OPAQUE_KT]
    typ, params, xf, _, objs, solid, _, _ = b.blocks[root_block]
    params[0, 0] = tree_rows
    params[0, 1] = len(leaves)
    params[0, 2:5] = lo  # the box of the whole: rays that miss it skip the walk
    params[0, 5:8] = hi
    if shape.operation in ("difference", "intersection"):  # nothing shows outside its first
        params[0, 8] = first_leaves(shape)                  # operand: tested first
    if shape.operation == "difference" and not any(isinstance(c, CSG) for c in shape.objects[1:]):
        params[0, 9] = tree_rows_of(shape.objects[0])  # every cut one leaf: tested as a mask
        params[0, 10] = len(groups)
    material = np.array([material_row(clear[0]) if clear else body], np.int32)
    b.blocks[root_block] = (typ, params, xf, material, objs, solid, lo.reshape(1, 3),
                            hi.reshape(1, 3))


def first_leaves(shape: CSG) -> int:
    """Leaves of the first operand of ``shape``."""
    def count(node) -> int:
        return sum(count(c) for c in node.objects) if isinstance(node, CSG) else 1
    return count(shape.objects[0])


GROUP_BOX_COST = 0.5  # a group's box test, in tests of one leaf


def _areas(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Surface areas of boxes (rows of ``lo``, ``hi``), halved."""
    e = np.maximum(hi - lo, 0.0)
    return e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0]


def cut_groups(boxes, lo, hi, first_leaf: int) -> list[tuple]:
    """Runs of neighbouring cuts (leaf numbers from ``first_leaf``) that share a box the walk
    tests before their leaves: (first leaf, end leaf, lo, hi), the box padded. A partition of
    the cuts in order, chosen to minimise the expected tests of a ray through the object's
    box (``lo``, ``hi``): a group costs its box test and, when the ray passes its box (its
    share of the object's surface area), its leaves; a cut in no group costs one test."""
    m = len(boxes)
    if m == 0:
        return []
    los = np.array([box[0] for box in boxes], np.float64)
    his = np.array([box[1] for box in boxes], np.float64)
    whole = max(float(_areas(np.asarray(lo, np.float64), np.asarray(hi, np.float64))), 1e-300)
    best = np.zeros(m + 1)
    start = np.zeros(m + 1, np.int64)  # the group ending at j starts at start[j] (-1: none)
    for j in range(1, m + 1):
        # the groups i .. j-1 for every i at once: running boxes from j-1 down to 0
        glo = np.minimum.accumulate(los[j - 1::-1], axis=0)
        ghi = np.maximum.accumulate(his[j - 1::-1], axis=0)
        share = np.minimum(_areas(glo, ghi) / whole, 1.0)
        i = np.arange(j - 1, -1, -1)
        cost = best[i] + GROUP_BOX_COST + share * (j - i)
        k = int(np.argmin(cost))
        best[j], start[j] = best[j - 1] + 1.0, -1
        if cost[k] < best[j]:
            best[j], start[j] = cost[k], i[k]
    groups = []
    j = m
    while j > 0:
        i = int(start[j])
        if i < 0:
            j -= 1
            continue
        glo, ghi = los[i:j].min(axis=0), his[i:j].max(axis=0)
        pad = 1e-6 * max(1.0, float(np.max(np.abs(np.concatenate([glo, ghi])))))
        groups.append((first_leaf + i, first_leaf + j, glo - pad, ghi + pad))
        j = i
    return groups[::-1]


def tree_rows_of(node) -> int:
    """Rows of ``node``'s subtree in the walk's postfix order (1 for a leaf)."""
    if not isinstance(node, CSG):
        return 1
    return 1 + sum(tree_rows_of(c) for c in node.objects)


def _closed_mesh(mesh_source, child: Mesh, where: str):
    """The mesh child's source, checked: closed, and small enough to keep (each triangle a
    row of the walk and a triangle of a stored mesh's BVH)."""
    src = mesh_source(child, where)
    what = f"{where} ({child.name or 'mesh'})"
    if len(src.faces) == 0:
        raise SceneError(f"{what}: the mesh has no triangles, so it bounds no volume")
    if len(src.faces) > CSG_MESH_LIMIT:
        raise SceneError(f"{what}: {len(src.faces):,} triangles; a mesh in CSG may have at "
                         f"most {CSG_MESH_LIMIT:,} (about 300 bytes each)")
    holes = open_edges(src.faces)
    if holes:
        raise SceneError(f"{what}: the mesh is open ({holes:,} edges not shared by exactly two "
                         "triangles), so it has no inside for CSG")
    return src


def open_edges(faces: np.ndarray) -> int:
    """Edges of a triangle mesh not shared by exactly two of its triangles."""
    f = np.asarray(faces, np.int64)
    if len(f) == 0:
        return 0
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.sum(counts != 2))
