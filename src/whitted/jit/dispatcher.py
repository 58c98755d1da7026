"""Numba's side of a kernel: stock ``numba.njit``, or a tuned dispatcher on the Numba versions
it was verified with. The one module of whitted that uses names Numba does not document.

:func:`make_dispatcher` gives ``numba.njit`` with the kernel's documented options (see
jit/decorators.py) unless :func:`tuned` holds: Numba and llvmlite within :data:`VERIFIED`, every
name in :data:`PRIVATE_NAMES` importable, and ``WHITTED_NUMBA_TUNING`` not ``0``. The tuned
dispatcher cuts the cold compile and the render time; kernels compute the same either way
(the tests run both). docs/performance.md has the measurements.

What the tuned dispatcher does:

- **Integer widening.** Numba compiles a callee once per distinct argument type, and counts
  each integer constant (``Literal[int](0)``) and each narrower signed integer as a type of
  its own (``vload`` was compiled 25 times). :class:`KernelDispatcher` widens them to int64
  before it picks or compiles the callee (``get_call_template``). Boolean constants stay
  literal (compile-time switches). A kernel with ``specialise_constants=True`` keeps Numba's
  behaviour (``_pass_surface``: LLVM drops dead branches per call site).
- **Twins.** Calls from one kernel to another go to the kernel's twin (``callee``), compiled
  without the wrapper that lets Python call it (``no_cpython_wrapper``; for the kernels that
  take ``GeometryArrays`` unboxing is more code than the kernel). The twin has a name of its
  own (``<name>__whitted_twin``), so cache files of its own. No kernel gets a C-callable
  wrapper (``no_cfunc_wrapper``).
- **No runtime in render kernels** (``_nrt=False``): arrays are passed without atomic
  reference counting (about a third of the render time); render kernels never allocate.
- **LLVM inlining** (``forceinline``) for ``inline="always"``, set to False on every other
  kernel (Numba passes it on to callees that do not set it, so inlining would depend on
  compile order); an overload's implementation gets it as its overload says, and no Python
  wrappers (:func:`overload_options`).
- **A read-only warm folder** (jit/cache.py, ``KernelCache.read_only``): a failed save there
  is no error: the kernel is compiled in memory, said once (jit/locator.py, public API, takes
  the folder without Numba's writability check, and checks a writable one once a process).
- **Loading without refreshing the compiler's registries**: before it looks in the cache,
  Numba's ``FunctionCache.load_overload`` installs every implementation registry, and the
  NumPy one probes for a BLAS by importing ``scipy.linalg`` (0.25-0.35 s of a warm render's
  start-up); machine code read back needs only the runtime (``rtsys.initialize``), and a
  kernel compiled without it (``_nrt=False``: every render kernel, the builders that
  allocate nothing) not even that: the runtime's functions are compiled by LLVM in the
  process that first needs them (20-40 ms), which a warm render of analytic shapes never
  does. A compile after a miss refreshes them itself.
- **The compile helper's share** (:attr:`KernelCache.wait_for_helper`, render/warm_up.py):
  on a cold compile, a kernel the helper process is compiling is waited for and loaded
  instead of being compiled twice.
"""

from __future__ import annotations

import contextlib
import os
import threading
import types as pytypes

from .cache import read_only

#: (package, oldest version, first version not verified): the tuned dispatcher runs only here
VERIFIED = {"numba": ((0, 68), (0, 69)), "llvmlite": ((0, 50), (0, 51))}

#: every name of Numba's that is not documented and this module relies on
PRIVATE_NAMES = (
    "numba.core.registry.CPUDispatcher (subclassed; its constructor's py_func, locals, "
    "targetoptions)",
    "Dispatcher.get_call_template (overridden)",
    "Dispatcher.get_overload (overridden)",
    "Dispatcher.enable_caching (overridden), Dispatcher._cache",
    "numba.core.caching.FunctionCache (subclassed): load_overload, _load_overload, "
    "_guard_against_spurious_io_errors (overridden), _cache_path, _py_func, _impl_class",
    "numba.core.runtime.rtsys.initialize",
    "target options _nrt, no_cpython_wrapper, no_cfunc_wrapper, forceinline",
    "numba.np.arrayobj.make_array, populate_array (frame_view: an array over stack slots "
    "without the runtime, which numba.carray needs)",
)

