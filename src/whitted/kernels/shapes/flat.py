"""What the flat shapes (plane, rectangle, disk, triangle) share: where a ray meets their
plane, and how far past their edges a hit still counts."""

from __future__ import annotations

from ...jit import kernel
from ..vec import dot, sub
from . import INF

# Flat shapes accept hits a hair outside their edges (in parametric units): rays through a
# shared edge of two rectangles or triangles never slip between them.
EDGE_TOL = 1e-9


@kernel
def plane_t(p0, n, o, d):
    """t where the ray ``o + t d`` meets the plane through ``p0`` with normal ``n`` (INF:
    parallel to it)."""
    denom = dot(n, d)
    if denom == 0.0:
        return INF
    return dot(sub(p0, o), n) / denom
