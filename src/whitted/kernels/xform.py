"""Affine maps of rays, points and normals between world space and a primitive's own space
(the 3x4 world-to-object matrices of ``GeometryArrays.xforms``)."""

from __future__ import annotations

from ..jit import kernel
from .vec import normalize


@kernel
def to_object(xforms, xf, o, d):
    """Ray (o, d) mapped by the world-to-object matrix ``xforms[xf]``; t is unchanged."""
    lo = (
        xforms[xf, 0, 0] * o[0]
        + xforms[xf, 0, 1] * o[1]
        + xforms[xf, 0, 2] * o[2]
        + xforms[xf, 0, 3],
        xforms[xf, 1, 0] * o[0]
        + xforms[xf, 1, 1] * o[1]
        + xforms[xf, 1, 2] * o[2]
        + xforms[xf, 1, 3],
        xforms[xf, 2, 0] * o[0]
        + xforms[xf, 2, 1] * o[1]
        + xforms[xf, 2, 2] * o[2]
        + xforms[xf, 2, 3],
    )
    ld = (
        xforms[xf, 0, 0] * d[0] + xforms[xf, 0, 1] * d[1] + xforms[xf, 0, 2] * d[2],
        xforms[xf, 1, 0] * d[0] + xforms[xf, 1, 1] * d[1] + xforms[xf, 1, 2] * d[2],
        xforms[xf, 2, 0] * d[0] + xforms[xf, 2, 1] * d[1] + xforms[xf, 2, 2] * d[2],
    )
    return lo, ld


@kernel
def normal_to_world(m, xf, n):
    """Normals map by the transpose of the world-to-object matrix, which keeps them
    perpendicular to the surface even under non-uniform scale."""
    return normalize(
        (
            m[xf, 0, 0] * n[0] + m[xf, 1, 0] * n[1] + m[xf, 2, 0] * n[2],
            m[xf, 0, 1] * n[0] + m[xf, 1, 1] * n[1] + m[xf, 2, 1] * n[2],
            m[xf, 0, 2] * n[0] + m[xf, 1, 2] * n[1] + m[xf, 2, 2] * n[2],
        )
    )
