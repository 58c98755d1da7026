"""Adaptive anti-aliasing in the spirit of POV-Ray's method 2 (``+A0.3 +AM2 +R3``).

Every pixel's four corners are traced; a pixel whose corners differ by more than the
threshold (POV-Ray's colour distance: the sum of the absolute differences of the red, green
and blue values, clamped to [0, 1]) is split into four squares, each split again while its
own corners differ, down to ``levels`` splits (a grid of 2^levels + 1 samples a side at
most). A square that is not split counts as the mean of its corners; the pixel is the mean
of its squares weighted by their area.

A sample's position is a point of the image's finest grid (1 / 2^levels of a pixel), and
its value depends only on that point: its random numbers (area lights, the lens) are drawn
with the point's index in the grid as the "pixel". Neighbouring pixels share their corners
(traced once per tile) and their split edges (traced by each pixel that needs them, to the
same value), so no tile depends on another, and the image is the same whatever the thread
count or the order of the tiles.
"""

from __future__ import annotations

import numpy as np

from ..jit import kernel, numba_object
from .integrator import trace_path
from .layout import N_RAY_KINDS, RAY_PRIMARY
from .tiles import camera_ray, lens_ray, own_lines

geometry_ref_if_instances = numba_object(f"{__package__}.geometry_ref",
                                         "geometry_ref_if_instances")
def adaptive_workspace(tile_width: int, tile_height: int, levels: int):
    """Scratch memory of one lane: the corners of a tile's pixels, one pixel's sample grid
    and its marks, and the stack of squares to visit (three per level and the first)."""
    side = (1 << levels) + 1
    return (own_lines((tile_height + 1, tile_width + 1, 3)), own_lines((side, side, 3)),
            own_lines((side, side), np.int8), own_lines((3 * levels + 2, 3), np.int32))


@kernel  # one call site of trace_path (which Numba inlines into it)
def _sample(geo, mats, lights, params, gx, gy, fine, work, cnt):
    """Radiance through the point (gx, gy) of the image's finest grid."""
    st_f, st_i, media, scratch, stack, hits, listed, _ = work
    key = gy * (params.width * fine + 1) + gx
    o, d = camera_ray(params, gx / fine, gy / fine)
    if params.focal_distance > 0.0:
        o, d = lens_ray(params, o, d, key, 0)
    cnt[RAY_PRIMARY] += 1
    return trace_path(geo, mats, lights, params, o, d, key, 0, st_f, st_i, media, scratch,
                      stack, hits, listed, cnt)


@kernel
def _clamp01(x):
    return min(max(x, 0.0), 1.0)


@kernel
def _distance(a0, a1, a2, b0, b1, b2):
    """POV-Ray's colour distance of two samples (clamped to displayable values)."""
    return (abs(_clamp01(a0) - _clamp01(b0)) + abs(_clamp01(a1) - _clamp01(b1))
            + abs(_clamp01(a2) - _clamp01(b2)))


@kernel
def corners_differ(g, i0, j0, i1, j1, threshold):
    """Do the four corners (i0|i1, j0|j1) of the sample grid ``g`` differ by more than
    ``threshold`` (any pair)?"""
    for a in range(4):
        ia = i0 if a % 2 == 0 else i1
        ja = j0 if a < 2 else j1
        for b in range(a + 1, 4):
            ib = i0 if b % 2 == 0 else i1
            jb = j0 if b < 2 else j1
            if _distance(g[ja, ia, 0], g[ja, ia, 1], g[ja, ia, 2],
                         g[jb, ib, 0], g[jb, ib, 1], g[jb, ib, 2]) > threshold:
                return True
    return False


@kernel(inline="always")
def _known(geo, mats, lights, params, grid, known, gx0, gy0, i, j, fine, work, cnt):
    """Make sure point (i, j) of the pixel's sample grid is traced."""
    if known[j, i] == 0:
        c = _sample(geo, mats, lights, params, gx0 + i, gy0 + j, fine, work, cnt)
        grid[j, i, 0] = c[0]
        grid[j, i, 1] = c[1]
        grid[j, i, 2] = c[2]
        known[j, i] = 1


