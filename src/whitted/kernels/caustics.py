"""The caustics' side of the render kernel: the photon map's gather, and the test that
turns it on in renders with caustics (docs/caustics.md).

Caustics are a run-time choice of the one render kernel, not a kind compiled of its own: a
render without caustics passes a ``LightArrays`` whose ``photon_grid`` holds no pass
(layout.GRID_PASS entries), and :func:`caustics_on` reads that while it runs. Measured side by
side (docs/performance.md, the variant table), a render kernel compiled without the gather
was within 3 % of this one on scenes without caustics, and each kind cost a full compile of
the render kernel (the render tree again, for each kind of geometry); the images are the same
bit for bit.
"""

from __future__ import annotations

import math

from ..jit import kernel
from .layout import (
    GRID_BITS,
    GRID_INV_CELL,
    GRID_PASS,
    GRID_R2_MAX,
    MAT_KD,
    PHOTON_DIRECTION,
    PHOTON_PASS,
    PHOTON_POWER,
)

#: a photon counts at a point only when it lies within this fraction of the gather radius
#: of the point's tangent plane (no light leaks round corners onto walls)
PLANE_FRACTION = 0.5


@kernel(inline="always")
def caustics_on(lights):
    """True when the render has a photon map: its grid holds at least one pass (the photon
    map may still be empty, when no photon reached a clear or mirrored body)."""
    return lights.photon_grid.shape[0] > GRID_PASS


@kernel(inline="always")
def cell_hash(ix, iy, iz, bits):
    """Row of the photon grid's hash table for integer cell (ix, iy, iz): the cell's
    coordinates modulo 2^bits, packed. Cells fewer than 2^bits apart on every axis never
    share a row, so the 3x3x3 cells around a point are always distinct rows."""
    m = (1 << bits) - 1
    return (ix & m) | ((iy & m) << bits) | ((iz & m) << (2 * bits))


@kernel(inline="always")
def cell_of(x, inv_cell):
    return int(math.floor(x * inv_cell))


@kernel
def caustic_irradiance(lights, p, n, shadows):
    """Irradiance (per channel) the photon map gives at point ``p`` of a surface whose unit
    normal ``n`` faces the side being shaded: the photons of each pass within that pass's
    radius of ``p``, arriving on that side and near the tangent plane, weighted by the
    Epanechnikov kernel ``2 / (pi r^2) (1 - d^2 / r^2)``, averaged over the passes; with
    ``shadows`` the shadow photons' estimate (negative: the light the direct term counts and
    the clear bodies take away) is added, made the same way. The two are one estimator, never
    faded or cut where photons are few: each photon's kernel integrates to its power, so the
    light a region gets is counted in full however thinly it is spread, and where a clear
    body bends nothing its caustic and shadow photons cancel exactly. The grid's cells are the
    largest radius: the ball around ``p`` meets at most 3x3x3 of them, each its own row of
    the hash table (:func:`cell_hash`)."""
    grid = lights.photon_grid
    photons = lights.photons
    cells = lights.photon_cells
    inv_cell = grid[GRID_INV_CELL]
    bits = int(grid[GRID_BITS])
    r2_max = grid[GRID_R2_MAX]
    r = math.sqrt(r2_max)
    ix0 = cell_of(p[0] - r, inv_cell)
    iy0 = cell_of(p[1] - r, inv_cell)
    iz0 = cell_of(p[2] - r, inv_cell)
    ix1 = cell_of(p[0] + r, inv_cell)
    iy1 = cell_of(p[1] + r, inv_cell)
    iz1 = cell_of(p[2] + r, inv_cell)
    e0 = 0.0
    e1 = 0.0
    e2 = 0.0
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    for ix in range(ix0, ix1 + 1):
        for iy in range(iy0, iy1 + 1):
            for iz in range(iz0, iz1 + 1):
                h = cell_hash(ix, iy, iz, bits)
                for q in range(cells[h], cells[h + 1]):
                    ox = photons[q, 0] - p[0]
                    oy = photons[q, 1] - p[1]
                    oz = photons[q, 2] - p[2]
                    d2 = ox * ox + oy * oy + oz * oz
                    if d2 >= r2_max:
                        continue
                    s = GRID_PASS + 2 * int(photons[q, PHOTON_PASS])
                    r2 = grid[s]
                    if d2 >= r2:
                        continue
                    if (photons[q, PHOTON_DIRECTION] * n[0]
                            + photons[q, PHOTON_DIRECTION + 1] * n[1]
                            + photons[q, PHOTON_DIRECTION + 2] * n[2]) >= 0.0:
                        continue  # it arrived on the other side
                    off = ox * n[0] + oy * n[1] + oz * n[2]
                    if off * off > PLANE_FRACTION * PLANE_FRACTION * r2:
                        continue
                    w = (1.0 - d2 / r2) * grid[s + 1]
                    c0 = photons[q, PHOTON_POWER]
                    c1 = photons[q, PHOTON_POWER + 1]
                    c2 = photons[q, PHOTON_POWER + 2]
                    if c0 + c1 + c2 < 0.0:  # a shadow photon
                        s0 += w * c0
                        s1 += w * c1
                        s2 += w * c2
                        continue
                    e0 += w * c0
                    e1 += w * c1
                    e2 += w * c2
    if shadows:
        return e0 + s0, e1 + s1, e2 + s2
    return e0, e1, e2


@kernel(entry=True)  # called from Python: the photon map's estimate at given points
def irradiance_at(lights, points, normals, shadows, out):
    """:func:`caustic_irradiance` at each row of ``points`` (with unit ``normals``) into
    ``out`` (tests, docs/caustics.md's validation)."""
    for i in range(points.shape[0]):
        e = caustic_irradiance(lights, (points[i, 0], points[i, 1], points[i, 2]),
                               (normals[i, 0], normals[i, 1], normals[i, 2]), shadows)
        out[i, 0] = e[0]
        out[i, 1] = e[1]
        out[i, 2] = e[2]


@kernel(inline="always")  # one kernel, not two: each is compiled on its own
def add_caustic(lights, mats, m, albedo, p, n, local):
    """``local`` (a hit's direct light) plus, in renders with caustics, the caustic's diffuse
    term kd·albedo·E, E the photon map's irradiance at ``p`` (exactly as a light's direct
    term enters); ``local`` unchanged without caustics."""
    if not caustics_on(lights):
        return local
    kd = mats[m, MAT_KD]
    if kd == 0.0:
        return local
    e = caustic_irradiance(lights, p, n, True)
    # the shadow photons take away what the direct term counts: never more, but for noise
    return (max(0.0, local[0] + kd * albedo[0] * e[0]),
            max(0.0, local[1] + kd * albedo[1] * e[1]),
            max(0.0, local[2] + kd * albedo[2] * e[2]))
