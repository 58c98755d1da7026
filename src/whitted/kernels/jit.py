"""The one decorator every kernel uses, so the compilation options live in one place.

``cache=True`` keeps compiled machine code on disk (``NUMBA_CACHE_DIR``, see the README);
``error_model="numpy"`` lets 1/0 give inf instead of raising; ``nogil=True`` lets the editor's
UI thread run while a render is in flight; ``_nrt=False`` compiles without the Numba runtime:
arrays are passed without atomic reference counting (measured at about a third of the render
time), so kernels never allocate: callers pass in every array they need.

``fastmath`` takes the flags that let LLVM reorder and fuse arithmetic (``reassoc``,
``contract``, ``arcp``, ``nsz``, ``afn``: +17 % on the analytic benchmark) but not ``nnan``
or ``ninf``: kernels use inf as the "no hit" sentinel. The watertight triangle test opts out
(``@kernel(fastmath=False)``): its edge functions must round exactly alike for both triangles
that share an edge.

Numba leaves LLVM's SLP vectoriser off; whitted turns it on (unless ``NUMBA_SLP_VECTORIZE``
is set in the environment) before its kernels compile: it packs the three lanes of the vector
arithmetic and the slab tests into SIMD instructions. Measured, CPU-time medians on this
2-core VM: seed000 0.75 -> 0.60 s, mesh1m 0.81 -> 0.72 s, ice 4.65 -> 4.50 s, softshadow at
half size 2.65 -> 2.60 s. The setting is Numba's process-wide one, read when a kernel is
optimised; code already in the on-disk cache keeps the setting it was compiled with.

Every kernel is a :class:`KernelDispatcher`: when one kernel calls another, Numba would compile
the callee once per distinct argument type it meets, and it counts each integer constant
(``Literal[int](0)``, ``Literal[int](-1)``, ...) and each narrower signed integer as a type of
its own: ``vload`` was compiled 25 times, ``hit_analytic`` three times at 1.6 s each. The
dispatcher widens those arguments to int64 before it picks or compiles the callee, so each
kernel is compiled once per real variant. Boolean constants stay literal: kernels take them as
compile-time switches (``next_scene_candidate``'s ``nearest``). Measured: the render kernel's
cold compile 27.1 -> 19.2 s, the builders' 6.0 -> 4.3 s (with one slice copy made a loop).

A kernel declared with ``specialise_constants=True`` keeps Numba's behaviour: a variant per
integer constant. ``_pass_surface`` needs it: with a variant per call site LLVM inlines each
one (and drops the mesh branches where the triangle is the constant -1); one shared variant is
called out of line, and seed000 renders 20 % slower.
"""

from __future__ import annotations

import os

from numba import config, types
from numba.core.caching import FunctionCache
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import CPUDispatcher
from numba.core.runtime import nrtdynmod, rtsys

if "NUMBA_SLP_VECTORIZE" not in os.environ:
    config.SLP_VECTORIZE = 1

FAST_MATH = {"reassoc", "contract", "arcp", "nsz", "afn"}


def widen_integer(ty):
    """The argument type a kernel is compiled for: int64 for integer constants and narrower
    signed integers, everything else (unsigned, float, arrays, bool constants) unchanged."""
    if isinstance(ty, types.IntegerLiteral):
        ty = ty.literal_type
    if isinstance(ty, types.Integer) and ty.signed and ty.bitwidth < 64:
        return types.int64
    return ty


class KernelCache(FunctionCache):
    """Numba's on-disk cache of one kernel, loading without first loading Numba's compiler.

    Before it even looks in the cache, Numba's ``FunctionCache.load_overload`` refreshes the
    target context: it imports and installs every implementation registry (typed containers,
    random generators, polynomials, datetimes, ...), and the NumPy one probes for a BLAS by
    importing ``scipy.linalg``. That is 0.35 s the first time in a process (0.13 s without
    the BLAS probe), three quarters of loading all of whitted's cached kernels, and machine
    code read back from the cache needs none of it: only the runtime's symbols (``NRT_*``,
    which the builders' code calls). On a miss, the compile that follows refreshes the
    context itself (Numba's ``CompilerBase`` does, before typing), so what gets compiled
    is unchanged."""

    def load_overload(self, sig, target_context):
        initialize_runtime(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)


