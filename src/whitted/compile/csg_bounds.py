"""A tighter box for a CSG difference cut by boxes.

The box of ``difference { A, B, ... }`` is A's box: nothing outside A shows. When a cutter is
an axis-aligned box (in the difference's own frame) that holds A's box across two axes, it
takes a slab off A's box along the third: half a ring cut by a box that covers one half is
bounded by the other half, and rays through the cut-away half skip the walk (and the
torus's quartic) altogether. The clipped box, taken to the world by the difference's own
matrix, meets the box from the children's world boxes; what shows lies inside both.
"""

from __future__ import annotations

import numpy as np

from ..scene.shapes import CSG, Box, Mesh
from .primitives import PrimitiveRows
from .shapes import add_shape

PAD = 1e-9  # relative slack on the clipped box (the cut face lies on its side)


def _transform(shape) -> np.ndarray:
    return shape.transform.matrix() if shape.transform is not None else np.eye(4)


def _local_box(shape) -> tuple[np.ndarray, np.ndarray] | None:
    """The box of an analytic child in the difference's own frame (None for a CSG or mesh
    child, whose box is not worked out here)."""
    if isinstance(shape, (CSG, Mesh)):
        return None
    rows = PrimitiveRows()
    add_shape(rows, shape, _transform(shape), 0, 0)
    block = rows.blocks[-1]
    return block[6][0].astype(np.float64), block[7][0].astype(np.float64)


def _aligned_box(shape) -> tuple[np.ndarray, np.ndarray] | None:
    """The exact region of a cutter that is a box with faces along the difference's axes
    (``min``/``max``, moved, scaled or turned by right angles), else None."""
    if not isinstance(shape, Box) or shape.min is None:
        return None
    lin = _transform(shape)[:3, :3]
    if not all(np.count_nonzero(lin[k]) == 1 and np.count_nonzero(lin[:, k]) == 1
               for k in range(3)):
        return None
    return _local_box(shape)


def clipped_bounds(shape: CSG, matrix: np.ndarray, lo: np.ndarray,
                   hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi): the world box ``lo``, ``hi`` of difference ``shape`` (world matrix
    ``matrix``), made smaller where box cutters take slabs off its first operand's box."""
    if shape.operation != "difference":
        return lo, hi
    first = _local_box(shape.objects[0])
    if first is None:
        return lo, hi
    a_lo, a_hi = first
    clipped = False
    for cut in shape.objects[1:]:
        box = _aligned_box(cut)
        if box is None:
            continue
        c_lo, c_hi = box
        for k in range(3):
            others = [j for j in range(3) if j != k]
            if not all(c_lo[j] <= a_lo[j] and c_hi[j] >= a_hi[j] for j in others):
                continue
            if c_lo[k] <= a_lo[k] < c_hi[k] < a_hi[k]:  # takes the low slab
                a_lo[k] = c_hi[k]
                clipped = True
            elif a_lo[k] < c_lo[k] < a_hi[k] <= c_hi[k]:  # takes the high slab
                a_hi[k] = c_lo[k]
                clipped = True
    if not clipped:
        return lo, hi
    pad = PAD * max(1.0, float(np.max(a_hi - a_lo)))
    corners = np.array([[x, y, z] for x in (a_lo[0] - pad, a_hi[0] + pad)
                        for y in (a_lo[1] - pad, a_hi[1] + pad)
                        for z in (a_lo[2] - pad, a_hi[2] + pad)])
    world = corners @ matrix[:3, :3].T + matrix[:3, 3]
    new_lo = np.maximum(lo, world.min(axis=0))
    new_hi = np.minimum(hi, world.max(axis=0))
    return new_lo, np.maximum(new_hi, new_lo)
