"""Numba's side of every kernel: the dispatcher that compiles, caches and loads it.

The decorators are in kernels/jit.py, which makes a kernel's dispatcher (here) only when
something must be compiled or loaded through Numba (see kernels/native.py).

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
optimised; code already in the on-disk cache keeps the setting it was compiled with. whitted
sets it in the environment too (``NUMBA_SLP_VECTORIZE=1``): Numba reads its settings from
the environment again before a compile whenever the environment has changed since it last
did, and a setting made only in ``numba.config`` is then lost. That happened whenever Numba
was imported before whitted (``import numba`` in a notebook, another library): whitted then
sets ``NUMBA_CACHE_DIR``, and the kernels compiled next, and cached for every later run, had
no SLP vectoriser: seed000 rendered in 0.39 s against 0.25 s at two threads.

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

Calls from one kernel to another go to the kernel's twin (``KernelDispatcher.callee``),
compiled without the wrapper that lets Python call it (``no_cpython_wrapper``): Numba would
generate, optimise and compile that wrapper for every kernel, and for the kernels that take
``GeometryArrays`` (a tuple of some 30 arrays) unboxing the arguments from Python objects is
more code than the kernel itself. The twin has a name of its own (``<name>__whitted_twin``), so its
own cache files; a kernel called from Python (``render_tiles``, the builders, tests) compiles
its Python-callable version as before. No kernel gets a C-callable wrapper
(``no_cfunc_wrapper``): nothing calls them through ctypes. Measured (one process, the render
kernel's cold compile, CPU): 18.0-19.6 -> 15.3-15.9 s. A twin is never turned into machine
code (its callers link its LLVM module) and is cached as bitcode: see kernels/cache_load.py.

A kernel declared ``inline="always"`` is inlined by LLVM (Numba's ``forceinline``: the
``alwaysinline`` attribute), not by Numba's IR inliner, which deep-copies the callee's whole
variable scope once per block of it (quadratic in the callee's size) and types the inlined
code again in each caller. The machine code does the same arithmetic (every image stayed
bit-identical) and runs faster (LLVM inlines a callee it has already optimised on its own).
``trace_path`` is the exception (``numba_inline=True``: Numba's IR inliner): with LLVM
inlining it was optimised and compiled twice, once on its own and once in ``render_tiles``,
its one caller, and Numba's copy of it is cheap now that its own callees are not copied into
it. Measured, CPU, with the twins, one process, cold (the plain render kernel / the one for
scenes with mesh instances):

| inlining | compile | seed000, one thread, CPU (interleaved) | ice | softshadow |
| --- | --- | --- | --- | --- |
| Numba's (speed: main 5565e00) | 15.9 / 18.4 s | 0.712, 0.672 s | 4.06 s | 13.02 s |
| LLVM's, ``trace_path`` too (*) | 12.5 / 15.6 s | (0.453-0.458 s against 0.54-0.66 s) | | |
| LLVM's, ``trace_path`` Numba's (this) | 10.9 / 10.2 s | 0.600, 0.678 s | 3.89 s | 9.85 s |

(*) measured before ``forceinline`` was set on every kernel: Numba passes it on to the
callees compiled while an alwaysinline kernel compiles, unless they set it, so many more
kernels were inlined, and which ones depended on the order they were first compiled in (one
process or another, a cache): a texture lookup inlined that way lost its NaN check in one
order and not the other. Every kernel now says whether it is inlined.
"""

from __future__ import annotations

import os
import threading
import types as pytypes

from numba import config, types
from numba.core.caching import CompileResultCacheImpl, FunctionCache, UserProvidedCacheLocator
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import CPUDispatcher
from numba.core.runtime import nrtdynmod, rtsys

from . import cache_load  # noqa: F401 - faster loading of cached kernels (see there)

if "NUMBA_SLP_VECTORIZE" not in os.environ:
    os.environ["NUMBA_SLP_VECTORIZE"] = "1"  # survives Numba reading its environment again
    config.SLP_VECTORIZE = 1

#: the options of the twin that other kernels call: no wrappers for calls from Python
CALLEE_ONLY = {"no_cpython_wrapper": True}


def widen_integer(ty):
    """The argument type a kernel is compiled for: int64 for integer constants and narrower
    signed integers, everything else (unsigned, float, arrays, bool constants) unchanged."""
    if isinstance(ty, types.IntegerLiteral):
        ty = ty.literal_type
    if isinstance(ty, types.Integer) and ty.signed and ty.bitwidth < 64:
        return types.int64
    return ty


