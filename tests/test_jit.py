"""The kernel decorator: one compiled variant per real argument type, not per integer constant."""

from __future__ import annotations

import numpy as np
from numba import types

from whitted.kernels.jit import kernel, widen_integer


@kernel(cache=False)
def _row_sum(a, i):
    return a[i, 0] + a[i, 1]


@kernel(cache=False)
def _sum_rows_by_constants(a, small):
    # constants 0 and 1, an int32 and an int64: all one int64 variant of _row_sum
    return _row_sum(a, 0) + _row_sum(a, 1) + _row_sum(a, small[0]) + _row_sum(a, np.int64(2))


@kernel(cache=False, specialise_constants=True)
def _row_sum_per_constant(a, i):
    return a[i, 0] + a[i, 1]


@kernel(cache=False)
def _sum_rows_per_constant(a):
    return _row_sum_per_constant(a, 0) + _row_sum_per_constant(a, 1)


def test_integer_constants_and_int32_share_one_int64_variant():
    a = np.arange(6.0).reshape(3, 2)
    small = np.array([2], np.int32)
    assert _sum_rows_by_constants(a, small) == (0 + 1) + (2 + 3) + (4 + 5) + (4 + 5)
    assert [sig[1] for sig in _row_sum.signatures] == [types.int64]


def test_specialise_constants_keeps_a_variant_per_constant():
    a = np.arange(6.0).reshape(3, 2)
    assert _sum_rows_per_constant(a) == 6.0
    assert sorted(str(sig[1]) for sig in _row_sum_per_constant.signatures) == [
        "Literal[int](0)", "Literal[int](1)"]


def test_widen_integer_keeps_unsigned_floats_and_bool_constants():
    assert widen_integer(types.IntegerLiteral(7)) == types.int64
    assert widen_integer(types.int32) == types.int64
    assert widen_integer(types.int8) == types.int64
    assert widen_integer(types.uint32) == types.uint32
    assert widen_integer(types.float32) == types.float32
    assert widen_integer(types.BooleanLiteral(True)) == types.BooleanLiteral(True)
