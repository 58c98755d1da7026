"""Light buffers: which primitives could shadow a point light, listed per direction.

The directions leaving a point light are divided into the cells of a cube map around it,
``LIGHT_BUFFER_RES`` x ``LIGHT_BUFFER_RES`` per face. For every cell the compiler lists the
analytic primitives whose boxes meet the pyramid of rays through that cell (and the unbounded
ones those rays can reach), then the leaves of the instance BVH whose boxes meet it; a shadow
ray toward the light lies inside the pyramid of the cell its direction falls in, so it needs
to test only that cell's list instead of walking the BVHs.
Seen from a light most cells hold nothing or a primitive or two: the shadow ray's cost is then
a handful of arithmetic. POV-Ray calls the same idea a light buffer.

Cell addressing: face 0/1 are the +x/-x faces (u = y, v = z over |x|), 2/3 the ±y faces
(u = z, v = x), 4/5 the ±z faces (u = x, v = y); u and v in [-1, 1] map to the columns and
rows of the face.
"""

from __future__ import annotations

import math

from ..jit import kernel

# Measured on the seed000 benchmark (CPU-time medians; 0.577 s without light buffers): 32
# cells a side 0.538 s, 64: 0.531 s, 128: 0.527 s (lists of at most 16 primitives); at 128, a
# cap of 6-10 primitives 0.527 s, 16: 0.535 s, 32: 0.538 s. A long list costs more than the
# walk it replaces.
LIGHT_BUFFER_RES = 128  # cells along a cube-face side
LIGHT_BUFFER_CAP = 12  # primitives a cell may list; shadow rays through a cell with more walk
LIGHT_BUFFER_CELLS = 1 << 20  # all point lights' cells together (12 bytes each) at most


@kernel
def cube_face(w):
    """(face, major component magnitude, u component, v component) of direction ``w``."""
    ax = abs(w[0])
    ay = abs(w[1])
    az = abs(w[2])
    if ax >= ay and ax >= az:
        return (0 if w[0] > 0.0 else 1), ax, w[1], w[2]
    if ay >= az:
        return (2 if w[1] > 0.0 else 3), ay, w[2], w[0]
    return (4 if w[2] > 0.0 else 5), az, w[0], w[1]


@kernel
def _cell_index(x, major, res):
    i = int((x / major + 1.0) * (0.5 * res))
    return min(max(i, 0), res - 1)


@kernel
def cube_cell(w, res):
    """Row (within one light's block of 6·res² cells) of the cell direction ``w`` (nonzero)
    from the light falls in."""
    face, major, u, v = cube_face(w)
    return (face * res + _cell_index(u, major, res)) * res + _cell_index(v, major, res)


@kernel
def cell_direction(face, u, v):
    """The direction (not unit) with cube-face coordinates (u, v) on ``face``."""
    s = 1.0 if face % 2 == 0 else -1.0
    axis = face // 2
    if axis == 0:
        return (s, u, v)
    if axis == 1:
        return (v, s, u)
    return (u, v, s)


@kernel
def cell_cone(cell, res):
    """(unit axis, tangent of the half-angle) of a cone that holds every direction of
    ``cell``: its axis through the cell's centre, its half-angle reaching the farthest corner."""
    face = cell // (res * res)
    iu = (cell // res) % res
    iv = cell % res
    u0 = -1.0 + 2.0 * iu / res
    u1 = -1.0 + 2.0 * (iu + 1) / res
    v0 = -1.0 + 2.0 * iv / res
    v1 = -1.0 + 2.0 * (iv + 1) / res
    c = cell_direction(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
    inv = 1.0 / math.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
    c = (c[0] * inv, c[1] * inv, c[2] * inv)
    cos_min = 1.0
    for u in (u0, u1):
        for v in (v0, v1):
            q = cell_direction(face, u, v)
            cos_q = (c[0] * q[0] + c[1] * q[1] + c[2] * q[2]) / math.sqrt(
                q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
            cos_min = min(cos_min, cos_q)
    return c, math.sqrt(max(0.0, 1.0 - cos_min * cos_min)) / cos_min
