"""The kernel decorator: one compiled variant per real argument type, not per integer constant
(the tuned dispatcher of jit/dispatcher.py), and stock Numba where that is not verified."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import types

from whitted.jit import body, dispatcher, kernel, load_numba, overload
from whitted.jit.dispatcher import widen_integer

load_numba()
tuned_only = pytest.mark.skipif(not dispatcher.tuned(),
                                reason="stock Numba here (jit/dispatcher.py VERIFIED)")


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


@tuned_only
def test_integer_constants_and_int32_share_one_int64_variant():
    a = np.arange(6.0).reshape(3, 2)
    small = np.array([2], np.int32)
    assert _sum_rows_by_constants(a, small) == (0 + 1) + (2 + 3) + (4 + 5) + (4 + 5)
    # compiled once, for calls from kernels: in the twin without the Python wrapper
    assert [sig[1] for sig in _row_sum.callee.signatures] == [types.int64]


@tuned_only
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


@tuned_only
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


@tuned_only
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


@tuned_only
def test_a_callee_of_an_inlined_kernel_is_not_inlined_by_inheritance():
    """Numba passes ``forceinline`` on to callees compiled while an alwaysinline kernel
    compiles, unless they set it: a kernel would then be inlined or not depending on which
    caller compiled it first (a texture lookup inlined that way lost its NaN check)."""
    assert _inlined_caller(1.0) == 4.0
    (caller,) = _inlined_caller.overloads.values()
    (callee,) = _plain_callee.callee.overloads.values()
    assert caller.fndesc.inline is True
    assert callee.fndesc.inline is False


STOCK = """
import numpy as np
from numba.core.registry import CPUDispatcher
from whitted.jit import dispatcher
from whitted.jit import body, kernel, load_numba, overload

load_numba()
assert dispatcher.tuned() is False


@kernel(cache=False, inline="always")
def inlined_square(x):
    return x * x


@kernel(cache=False, specialise_constants=True, numba_inline=True)
def row_sum(a, i):
    return a[i, 0] + a[i, 1]


@kernel(cache=False)
def doubled(x):
    return 2.0 * x


def doubled_through_overload(x):
    return doubled(x)


@overload(doubled_through_overload, forceinline=True)
def _doubled_through_overload(x):
    return body(doubled)


@kernel(entry=True)
def total(a, small):
    return (inlined_square(a[0, 0]) + row_sum(a, 1) + row_sum(a, small[0])
            + doubled_through_overload(a[0, 1]))


a = np.arange(6.0).reshape(3, 2)
print("RESULT", total(a, np.array([2], np.int32)), type(total.dispatcher).__name__)
"""


@kernel(cache=False)
def _tripled(x):
    return 3.0 * x


def _tripled_through_overload(x):
    return _tripled(x)


@overload(_tripled_through_overload)
def _tripled_overload(x):
    return body(_tripled)


@kernel(cache=False, inline="always")
def _inlined_tripler(x):
    return _tripled_through_overload(x) + 1.0


@tuned_only
def test_an_overloads_body_is_compiled_with_its_own_options_not_its_callers():
    """An overload whose implementation is a kernel's body (jit.body) is compiled as that
    kernel: without Python wrappers and with the overload's ``forceinline`` (False here),
    not the one of the caller that happens to compile it first (an ``inline="always"``
    one here), which Numba would pass on."""
    from numba.core import event

    def numba_side(k):  # a Kernel, or (swapped into this module's globals) its dispatcher
        return getattr(k, "dispatcher", k)

    with event.install_recorder("numba:compile") as rec:
        numba_side(_inlined_tripler).compile((types.float64,))
    impls = [ev.data["dispatcher"] for _, ev in rec.buffer
             if ev.is_start and ev.data["dispatcher"].py_func is _tripled.py_func
             and ev.data["dispatcher"] is not numba_side(_tripled)]
    assert impls, "the overload's body was not compiled"
    options = impls[0].targetoptions
    assert options["forceinline"] is False
    assert options["no_cpython_wrapper"] is True and options["no_cfunc_wrapper"] is True


def test_an_overloads_options_with_stock_numba_are_numbas_own(monkeypatch):
    monkeypatch.setattr(dispatcher, "_tuned", False)
    assert dispatcher.overload_options(True) == {}


@pytest.mark.parametrize("why", [{"WHITTED_NUMBA_TUNING": "0"}, "unverified"])
def test_stock_numba_runs_the_same_kernels(tmp_path, why):
    """Where the tuned dispatcher is off (asked, or Numba outside the verified versions),
    kernels are plain ``numba.njit`` functions taking the same decorator options (the
    tuned-only ones dropped), cached, with the same results."""
    script = STOCK
    env = dict(os.environ, WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    if why == "unverified":
        script = script.replace("load_numba()\n", "dispatcher.VERIFIED['numba'] = ((0, 0), "
                                "(0, 1))\nload_numba()\n", 1)
    else:
        env.update(why)
    (tmp_path / "run.py").write_text(script)
    for _ in range(2):  # compiled, then loaded from the cache
        run = subprocess.run([sys.executable, "run.py"], cwd=tmp_path, env=env,
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        assert "RESULT 16.0 CPUDispatcher" in run.stdout  # 0 + (2+3) + (4+5) + 2*1
        assert run.stderr == ""
    assert list((tmp_path / "cache").rglob("*total*.nbc"))


ARRAY_TYPING = """
import sys
import numpy as np
import numba
from numba import types
from whitted.jit import kernel, load_numba

