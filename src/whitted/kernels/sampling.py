"""Deterministic random numbers (a counter-based hash, so every pixel draws the same numbers
whatever thread renders it) and the sample warps that use them."""

from __future__ import annotations

import math

from ..jit import kernel

MASK32 = 0xFFFFFFFF
INV_2_32 = 1.0 / 4294967296.0


@kernel
def mix32(x):
    """A 32-bit integer finaliser with good avalanche (xor-shift-multiply, 'lowbias32')."""
    x &= MASK32
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK32
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK32
    x ^= x >> 16
    return x


@kernel
def random01(seed, pixel, sample, dim):
    """Uniform number in [0, 1) determined only by (seed, pixel, sample, dim)."""
    # int(): the products need 64 bits whatever integer type the caller holds (as plain
    # Python a NumPy int32 would overflow; compiled, the arguments are int64 already)
    h = mix32(int(sample) * 0x27D4EB2F + dim)
    h = mix32(int(pixel) * 0x85EBCA77 + h)
    if int(pixel) >> 32:  # a key past 32 bits (an adaptive grid's points of a huge image)
        h = mix32((int(pixel) >> 32) * 0x85EBCA77 + h)
    h = mix32(int(seed) * 0x9E3779B1 + h)
    return h * INV_2_32


@kernel
def random_pair(seed, pixel, sample, dim):
    """Two uniform numbers in [0, 1) determined only by (seed, pixel, sample, dim): the
    first as :func:`random01` draws it, the second hashed on from the first. One chain of
    dependent steps: four mixes instead of six, and nothing for the compiler to pack into
    64-bit vector multiplies, which x86 lacks (that doubled the cost of sampling)."""
    # int(): the products need 64 bits whatever integer type the caller holds (as plain
    # Python a NumPy int32 would overflow; compiled, the arguments are int64 already)
    h = mix32(int(sample) * 0x27D4EB2F + dim)
    h = mix32(int(pixel) * 0x85EBCA77 + h)
    if int(pixel) >> 32:  # as random01: keys apart by 2**32 draw different numbers
        h = mix32((int(pixel) >> 32) * 0x85EBCA77 + h)
    h = mix32(int(seed) * 0x9E3779B1 + h)
    return h * INV_2_32, mix32(h + 0x632BE5AB) * INV_2_32


@kernel
def stratum(index, count):
    """Cell (column, row) and grid size (m, rows) of sample ``index`` out of ``count`` on a
    near-square grid, for stratified sampling of the unit square."""
    m = int(math.ceil(math.sqrt(count)))
    rows = (count + m - 1) // m
    return index % m, index // m, m, rows


@kernel
def concentric_disk(u, v):
    """Shirley–Chiu map of the unit square onto the unit disk (keeps strata compact)."""
    a = 2.0 * u - 1.0
    b = 2.0 * v - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0
    if abs(a) > abs(b):
        r = a
        phi = (math.pi / 4.0) * (b / a)
    else:
        r = b
        phi = (math.pi / 2.0) - (math.pi / 4.0) * (a / b)
    return r * math.cos(phi), r * math.sin(phi)


SAMPLE_CHUNK = 64  # an area light's samples drawn ahead at a time (:func:`stratified_disk`)


@kernel
def stratified_disk(seed, pixel, sample, dim, cx, cy, m_cols, m_rows, count, out, first):
    """The next ``count`` points of the unit disk of an area light's stratified samples: the
    grid of ``m_cols`` x ``m_rows`` cells walked cell by cell from cell (``cx``, ``cy``)
    (exclusive), one jittered point a cell, point k from the random pair of dimensions
    ``dim + 2k``, ``dim + 2k + 1``, mapped by :func:`concentric_disk`; it goes to
    ``out[first + 2k]``, ``out[first + 2k + 1]``. Returns (dim, cx, cy) after them.

    The same numbers as drawing each point where its shadow ray is traced, found faster: the
    random pairs in a loop of their own (independent integer hashes, which the compiler
    packs into vector lanes), then the points in another, which holds few values across the
    call to the sine and cosine (every vector register is the caller's to save), where the
    loop of the shadow rays held many. ``out[first:]`` holds the pairs in between."""
    for k in range(count):
        ju, jw = random_pair(seed, pixel, sample, dim + 2 * k)
        out[first + 2 * k] = ju
        out[first + 2 * k + 1] = jw
    for k in range(count):
        cx += 1
        if cx == m_cols:
            cx = 0
            cy += 1
        u = (cx + out[first + 2 * k]) / m_cols
        w = (cy + out[first + 2 * k + 1]) / m_rows
        dx, dy = concentric_disk(u, w)
        out[first + 2 * k] = dx
        out[first + 2 * k + 1] = dy
    return dim + 2 * count, cx, cy