class KernelCacheLocator(UserProvidedCacheLocator):
    """Numba's locator of the cache folder (``NUMBA_CACHE_DIR``, which whitted always sets),
    doing once per process what Numba does for every dispatcher it creates: check that the
    folder can be written (a temporary file made and deleted) and hash the kernel's whole
    source file. whitted makes some 230 dispatchers at import, and the two took 15 ms of every
    render's start-up. A source file changed while the process runs is hashed again (the key
    holds its modification time and size, as Numba's does)."""

    _writable: set[str] = set()
    _stamps: dict[tuple, bytes] = {}

    def ensure_cache_path(self):
        path = self.get_cache_path()
        if path not in self._writable:
            super().ensure_cache_path()  # raises OSError when the folder is not usable
            self._writable.add(path)

    def get_source_stamp(self):
        st = os.stat(self._py_file)
        key = (self._py_file, st.st_mtime_ns, st.st_size)
        stamp = self._stamps.get(key)
        if stamp is None:
            stamp = self._stamps[key] = super().get_source_stamp()
        return stamp


class KernelCacheImpl(CompileResultCacheImpl):
    _locator_classes = [KernelCacheLocator, *CompileResultCacheImpl._locator_classes]


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

    #: set while a cold compile shares its work with a helper process (render/warm_up.py):
    #: called with a kernel's qualified name when it is not in the cache, it waits while the
    #: helper compiles that kernel and says whether it did (then it loads instead of being
    #: compiled twice, here and there)
    wait_for_helper = None
    _impl_class = KernelCacheImpl

    def load_overload(self, sig, target_context):
        initialize_runtime(target_context)
        with self._guard_against_spurious_io_errors():
            data = self._load_overload(sig, target_context)
        wait = KernelCache.wait_for_helper
        if data is None and wait is not None and wait(self._py_func.__qualname__):
            with self._guard_against_spurious_io_errors():
                data = self._load_overload(sig, target_context)
        return data


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
    argument types (see the module docstring), and cached by :class:`KernelCache`.

    Calls from other kernels go to ``callee``, a twin compiled without the wrappers that
    let Python call it (see the module docstring)."""

    specialise_constants = False
    #: makes the twin, for a kernel that has one; the twin itself is made on first use (a
    #: kernel is compiled, or a cached caller that needs it is not in the cache): a render
    #: whose kernels all load from the cache never makes any (117 dispatchers, 8 ms)
    make_callee = None
    _callee: KernelDispatcher | None = None

    @property
    def callee(self) -> KernelDispatcher | None:
        if self._callee is None and self.make_callee is not None:
            with _twin_lock:
                if self._callee is None:
                    self._callee = self.make_callee()
        return self._callee

    def enable_caching(self):
        self._cache = KernelCache(self.py_func)

    def get_call_template(self, args, kws):
        if not self.specialise_constants:
            args = tuple(widen_integer(a) for a in args)
            kws = {name: widen_integer(a) for name, a in kws.items()}
        if self.callee is not None:
            return self.callee.get_call_template(args, kws)
        return super().get_call_template(args, kws)

    def get_overload(self, sig):
        try:
            return super().get_overload(sig)
        except KeyError:  # compiled for calls from kernels only: the twin has it
            if self.callee is None:
                raise
            return self.callee.get_overload(sig)


_twin_lock = threading.Lock()


def _twin_function(f):
    """A copy of ``f`` under its own name (``<name>__whitted_twin``): the twin's cache files and
    machine-code symbols are its own."""
    twin = pytypes.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__,
                                f.__closure__)
    twin.__kwdefaults__ = f.__kwdefaults__
    twin.__qualname__ = f.__qualname__ + cache_load.TWIN_SUFFIX
    twin.__module__ = f.__module__
    twin.__doc__ = f.__doc__
    return twin


def make_dispatcher(f, options: dict, specialise_constants: bool, cache: bool):
    """The :class:`KernelDispatcher` of kernel ``f`` compiled with Numba ``options`` (as
    :func:`.jit.kernel` resolved them), with the maker of its twin."""

    def make(function, targetoptions):
        dispatcher = KernelDispatcher(py_func=function, locals={}, targetoptions=targetoptions)
        dispatcher.specialise_constants = specialise_constants
        if cache:
            dispatcher.enable_caching()
        return dispatcher

    dispatcher = make(f, options)
    dispatcher.make_callee = lambda: make(_twin_function(f), {**options, **CALLEE_ONLY})
    return dispatcher
