"""An area light's points on its disk are drawn ahead of their shadow rays, a chunk at a time
(kernels/sampling.py ``stratified_disk``): they must be, bit for bit, the points drawn one
at a time where each shadow ray is traced (the stratified grid walked cell by cell, a random
pair of dimensions per point, the concentric map), whatever the count and the chunking."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from whitted.jit import kernel
from whitted.kernels.sampling import (
    SAMPLE_CHUNK,
    concentric_disk,
    random_pair,
    stratified_disk,
    stratum,
)


@kernel(entry=True, cache=False)
def _one_at_a_time(seed, pixel, sample, dim, n_samples, out):
    """The points as the shadow-ray loop drew them before, one per sample where its ray was
    traced, into ``out`` (compiled as the render kernel is: the same floating-point flags)."""
    _, _, m_cols, m_rows = stratum(0, n_samples)
    cx = -1
    cy = 0
    for s in range(n_samples):
        cx += 1
        if cx == m_cols:
            cx = 0
            cy += 1
        ju, jw = random_pair(seed, pixel, sample, dim)
        u = (cx + ju) / m_cols
        w = (cy + jw) / m_rows
        dim += 2
        dx, dy = concentric_disk(u, w)
        out[2 * s] = dx
        out[2 * s + 1] = dy


def _ahead(seed, pixel, sample, dim, n_samples, chunk, first):
    """The points drawn ahead ``chunk`` at a time into a buffer at ``first``."""
    _, _, m_cols, m_rows = stratum(0, n_samples)
    cx, cy = -1, 0
    out = np.full(first + 2 * chunk, np.nan)
    points = []
    for start in range(0, n_samples, chunk):
        count = min(chunk, n_samples - start)
        dim, cx, cy = stratified_disk(seed, pixel, sample, dim, cx, cy, m_cols, m_rows, count,
                                      out, first)
        points += [(out[first + 2 * k], out[first + 2 * k + 1]) for k in range(count)]
        assert np.isnan(out[:first]).all()  # nothing written before its place
    return points, dim


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), pixel=st.integers(0, 10**7),
       sample=st.integers(0, 255), dim=st.integers(0, 10**4),
       n_samples=st.integers(1, 3 * SAMPLE_CHUNK + 5),
       chunk=st.sampled_from([1, 7, SAMPLE_CHUNK]), first=st.integers(0, 70))
def test_points_drawn_ahead_are_the_points_drawn_one_at_a_time(seed, pixel, sample, dim,
                                                               n_samples, chunk, first):
    one = np.empty(2 * n_samples)
    _one_at_a_time(seed, pixel, sample, dim, n_samples, one)
    expected = list(zip(one[0::2], one[1::2], strict=True))
    got, dim_after = _ahead(seed, pixel, sample, dim, n_samples, chunk, first)
    assert dim_after == dim + 2 * n_samples  # the next light's dimensions start where they did
    assert len(got) == n_samples
    for (gx, gy), (ex, ey) in zip(got, expected, strict=True):
        assert gx == ex and gy == ey  # bit for bit (same operations, same order)
        assert math.hypot(gx, gy) <= 1.0 + 1e-15  # on the unit disk


def test_the_benchmark_light_walks_its_whole_grid():
    """64 samples: an 8 x 8 grid, one point in each cell's image under the concentric map."""
    points, _ = _ahead(7, 1234, 0, 2, 64, SAMPLE_CHUNK, 0)
    assert len(set(points)) == 64
    # the concentric map sends the square's cells to disk sectors; the cell of each point,
    # mapped back, is the grid's cells in order
    cells = []
    for x, y in points:
        r = math.hypot(x, y)
        phi = math.atan2(y, x)
        # inverse of the Shirley-Chiu map
        if -math.pi / 4 <= phi <= math.pi / 4:
            a, b = r, r * phi / (math.pi / 4)
        elif math.pi / 4 < phi <= 3 * math.pi / 4:
            b, a = r, r * (math.pi / 2 - phi) / (math.pi / 4)
        elif phi > 3 * math.pi / 4 or phi < -3 * math.pi / 4:
            a = -r
            b = -r * ((phi - math.pi) if phi > 0 else (phi + math.pi)) / (math.pi / 4)
        else:
            b = -r
            a = -r * (-math.pi / 2 - phi) / (math.pi / 4)
        cells.append((int((a + 1) / 2 * 8), int((b + 1) / 2 * 8)))
    assert cells == [(k % 8, k // 8) for k in range(64)]


def _lowbias32(x):
    x &= 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


def _hash_below_2_32(seed, pixel, sample, dim):
    # the hash of a key below 2**32, written out in plain Python integers
    h = _lowbias32(sample * 0x27D4EB2F + dim)
    h = _lowbias32(pixel * 0x85EBCA77 + h)
    return _lowbias32(seed * 0x9E3779B1 + h)


@given(st.integers(0, 2**31), st.integers(0, 2**32 - 1), st.integers(0, 4095),
       st.integers(0, 8))
@settings(max_examples=60, deadline=None)
def test_keys_below_32_bits_draw_the_numbers_of_the_worked_hash(seed, pixel, sample, dim):
    from whitted.kernels.sampling import random01

    assert random01(seed, pixel, sample, dim) == _hash_below_2_32(seed, pixel, sample, dim) \
        / 2.0**32


@given(st.integers(0, 2**31), st.integers(0, 2**32 - 1), st.integers(1, 2**20))
@settings(max_examples=60, deadline=None)
def test_keys_apart_by_a_multiple_of_2_32_draw_other_numbers(seed, pixel, high):
    # an adaptive grid's points of a huge image have keys past 32 bits: a key and the same
    # key plus k * 2**32 must not share their random numbers (lens and area-light samples)
    from whitted.kernels.sampling import random01, random_pair

    far = pixel + high * 2**32
    assert random01(seed, pixel, 3, 1) != random01(seed, far, 3, 1)
    assert random_pair(seed, pixel, 3, 1) != random_pair(seed, far, 3, 1)
