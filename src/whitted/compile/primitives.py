"""The primitive table the kernels read, gathered row by row (analytic shapes) or block by
block (flattened meshes) and joined when the scene is complete."""

from __future__ import annotations

import numpy as np

from ..kernels.layout import N_PRIM_PARAMS


class PrimitiveRows:
    """Primitive rows, gathered in blocks (one row per analytic shape, one block per
    flattened mesh) and joined at the end."""

    def __init__(self) -> None:
        self.blocks: list[tuple] = []
        self.xforms: list[np.ndarray] = []
        # rows that are the leaves or operations of a CSG object: in no BVH (compile/csg.py),
        # with their PRIM_FLIP and PRIM_MEDIUM columns
        self.csg_rows: dict[int, tuple[int, int]] = {}
        self.rows = 0

    def add(self, typ, values, lo, hi, *, material, obj, solid, world_to_object=None):
        row = np.zeros((1, N_PRIM_PARAMS))
        row[0, : len(values)] = values
        xf = -1
        if world_to_object is not None:
            xf = len(self.xforms)
            self.xforms.append(world_to_object[:3, :4])
        self.add_block(typ, row, np.asarray(lo, np.float64).reshape(1, 3),
                       np.asarray(hi, np.float64).reshape(1, 3), material, obj, solid, xf)

    def add_block(self, typ, params, lo, hi, material, obj, solid, xf=-1):
        k = len(params)
        self.rows += k
        self.blocks.append((np.full(k, typ, np.int32), params, np.full(k, xf, np.int32),
                            np.broadcast_to(np.asarray(material, np.int32), (k,)),
                            np.full(k, obj, np.int32), np.full(k, int(solid), np.int32),
                            lo, hi))

    def columns(self):
        """types, params, xform index, material, object, solid, lo, hi: joined arrays."""
        if not self.blocks:
            return (np.zeros(0, np.int32), np.zeros((0, N_PRIM_PARAMS)), np.zeros(0, np.int32),
                    np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0, np.int32),
                    np.zeros((0, 3)), np.zeros((0, 3)))
        return tuple(np.concatenate([blk[k] for blk in self.blocks]) for k in range(8))

    def extra_columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(walked, flip, medium) per row: whether a BVH walk may meet the row (CSG leaves
        and operations are reached through their object), PRIM_FLIP and PRIM_MEDIUM."""
        walked = np.ones(self.rows, bool)
        flip = np.zeros(self.rows, np.int32)
        medium = np.full(self.rows, -1, np.int32)
        for row, (f, m) in self.csg_rows.items():
            walked[row] = False
            flip[row] = f
            medium[row] = m
        return walked, flip, medium