#: the options only the tuned dispatcher takes
TUNED_ONLY = ("_nrt", "no_cfunc_wrapper", "forceinline", "no_cpython_wrapper")
#: the options of the twin that other kernels call: no wrappers for calls from Python
CALLEE_ONLY = {"no_cpython_wrapper": True}
#: the end of a twin's name, which Numba gives its cache files
TWIN_SUFFIX = "__whitted_twin"

_tuned: bool | None = None
_classes = None


def _version(text: str) -> tuple[int, int]:
    parts = text.split(".")
    try:
        return int(parts[0]), int(parts[1])
    except (IndexError, ValueError):
        return (0, 0)


def tuned() -> bool:
    """Whether kernels get the tuned dispatcher (module docstring)."""
    global _tuned, _classes
    if _tuned is None:
        _tuned = False
        if os.environ.get("WHITTED_NUMBA_TUNING", "1") != "0":
            import llvmlite
            import numba

            versions = {"numba": numba.__version__, "llvmlite": llvmlite.__version__}
            if all(low <= _version(versions[name]) < high
                   for name, (low, high) in VERIFIED.items()):
                try:
                    _classes = _make_classes()
                    _tuned = True
                except (ImportError, AttributeError):  # a name gone: stock Numba
                    _classes = None
    return _tuned


def widen_integer(ty):
    """The argument type a kernel is compiled for: int64 for integer constants and narrower
    signed integers, everything else (unsigned, float, arrays, bool constants) unchanged."""
    from numba import types

    if isinstance(ty, types.IntegerLiteral):
        ty = ty.literal_type
    if isinstance(ty, types.Integer) and ty.signed and ty.bitwidth < 64:
        return types.int64
    return ty


def _make_classes():
    from numba.core.caching import FunctionCache
    from numba.core.registry import CPUDispatcher
    from numba.core.runtime import rtsys

    for owner, names in ((CPUDispatcher, ("get_call_template", "get_overload",
                                          "enable_caching")),
                         (FunctionCache, ("load_overload", "_load_overload",
                                          "_guard_against_spurious_io_errors")),
                         (rtsys, ("initialize",))):
        for name in names:
            getattr(owner, name)  # AttributeError: not the Numba this was verified with

    class KernelCache(FunctionCache):
        """Numba's on-disk cache of one kernel, waiting for the compile helper when it is
        compiling this kernel (render/warm_up.py)."""

        #: set while a cold compile shares its work with a helper process: called with a
        #: kernel's qualified name when it is not in the cache, it waits while the helper
        #: compiles that kernel and says whether it did (then it loads instead)
        wait_for_helper = None

        @contextlib.contextmanager
        def _guard_against_spurious_io_errors(self):
            """Numba's guard; in a read-only folder, a file that cannot be written or read
            is a kernel compiled in memory (said once), not an error."""
            if not read_only(self._cache_path):
                with super()._guard_against_spurious_io_errors():
                    yield
                return
            try:
                yield
            except OSError:
                from .cache import read_only_miss

                read_only_miss()

        #: whether the kernel was compiled with Numba's runtime (``_nrt``); the machine code
        #: of one without it calls none of the runtime's functions
        runtime = True

        def load_overload(self, sig, target_context):
            if self.runtime:  # what loading needs of Numba's refresh
                rtsys.initialize(target_context)
            data = None
            with self._guard_against_spurious_io_errors():
                data = self._load_overload(sig, target_context)
            wait = KernelCache.wait_for_helper
            if data is None and wait is not None and wait(self._py_func.__qualname__):
                with self._guard_against_spurious_io_errors():
                    data = self._load_overload(sig, target_context)
            return data

    class KernelDispatcher(CPUDispatcher):
        """Numba's CPU dispatcher, compiling one variant for calls that differ only in
        integer argument types, calls from kernels going to its twin (module docstring)."""

        specialise_constants = False
        #: makes the twin; the twin itself is made on first use
        make_callee = None
        _callee = None

        @property
        def callee(self):
            if self._callee is None and self.make_callee is not None:
                with _twin_lock:
                    if self._callee is None:
                        self._callee = self.make_callee()
            return self._callee

        def enable_caching(self):
            self._cache = KernelCache(self.py_func)
            self._cache.runtime = self.targetoptions.get("_nrt", True) is not False

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

    return KernelDispatcher, KernelCache


