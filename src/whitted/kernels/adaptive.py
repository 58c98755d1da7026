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

The render kernel (:func:`.tiles.render_tiles`) traces the samples: it has one call of the
path tracer, for the uniform samples and these alike, so that the tracer is compiled into it
once. This module says which sample it traces next and keeps what it traced
(:func:`next_sample`): the algorithm above as a walk that stops at each sample it still
needs and resumes where it stopped, its state in the lane's scratch memory
(:func:`.tiles.adaptive_workspace`).
"""

from __future__ import annotations

from ..jit import kernel
from .camera import camera_ray, lens_ray

# the walk's state, st[...] of the scratch memory: which pass (0: the tile's corners, 1: its
# pixels), the corner or pixel it is at, whether that pixel's squares are being split (their
# stack then holds them), the stack's top, and the grid point (i, j) whose sample is awaited
# (the corner pass: the corner's column and row in the tile), and whether it is awaited
ST_PASS = 0
ST_INDEX = 1
ST_SPLITTING = 2
ST_TOP = 3
ST_I = 4
ST_J = 5
ST_PENDING = 6
N_STATE = 7


@kernel(numba_inline=True)  # Numba inlines it into next_sample: one compile fewer
def corners_differ(g, i0, j0, i1, j1, threshold):
    """Do the four corners (i0|i1, j0|j1) of the sample grid ``g`` differ by more than
    ``threshold`` (any pair)? The distance of two samples is POV-Ray's (clamped to
    displayable values)."""
    for a in range(4):
        ia = i0 if a % 2 == 0 else i1
        ja = j0 if a < 2 else j1
        for b in range(a + 1, 4):
            ib = i0 if b % 2 == 0 else i1
            jb = j0 if b < 2 else j1
            if (abs(min(max(g[ja, ia, 0], 0.0), 1.0) - min(max(g[jb, ib, 0], 0.0), 1.0))
                    + abs(min(max(g[ja, ia, 1], 0.0), 1.0) - min(max(g[jb, ib, 1], 0.0), 1.0))
                    + abs(min(max(g[ja, ia, 2], 0.0), 1.0)
                          - min(max(g[jb, ib, 2], 0.0), 1.0))) > threshold:
                return True
    return False


@kernel
def next_sample(params, x0, y0, x1, y1, levels, threshold, framebuffer, aa, c):
    """The camera ray (o, d) of the sample the tile (x0, y0, x1, y1) needs next and its
    sampler's "pixel" (the point's index in the image's finest grid), or a key of -1 once
    every pixel of the tile is in ``framebuffer``. ``c``: the sample (r, g, b) traced for
    the ray of the call before (not read at the tile's first call). ``aa``: the lane's
    scratch memory (:func:`.tiles.adaptive_workspace`), its state zeroed at the tile's
    start.

    First the corners of every pixel, row by row; then pixel by pixel: a pixel whose corners
    differ has its squares split (a stack of squares, depth first: a square's four corners,
    then its four quarters while they differ) until no square needs a sample not yet traced;
    its colour is then the squares' area-weighted mean.

    The ray is made after the walk's loop, as the kernel that traced each sample made it
    before the render kernel traced them all: made inside a loop whose divisors do not
    change, LLVM may multiply by a reciprocal instead (fast-math's ``arcp``), and a ray
    through the image's centre (x exactly half the width) would no longer be exactly
    straight ahead: images would change in their last bits, and at an edge on that line more.
    """
    corners, grid, known, squares, st, acc = aa
    fine = 1 << levels
    if st[ST_PENDING] != 0:  # keep the sample asked for last
        i = st[ST_I]
        j = st[ST_J]
        if st[ST_PASS] == 0:  # a corner of the tile's pixels
            for k in range(3):
                corners[j, i, k] = c[k]
            st[ST_INDEX] += 1
        else:  # a point of the pixel's sample grid
            for k in range(3):
                grid[j, i, k] = c[k]
            known[j, i] = 1
    gx = -1
    gy = -1
    cols = x1 - x0 + 1
    w = x1 - x0
    while True:
        if st[ST_PASS] == 0:
            k = st[ST_INDEX]
            if k < (y1 - y0 + 1) * cols:
                cy = k // cols
                cx = k - cy * cols
                st[ST_I] = cx
                st[ST_J] = cy
                gx = (x0 + cx) * fine
                gy = (y0 + cy) * fine
                break
            st[ST_PASS] = 1
            st[ST_INDEX] = 0
            st[ST_SPLITTING] = 0
        if st[ST_INDEX] >= (y1 - y0) * w:
            break
        cy = st[ST_INDEX] // w
        cx = st[ST_INDEX] - cy * w
        px = x0 + cx
        py = y0 + cy
        if st[ST_SPLITTING] == 0:
            for k in range(3):  # the pixel's corners into its sample grid
                grid[0, 0, k] = corners[cy, cx, k]
                grid[0, fine, k] = corners[cy, cx + 1, k]
                grid[fine, 0, k] = corners[cy + 1, cx, k]
                grid[fine, fine, k] = corners[cy + 1, cx + 1, k]
            if not (levels > 0 and corners_differ(grid, 0, 0, fine, fine, threshold)):
                for k in range(3):  # the mean of its corners
                    framebuffer[py, px, k] = 0.25 * (grid[0, 0, k] + grid[0, fine, k]
                                                     + grid[fine, 0, k] + grid[fine, fine, k])
                st[ST_INDEX] += 1
                continue
            for j in range(fine + 1):
                for i in range(fine + 1):
                    known[j, i] = 0
            known[0, 0] = 1
            known[0, fine] = 1
            known[fine, 0] = 1
            known[fine, fine] = 1
            squares[0, 0] = 0
            squares[0, 1] = 0
            squares[0, 2] = fine
            st[ST_TOP] = 0
            st[ST_SPLITTING] = 1
            for k in range(3):
                acc[k] = 0.0
        top = st[ST_TOP]
        if top < 0:  # every square counted: the pixel's colour
            inv = 1.0 / (fine * fine)
            for k in range(3):
                framebuffer[py, px, k] = acc[k] * inv
            st[ST_SPLITTING] = 0
            st[ST_INDEX] += 1
            continue
        # the square on top of the stack stays there until its four corners are traced,
        # then it is split or counted
        i = squares[top, 0]
        j = squares[top, 1]
        size = squares[top, 2]
        for q in range(4):
            ci = i + (size if q % 2 else 0)
            cj = j + (size if q >= 2 else 0)
            if known[cj, ci] == 0:  # this corner's sample first
                gx = px * fine + ci
                gy = py * fine + cj
                st[ST_I] = ci
                st[ST_J] = cj
                break
        if gx >= 0:
            break
        top -= 1
        if size > 1 and corners_differ(grid, i, j, i + size, j + size, threshold):
            half = size // 2
            for q in range(4):
                top += 1
                squares[top, 0] = i + (half if q % 2 else 0)
                squares[top, 1] = j + (half if q >= 2 else 0)
                squares[top, 2] = half
        else:
            w4 = 0.25 * size * size
            for k in range(3):
                acc[k] += (grid[j, i, k] + grid[j, i + size, k] + grid[j + size, i, k]
                           + grid[j + size, i + size, k]) * w4
        st[ST_TOP] = top
    st[ST_PENDING] = gx >= 0
    if gx < 0:
        return params.camera_origin, params.camera_forward, -1
    key = gy * (params.width * fine + 1) + gx
    o, d = camera_ray(params, gx / fine, gy / fine)
    if params.focal_distance > 0.0:  # focal blur (0: a pinhole)
        o, d = lens_ray(params, o, d, key, 0)
    return o, d, key

