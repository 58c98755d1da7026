"""CSG objects -> primitive rows: the object's row (in the scene BVH, with the box of the
whole), then its tree in postfix order, leaves as ordinary solid rows and operations as
``SHAPE_CSG_OP`` rows (see kernels/csg.py for the walk that reads them).

Materials follow POV-Ray: a child without a material takes the nearest enclosing CSG
object's, and every surface shows its own leaf's material (so the cut of a difference shows
the material of the object that cut it). The whole object is one body for refraction and
absorption: its medium is its own material, or, when it has none, its first leaf's.
"""

from __future__ import annotations

import numpy as np

from ..kernels.layout import (
    CSG_DIFFERENCE,
    CSG_INTERSECTION,
    CSG_MERGE,
    CSG_UNION,
    SHAPE_CSG,
    SHAPE_CSG_OP,
)
from ..kernels.mesh import OPAQUE_KT
from ..scene.shapes import CSG
from .primitives import PrimitiveRows
from .shapes import add_shape

OPERATION_CODES = {"union": CSG_UNION, "intersection": CSG_INTERSECTION,
                   "difference": CSG_DIFFERENCE, "merge": CSG_MERGE}


def _transform(shape) -> np.ndarray:
    return shape.transform.matrix() if shape.transform is not None else np.eye(4)


def add_csg(b: PrimitiveRows, shape: CSG, m: np.ndarray, material_row, resolve, obj: int,
            default_material) -> None:
    """Append CSG object ``shape`` (world matrix ``m``) as rows of ``b``. ``resolve`` maps a
    material reference to a Material, ``material_row`` a Material to its table row;
    ``default_material`` is the object's resolved material (used by children without)."""
    root = b.rows
    b.add(SHAPE_CSG, [0.0, 0.0], np.zeros(3), np.zeros(3), material=0, obj=obj, solid=True)
    root_block = len(b.blocks) - 1
    leaves: list[tuple[int, object, int]] = []  # (row, Material, flip)

    def walk(node: CSG, matrix: np.ndarray, inherited, flip: int):
        """Rows of ``node``'s subtree; returns its bounds (lo, hi), None when empty."""
        boxes = []
        for k, child in enumerate(node.objects):
            cm = matrix @ _transform(child)
            mat = resolve(child.material) if child.material is not None else inherited
            cflip = flip ^ (1 if node.operation == "difference" and k > 0 else 0)
            if isinstance(child, CSG):
                boxes.append(walk(child, cm, mat, cflip))
                continue
            row = b.rows
            add_shape(b, child, cm, material_row(mat), obj)
            blk = b.blocks[-1]
            leaves.append((row, mat, cflip))
            boxes.append((blk[6][0].copy(), blk[7][0].copy()))
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

    lo, hi = walk(shape, m, default_material, 0)
    body_material = default_material if shape.material is not None else leaves[0][1]
    body = material_row(body_material)
    for row, _, flip in leaves:
        b.csg_rows[row] = (flip, body)
    # the object's own row: opaque (for shadow rays) only when every leaf is
    clear = [mat for _, mat, _ in leaves if mat.kt >= OPAQUE_KT]
    typ, params, xf, _, objs, solid, _, _ = b.blocks[root_block]
    params[0, 0] = b.rows - root - 1
    params[0, 1] = len(leaves)
    material = np.array([material_row(clear[0]) if clear else body], np.int32)
    b.blocks[root_block] = (typ, params, xf, material, objs, solid, lo.reshape(1, 3),
                            hi.reshape(1, 3))
