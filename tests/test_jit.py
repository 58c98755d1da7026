"""The kernel decorator: one compiled variant per real argument type, not per integer constant."""

from __future__ import annotations

import numpy as np
from numba import types

from whitted.kernels.dispatcher import widen_integer
from whitted.kernels.jit import kernel


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
    assert _scaled.callee.py_func.__qualname__ == "_scaled__whitted_twin"  # its own cache files
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


def test_a_twin_gets_no_machine_code_and_its_callers_link_its_bitcode():
    """kernels/cache_load.py: a twin's library is finalised without going into the JIT (its
    callers link its LLVM module; its own machine code was never run) and is cached as its
    bitcode beside an empty object code; its caller still runs it."""
    assert _twice_scaled(2.0) == 10.0
    (twin,) = _scaled.callee.overloads.values()
    library = twin.library
    assert library.name.endswith("__whitted_twin")
    assert library._finalized
    engine = library.codegen._engine
    assert engine.get_function_address(twin.fndesc.mangled_name) == 0  # not in the JIT
    name, kind, (obj, bitcode) = library.serialize_using_object_code()
    assert (name, kind, obj) == (library.name, "object", b"") and len(bitcode) > 0
    (caller,) = _twice_scaled.overloads.values()
    assert caller.library.get_pointer_to_function(
        caller.fndesc.llvm_cpython_wrapper_name) != 0


CACHED_TWIN = '''
import sys
import numpy as np
from whitted.kernels.jit import kernel
from cached_twin_kernels import double_it, quadruple


@kernel(cache=False)
def octuple(x):  # compiled in every run, calling the twin (from the cache in the second)
    return double_it(double_it(double_it(x)))


assert quadruple(np.float64(1.5)) == 6.0
assert octuple(np.float64(1.5)) == 12.0
twin = next(iter(double_it.callee.overloads.values())).library
print({None: "LOADED", "x": "COMPILED"}.get(getattr(twin, "_unparsed_bitcode", "x"), "UNPARSED"))
'''


def test_a_twin_from_the_cache_links_into_a_new_caller(tmp_path):
    """A twin written to the cache by one process (bitcode, no machine code) is loaded by the
    next for linking only, and a kernel compiled there calls it."""
    import os
    import subprocess
    import sys

    (tmp_path / "cached_twin_kernels.py").write_text(
        "from whitted.kernels.jit import kernel\n\n\n"
        "@kernel\ndef double_it(x):\n    return 2.0 * x\n\n\n"
        "@kernel\ndef quadruple(x):\n    return double_it(double_it(x))\n")
    (tmp_path / "run.py").write_text(CACHED_TWIN)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    runs = [subprocess.run([sys.executable, "run.py"], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=600) for _ in range(2)]
    for run in runs:
        assert run.returncode == 0, run.stderr
    # the first run compiled the twin, the second loaded it and parsed its bitcode to link it
    assert [run.stdout.strip() for run in runs] == ["COMPILED", "LOADED"]
    cached = list((tmp_path / "cache").rglob("*double_it__whitted_twin*.nbc"))
    assert cached, list((tmp_path / "cache").rglob("*"))