load_numba()


@kernel(entry=True)
def first_of(a):
    return a[0, 0]


c = np.arange(6.0).reshape(2, 3)
f = np.asfortranarray(c)
strided = np.arange(12.0).reshape(2, 6)[:, ::2]
frozen = c.copy()
frozen.flags.writeable = False
print("TYPES", numba.typeof(c) == types.Array(types.float64, 2, "C"),
      numba.typeof(f) == types.Array(types.float64, 2, "F"),
      numba.typeof(strided) == types.Array(types.float64, 2, "A"),
      numba.typeof(frozen) == types.Array(types.float64, 2, "C", readonly=True),
      numba.typeof(np.zeros(3, np.int32)) == types.Array(types.int32, 1, "C"))
print("CALLS", first_of(c), first_of(f), first_of(strided), first_of(frozen))
print("MA", "numpy.ma" in sys.modules)
import numpy.ma

try:
    numba.typeof(numpy.ma.masked_array(c))
except numba.core.errors.NumbaTypeError as exc:
    print("MASKED", exc)
"""


def test_arrays_are_typed_as_numba_types_them_without_importing_masked_arrays(tmp_path):
    """Numba's typing of array arguments, registered through its public typeof_impl
    (jit/array_typing.py): the same types for C, Fortran, strided and read-only arrays,
    without importing numpy.ma; once it is imported, a masked array is refused as Numba
    refuses it."""
    (tmp_path / "run.py").write_text(ARRAY_TYPING)
    env = dict(os.environ, WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    for _ in range(2):  # compiled (which may import anything), then loaded from the cache
        run = subprocess.run([sys.executable, "run.py"], cwd=tmp_path, capture_output=True,
                             text=True, timeout=600, env=env)
        assert run.returncode == 0, run.stderr[-2000:]
        assert "TYPES True True True True True" in run.stdout
        assert "CALLS 0.0 0.0 0.0 0.0" in run.stdout
        assert "MASKED Unsupported array type: numpy.ma.MaskedArray." in run.stdout
    if dispatcher.tuned():
        # the stock dispatcher refreshes Numba's registries at every cache look-up, which
        # imports numpy.ma by other ways (the oldest Numba's CI run): the types above still hold
        assert "MA False" in run.stdout


def test_private_names_are_listed_and_checked():
    """Every private name the tuned dispatcher uses is listed; a Numba outside the verified
    versions turns it off."""
    assert dispatcher.PRIVATE_NAMES and dispatcher.VERIFIED["numba"][0] < (
        dispatcher.VERIFIED["numba"][1])
    with open(dispatcher.__file__) as f:
        source = f.read()
    for name in ("get_call_template", "_load_overload", "rtsys.initialize", "_nrt",
                 "no_cpython_wrapper", "forceinline", "FunctionCache"):
        assert name in source.split("PRIVATE_NAMES = (", 1)[1].split(")\n", 1)[0], name


#: Numba's documented modules whitted may import outside jit/dispatcher.py: the package,
#: its high-level and low-level extension API (numba.extending, numba.core.cgutils and the
#: typing templates its examples use), the event API (numba.core.event), and the cache
#: locators that Numba's NUMBA_CACHE_LOCATOR_CLASSES setting chooses from (numba.core.caching:
#: jit/locator.py subclasses the public UserProvidedCacheLocator)
DOCUMENTED_NUMBA = {"numba", "numba.extending", "numba.types", "numba.core.cgutils",
                    "numba.core.event", "numba.core.typing.templates", "numba.core.caching"}


def test_only_the_dispatcher_imports_undocumented_numba_modules():
    import ast

    root = Path(dispatcher.__file__).parents[1]
    found = []
    for path in sorted(root.rglob("*.py")):
        if path == Path(dispatcher.__file__):
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
                names = [node.module] if node.module != "numba.core" else names[1:]
            else:
                continue
            for name in names:
                if name.split(".")[0] == "numba" and name not in DOCUMENTED_NUMBA:
                    found.append(f"{path.relative_to(root)}:{node.lineno}: {name}")
    assert found == []


def test_every_overload_of_a_kernels_body_has_that_kernels_forceinline():
    """An overload returning a kernel's body (jit.body) says the kernel's ``forceinline`` in
    its own options: were the kernel's changed alone, its code would be inlined one way
    where it is called directly and another way through the overload."""
    from whitted.jit import decorators
    from whitted.kernels import accel, extras, lighting, uv  # noqa: F401 - their overloads

    checked = 0
    for implementation, options in decorators.overloads_by_function.values():
        if "body" not in implementation.__code__.co_names:
            continue
        for name in implementation.__code__.co_names:
            target = implementation.__globals__.get(name)
            kern = decorators.kernels_by_function.get(getattr(target, "py_func", None))
            if kern is not None:
                assert options["forceinline"] == kern.options["forceinline"], name
                checked += 1
    assert checked >= 9