def _runtime_cache_file(codegen) -> str | None:
    """Where the runtime's machine code is kept: beside the kernels, named after everything
    the code depends on (Numba, llvmlite, the target CPU and its features)."""
    if not config.CACHE_DIR:
        return None
    import hashlib

    import llvmlite
    import numba

    key = repr((numba.__version__, llvmlite.__version__, codegen.magic_tuple()))
    name = f"whitted-nrt-{hashlib.sha256(key.encode()).hexdigest()[:16]}.bin"
    return os.path.join(config.CACHE_DIR, name)


def _cached_nrt_functions(target_context):
    """``nrtdynmod.compile_nrt_functions``, read back from the cache when it is there."""
    import contextlib
    import pickle

    codegen = target_context.codegen()
    path = _runtime_cache_file(codegen)
    if path is not None:
        with contextlib.suppress(Exception), open(path, "rb") as f:  # absent or unreadable:
            return codegen.unserialize_library(pickle.load(f))  # compiled below
    # as nrtdynmod.compile_nrt_functions does, keeping the object code to store
    ir_module, library = nrtdynmod.create_nrt_module(target_context)
    library.enable_object_caching()
    library.add_ir_module(ir_module)
    library.finalize()
    if path is not None:  # written whole or not at all; a failure only costs the compile
        tmp = f"{path}.{os.getpid()}.tmp"
        try:
            data = pickle.dumps(library.serialize_using_object_code())
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(tmp, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except Exception:  # noqa: BLE001 - a read-only or full disk, an unpicklable library
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return library


_compile_nrt_functions = nrtdynmod.compile_nrt_functions


def initialize_runtime(target_context) -> None:
    """``rtsys.initialize``, with the runtime's own LLVM functions (NRT_incref, NRT_decref,
    ...) read back as machine code from the kernel cache folder instead of compiled by LLVM
    in every process (20-25 ms). Numba's cache does the same for every kernel (object code
    plus bitcode for later linking)."""
    with global_compiler_lock:  # rtsys.initialize takes it too: no compile sees the swap
        nrtdynmod.compile_nrt_functions = _cached_nrt_functions
        try:
            rtsys.initialize(target_context)
        finally:
            nrtdynmod.compile_nrt_functions = _compile_nrt_functions


class KernelDispatcher(CPUDispatcher):
    """Numba's CPU dispatcher, compiling one variant for calls that differ only in integer
    argument types (see the module docstring), and cached by :class:`KernelCache`."""

    specialise_constants = False

    def enable_caching(self):
        self._cache = KernelCache(self.py_func)

    def get_call_template(self, args, kws):
        if self.specialise_constants:
            return super().get_call_template(args, kws)
        args = tuple(widen_integer(a) for a in args)
        kws = {name: widen_integer(a) for name, a in kws.items()}
        return super().get_call_template(args, kws)


def kernel(fn=None, **options):
    opts = {"nopython": True, "error_model": "numpy", "nogil": True, "_nrt": False,
            "fastmath": FAST_MATH}
    opts.update(options)
    cache = opts.pop("cache", True)
    specialise_constants = opts.pop("specialise_constants", False)

    def make(f):
        if config.DISABLE_JIT:
            return f
        dispatcher = KernelDispatcher(py_func=f, locals={}, targetoptions=opts)
        dispatcher.specialise_constants = specialise_constants
        if cache:
            dispatcher.enable_caching()
        return dispatcher

    return make if fn is None else make(fn)


def builder(fn=None, **options):
    """The decorator of the kernels that build acceleration data and parse files: Numba's own
    defaults (no fast-math, Python's error model, the Numba runtime so they may allocate
    their results), compiled and cached like every kernel."""
    opts = {"error_model": "python", "_nrt": True, "fastmath": False}
    opts.update(options)
    return kernel(fn, **opts)