_twin_lock = threading.Lock()


def kernel_cache_class():
    """The tuned dispatcher's cache class (for the compile helper's wait), or None."""
    return _classes[1] if tuned() else None


def _twin_function(f):
    """A copy of ``f`` under its own name (``<name>__whitted_twin``): the twin's cache files
    are its own."""
    twin = pytypes.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__,
                                f.__closure__)
    twin.__kwdefaults__ = f.__kwdefaults__
    twin.__qualname__ = f.__qualname__ + TWIN_SUFFIX
    twin.__module__ = f.__module__
    twin.__doc__ = f.__doc__
    return twin


def overload_options(forceinline: bool) -> dict:
    """Numba's options for an overload's implementation (jit/decorators.py ``overload``):
    with the tuned dispatcher, ``forceinline`` as given (Numba would pass on each caller's,
    so the code linked into a caller would depend on which callers were typed last) and no
    wrappers for calls from Python or C (an overload's implementation is never called from
    either); with stock Numba, none."""
    if not tuned():
        return {}
    return {"forceinline": forceinline, **CALLEE_ONLY, "no_cfunc_wrapper": True}


def make_dispatcher(f, options: dict, specialise_constants: bool, cache: bool):
    """The dispatcher of kernel ``f`` compiled with ``options`` (as jit/decorators.py resolved
    them): tuned (with the maker of its twin), or ``numba.njit`` with the documented ones."""
    if not tuned():
        import numba

        public = {k: v for k, v in options.items() if k not in TUNED_ONLY}
        public.pop("nopython", None)
        return numba.njit(cache=cache, **public)(f)
    dispatcher_class = _classes[0]

    def make(function, targetoptions):
        dispatcher = dispatcher_class(py_func=function, locals={},
                                      targetoptions=targetoptions)
        dispatcher.specialise_constants = specialise_constants
        if cache:
            dispatcher.enable_caching()
        return dispatcher

    dispatcher = make(f, options)
    dispatcher.make_callee = lambda: make(_twin_function(f), {**options, **CALLEE_ONLY})
    return dispatcher


def frame_view():
    """For kernels compiled without Numba's runtime (``_nrt=False``): ``view(pointer,
    count)``, an intrinsic viewing ``count`` slots at ``pointer`` (stack slots of the calling
    kernel, kernels/frame_array.py) as a 1-D C array without a memory owner. Numba's public
    ``numba.carray`` does the same but returns an array its runtime owns, which such kernels
    cannot take; stock Numba (runtime on) uses ``numba.carray``. Tuned dispatcher only."""
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def view(typingctx, pointer, count):
        if not isinstance(pointer, types.CPointer) or not isinstance(count, types.Integer):
            return None
        array_type = types.Array(pointer.dtype, 1, "C")

        def codegen(context, builder, sig, args):
            # imported here, when a kernel is compiled: NumPy's array code in Numba (20-40
            # ms with the string and hashing code it imports) is no part of a warm render
            from numba.np.arrayobj import make_array, populate_array

            data, n = args
            array = make_array(array_type)(context, builder)
            item = context.get_value_type(pointer.dtype)
            itemsize = context.get_constant(types.intp, context.get_abi_sizeof(item))
            populate_array(array, data=data,
                           shape=[context.cast(builder, n, sig.args[1], types.intp)],
                           strides=[itemsize], itemsize=itemsize, meminfo=None)
            return array._getvalue()

        return array_type(pointer, count), codegen

    return view