@kernel
def refine_pixel(geo, mats, lights, params, px, py, levels, threshold, grid, known, squares,
                 work, cnt):
    """The colour of pixel (px, py) whose corners (already in ``grid``'s corners, marked in
    ``known``) differ: its squares split while their corners differ, ``levels`` deep."""
    fine = 1 << levels
    gx0 = px * fine
    gy0 = py * fine
    r = 0.0
    g = 0.0
    b = 0.0
    top = 0
    squares[0, 0] = 0
    squares[0, 1] = 0
    squares[0, 2] = fine
    while top >= 0:
        i = squares[top, 0]
        j = squares[top, 1]
        size = squares[top, 2]
        top -= 1
        for c in range(4):
            ci = i + (size if c % 2 else 0)
            cj = j + (size if c >= 2 else 0)
            _known(geo, mats, lights, params, grid, known, gx0, gy0, ci, cj, fine, work, cnt)
        if size > 1 and corners_differ(grid, i, j, i + size, j + size, threshold):
            half = size // 2
            for c in range(4):
                top += 1
                squares[top, 0] = i + (half if c % 2 else 0)
                squares[top, 1] = j + (half if c >= 2 else 0)
                squares[top, 2] = half
            continue
        w = 0.25 * size * size
        for k in range(3):
            s = (grid[j, i, k] + grid[j, i + size, k] + grid[j + size, i, k]
                 + grid[j + size, i + size, k]) * w
            if k == 0:
                r += s
            elif k == 1:
                g += s
            else:
                b += s
    inv = 1.0 / (fine * fine)
    return r * inv, g * inv, b * inv


@kernel(entry=True)  # called from Python
def render_tiles_adaptive(tiles, framebuffer, geo, mats, lights, params, counters, work, aa,
                          threshold, levels, lane, lanes):
    """:func:`.tiles.render_tiles` with adaptive anti-aliasing (see the module docstring).
    ``aa`` is the lane's scratch memory from :func:`adaptive_workspace`."""
    geo = geometry_ref_if_instances(geo)
    corners, grid, known, squares = aa
    fine = 1 << levels
    cnt = work[7]  # the lane's own counts, stored in counters[t] once a tile (render_tiles)
    for t in range(lane, tiles.shape[0], lanes):
        for k in range(N_RAY_KINDS):
            cnt[k] = 0
        x0 = tiles[t, 0]
        y0 = tiles[t, 1]
        x1 = tiles[t, 2]
        y1 = tiles[t, 3]
        for cy in range(y1 - y0 + 1):
            for cx in range(x1 - x0 + 1):
                c = _sample(geo, mats, lights, params, (x0 + cx) * fine, (y0 + cy) * fine,
                            fine, work, cnt)
                corners[cy, cx, 0] = c[0]
                corners[cy, cx, 1] = c[1]
                corners[cy, cx, 2] = c[2]
        for py in range(y0, y1):
            for px in range(x0, x1):
                cy = py - y0
                cx = px - x0
                for k in range(3):  # the pixel's corners into its sample grid
                    grid[0, 0, k] = corners[cy, cx, k]
                    grid[0, fine, k] = corners[cy, cx + 1, k]
                    grid[fine, 0, k] = corners[cy + 1, cx, k]
                    grid[fine, fine, k] = corners[cy + 1, cx + 1, k]
                if levels > 0 and corners_differ(grid, 0, 0, fine, fine, threshold):
                    for j in range(fine + 1):
                        for i in range(fine + 1):
                            known[j, i] = 0
                    known[0, 0] = 1
                    known[0, fine] = 1
                    known[fine, 0] = 1
                    known[fine, fine] = 1
                    col = refine_pixel(geo, mats, lights, params, px, py, levels, threshold,
                                       grid, known, squares, work, cnt)
                else:
                    col = (
                        0.25 * (grid[0, 0, 0] + grid[0, fine, 0] + grid[fine, 0, 0]
                                + grid[fine, fine, 0]),
                        0.25 * (grid[0, 0, 1] + grid[0, fine, 1] + grid[fine, 0, 1]
                                + grid[fine, fine, 1]),
                        0.25 * (grid[0, 0, 2] + grid[0, fine, 2] + grid[fine, 0, 2]
                                + grid[fine, fine, 2]),
                    )
                framebuffer[py, px, 0] = col[0]
                framebuffer[py, px, 1] = col[1]
                framebuffer[py, px, 2] = col[2]
        for k in range(N_RAY_KINDS):
            counters[t, k] = cnt[k]
