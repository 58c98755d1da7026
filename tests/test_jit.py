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
    # compiled once, for calls from kernels: in the twin without the Python wrapper
    assert [sig[1] for sig in _row_sum.callee.signatures] == [types.int64]


def test_specialise_constants_keeps_a_variant_per_constant():
    a = np.arange(6.0).reshape(3, 2)
    assert _sum_rows_per_constant(a) == 6.0
    assert sorted(str(sig[1]) for sig in _row_sum_per_constant.callee.signatures) == [
        "Literal[int](0)", "Literal[int](1)"]


def test_widen_integer_keeps_unsigned_floats_and_bool_constants():
    assert widen_integer(types.IntegerLiteral(7)) == types.int64
    assert widen_integer(types.int32) == types.int64
    assert widen_integer(types.int8) == types.int64
    assert widen_integer(types.uint32) == types.uint32
    assert widen_integer(types.float32) == types.float32
    assert widen_integer(types.BooleanLiteral(True)) == types.BooleanLiteral(True)


@kernel(cache=False)
def _scaled(a, s):
    return a * s


@kernel(cache=False)
def _twice_scaled(a):
    return _scaled(a, 2.0) + _scaled(a, 3.0)


def test_calls_from_kernels_compile_the_twin_without_a_python_wrapper():
    assert _twice_scaled(1.5) == 7.5
    assert _scaled.signatures == []  # nothing compiled the Python-callable version
    assert len(_scaled.callee.signatures) == 1
    (twin,) = _scaled.callee.overloads.values()
    assert twin.fndesc.llvm_cpython_wrapper_name not in twin.library.get_llvm_str()
    assert _scaled.callee.py_func.__qualname__ == "_scaled__callee"  # its own cache files
    # a call from Python compiles the Python-callable version, with the same result
    assert _scaled(1.5, 2.0) == 3.0
    assert len(_scaled.signatures) == 1


@kernel(cache=False, inline="always")
def _inlined_square(x):
    return x * x


@kernel(cache=False)
def _sum_of_squares(x, y):
    return _inlined_square(x) + _inlined_square(y)


def test_inline_always_is_left_to_llvm():
    """Numba's IR inliner is not used (its copies grow with the square of the callee's
    size): the callee is compiled once and LLVM inlines it (``alwaysinline``)."""
    assert _sum_of_squares(3.0, 4.0) == 25.0
    assert _inlined_square.targetoptions.get("inline", "never") == "never"
    assert _inlined_square.callee.targetoptions["forceinline"] is True
    (caller,) = _sum_of_squares.overloads.values()
    llvm = caller.library.get_llvm_str()
    assert "_inlined_square" in llvm  # linked in, and then inlined: no call is left
    assert not [line for line in llvm.splitlines() if " call " in line
                and "_inlined_square" in line]


@kernel(cache=False)
def _plain_callee(x):
    return x + 1.0


@kernel(cache=False, inline="always")
def _inlined_caller(x):
    return _plain_callee(x) * 2.0


def test_a_callee_of_an_inlined_kernel_is_not_inlined_by_inheritance():
    """Numba passes ``forceinline`` on to callees compiled while an alwaysinline kernel
    compiles, unless they set it: a kernel would then be inlined or not depending on which
    caller compiled it first (a texture lookup inlined that way lost its NaN check)."""
    assert _inlined_caller(1.0) == 4.0
    (caller,) = _inlined_caller.overloads.values()
    (callee,) = _plain_callee.callee.overloads.values()
    assert caller.fndesc.inline is True
    assert callee.fndesc.inline is False
