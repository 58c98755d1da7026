"""kernels/prefetch.py: the prefetch hint compiles to the CPU's prefetch instruction at the
address of the row asked for, and changes no value the kernel computes."""

from __future__ import annotations

import numpy as np
from numba import njit

from whitted.kernels.prefetch import prefetch_row


@njit(cache=False)
def _sum_rows(faces, normals, rows):
    """Sums of the rows picked, each row prefetched first (both kinds of array)."""
    total = 0
    shade = 0.0
    for k in range(rows.shape[0]):
        r = rows[k]
        prefetch_row(faces, r)
        prefetch_row(normals, r)
        total += faces[r, 0] + faces[r, 1] + faces[r, 2]
        shade += normals[r, 2, 1]
    return total, shade


def test_a_prefetch_changes_no_value():
    rng = np.random.default_rng(5)
    faces = rng.integers(0, 1000, (500, 3)).astype(np.int32)
    normals = rng.standard_normal((500, 3, 3)).astype(np.float32)
    rows = rng.integers(0, 500, 300)
    total, shade = _sum_rows(faces, normals, rows)
    assert total == int(faces[rows].astype(np.int64).sum())
    want = 0.0
    for r in rows:
        want += float(normals[r, 2, 1])
    assert shade == want


def test_a_prefetch_is_the_cpus_prefetch_instruction():
    faces = np.zeros((4, 3), np.int32)
    normals = np.zeros((4, 3, 3), np.float32)
    _sum_rows(faces, normals, np.array([1, 2]))
    asm = _sum_rows.inspect_asm(_sum_rows.signatures[0])
    # x86: prefetcht0; AArch64: prfm pldl1keep
    assert "prefetcht0" in asm or "prfm" in asm


def test_a_prefetch_refuses_what_is_not_a_row():
    import pytest
    from numba.core.errors import TypingError

    @njit(cache=False)
    def flat(a):
        prefetch_row(a, 0)

    with pytest.raises(TypingError):
        flat(np.zeros(4))
