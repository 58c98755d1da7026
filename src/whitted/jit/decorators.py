"""The decorators every kernel is written with, importable without importing Numba.

``@kernel`` (render kernels: fast-math, no runtime), ``@builder`` (the kernels that build a
scene's arrays and parse files: Numba's defaults, with the runtime), and the two Numba
extensions kernels use, ``@overload`` and :func:`numba_object`.

A decorated kernel is a :class:`Kernel`: its Python function and its options. Its Numba
dispatcher is made, and Numba imported, only when something needs it: a kernel is called or
compiled, or code asks for a dispatcher's attributes (``signatures``, ``overloads``, ...,
which a Kernel passes on to its dispatcher). So ``import whitted`` and the commands that
never render never import Numba.

The dispatcher is Numba's own (``numba.njit`` with the options below), or, on the Numba
versions jit/dispatcher.py was verified with, that module's tuned one (integer widening,
twins without Python wrappers, no runtime in render kernels): the one module that uses
names Numba does not document. Options:

- ``error_model="numpy"``: 1/0 gives inf instead of raising; ``nogil=True``: the editor's UI
  thread runs while a render is in flight;
- ``fastmath``: the flags that let LLVM reorder and fuse arithmetic (``reassoc``,
  ``contract``, ``arcp``, ``nsz``, ``afn``) but not ``nnan`` or ``ninf``: kernels use inf as
  the "no hit" sentinel. The watertight triangle test opts out (``fastmath=False``);
- ``inline="always"``: inlined by LLVM where the tuned dispatcher is used (its
  ``forceinline``), not inlined otherwise; ``numba_inline=True``: Numba's own IR inliner
  (``inline="always"`` of ``numba.njit``);
- ``specialise_constants=True``: a variant per integer constant (what stock Numba always
  does; the tuned dispatcher otherwise compiles one int64 variant);
- ``entry=True``: a kernel Python calls (its calls seal the cache files a compile wrote,
  jit/cache.py);
- ``cache`` (default True): kept in the kernel cache (jit/cache.py; in memory when no
  folder can be used).

When Numba comes in (:func:`load_numba`) the kernel cache is prepared and checked and the
deferred extensions are registered. Before Numba first compiles something in the process
(its ``numba:compile`` event, :func:`swap_in_globals`), in the globals of whitted's modules
(and of any module that defined a kernel) each Kernel that is not an entry point, and each
:func:`numba_object`, is replaced by the real thing: kernels call kernels through their
module globals, and Numba's compiler must find its own objects there. A process whose
kernels all load from the cache never makes the other 150 dispatchers nor imports the
Numba extensions (0.35 s of a loaded 2-core machine's warm render, measured with cProfile).
An entry point stays a Kernel, so calls from Python seal what they compiled; Numba types any
Kernel as its dispatcher (``_numba_type_``, which a Kernel passes on). A non-entry kernel
defined after the swap is its dispatcher at once.
"""

from __future__ import annotations

import functools
import importlib
import os
import sys
import threading

#: the fast-math flags of render kernels (module docstring)
FAST_MATH = frozenset({"reassoc", "contract", "arcp", "nsz", "afn"})

_lock = threading.RLock()
_numba_loaded = False  # Numba imported, extensions registered
_numba_imported = False  # the first two done (the extensions may still be registering)
_swapped = False  # dispatchers put in the kernels' globals (before the first compile)
_swapping = False
_deferred: list = []  # registrations waiting for Numba: callables, run in order
_defining_modules: set[str] = set()  # modules that defined kernels (swapped by load_numba)
#: globals of functions made outside a module (kernels/strict.py's twins), swapped like a
#: module's before the first compile
_namespaces: list[dict] = []
#: every kernel made, by its Python function, and every overload registered, by the function
#: it implements: (implementation, options) (kernels/strict.py makes IEEE twins from them)
kernels_by_function: dict = {}
overloads_by_function: dict = {}


def _jit_disabled() -> bool:
    """Numba's ``NUMBA_DISABLE_JIT``: kernels stay plain Python functions."""
    if "numba" in sys.modules:
        from numba import config

        return bool(config.DISABLE_JIT)
    try:
        return int(os.environ.get("NUMBA_DISABLE_JIT", "0") or 0) != 0
    except ValueError:
        return False


def load_numba() -> None:
    """Prepare and check the kernel cache (jit/cache.py), import Numba with whitted's
    settings and register the deferred extensions. Does nothing the second time. Dispatchers
    are put where kernels look for them (module docstring) only before Numba first compiles
    something (:func:`swap_in_globals`): a process that loads every kernel it runs from the
    cache makes only the dispatchers it calls."""
    global _numba_loaded, _numba_imported
    if _numba_loaded:
        return
    with _lock:  # another thread waits here until the swap is done
        if _numba_loaded or _numba_imported:  # done, or this thread is swapping (re-entry)
            return
        from .cache import prepare

        prepare()  # NUMBA_CACHE_DIR set, the files checked, before Numba reads any
        if "NUMBA_SLP_VECTORIZE" not in os.environ:
            # LLVM's SLP vectoriser packs the three lanes of vector arithmetic into SIMD
            # instructions (docs/performance.md); set in the environment, as Numba reads its
            # settings from there again whenever the environment has changed
            os.environ["NUMBA_SLP_VECTORIZE"] = "1"
            if "numba" in sys.modules:
                from numba import config

                config.SLP_VECTORIZE = 1
        from numba.core import event

        from .array_typing import install as type_arrays_without_numpy_ma
        from .collector import collector_listener
        from .frame_stack import frame_stack_listener

        type_arrays_without_numpy_ma()
        # the collector's first: Numba tells the listeners in turn and stops at one that
        # raises, and a skipped end of a compile would leave the collector off for good
        event.register("numba:compile", collector_listener())  # no collections mid-compile
        event.register("numba:compile", frame_stack_listener())  # chunks reused, not mapped
        event.register("numba:compile", _compile_listener())
        while _deferred:
            _deferred.pop(0)()
        _numba_imported = True
        _numba_loaded = True


def swap_in_globals() -> None:
    """Before Numba's first compile in this process (its compile event): each kernel that is
    not an entry point, and each :func:`numba_object`, replaced by the real thing in the
    globals of the modules that use them, where Numba's compiler looks (module docstring)."""
    global _swapped, _swapping
    if _swapped:
        return
    with _lock:
        if _swapped or _swapping:  # done, or this thread is swapping (re-entry)
            return
        _swapping = True
        try:
            done: set[str] = set()
            while True:  # modules imported while swapping (a resolved object's) too
                todo = _whitted_modules() - done
                if not todo:
                    break
                _swap_in_globals(todo)
                done |= todo
        finally:
            _swapped = True
            _swapping = False


def _compile_listener():
    """A listener of Numba's compile events (``numba.core.event``, Numba's documented event
    API): after a compile, the cache files it wrote are sealed when the call from Python
    returns (Kernel.__call__)."""
    from numba.core import event

    from .cache import prepare

    class CompileSeen(event.Listener):
        def on_start(self, ev) -> None:
            swap_in_globals()  # before the compiler reads any kernel's globals
            prepare().compiling()

        def on_end(self, ev) -> None:
            prepare().unsealed = True

    return CompileSeen()


def seal_cache() -> None:
    """Enter the cache files compiles wrote in the list of checksums (jit/cache.py)."""
    from .cache import prepare

    state = prepare()
    if state.unsealed:
        state.seal()


def _whitted_modules() -> set[str]:
    return {m for m in list(sys.modules) if m == "whitted" or m.startswith("whitted.")} \
        | set(_defining_modules)


def _swap_in_globals(names: set[str]) -> None:
    for name in names:
        module = sys.modules.get(name)
        if module is not None:
            _swap_in_namespace(vars(module))
    while _namespaces:
        _swap_in_namespace(_namespaces.pop())


def _swap_in_namespace(namespace: dict) -> None:
    for key, value in list(namespace.items()):
        if isinstance(value, Kernel) and not value.entry:
            namespace[key] = value.dispatcher
        elif isinstance(value, NumbaObject):
            namespace[key] = value.resolve()


def kernels_in_globals(namespace: dict) -> None:
    """Have the kernels in ``namespace`` (the globals of a function made outside a module,
    which calls them) swapped for their dispatchers as a module's are: before Numba's first
    compile in the process, or now if that has begun."""
    with _lock:
        if _swapped:
            _swap_in_namespace(namespace)
        else:
            _namespaces.append(namespace)


class Kernel:
    """A kernel: its Python function (``py_func``), the Numba options it is compiled with,
    and, made when first needed, its Numba dispatcher (jit/dispatcher.py)."""

    _dispatcher = None
    entry = False

    def __init__(self, py_func, options: dict, specialise_constants: bool, cache: bool,
                 entry: bool) -> None:
        functools.update_wrapper(self, py_func)
        self.py_func = py_func
        self.options = options
        self.specialise_constants = specialise_constants
        self.cache = cache
        #: called from Python: its calls seal the cache files their compiles wrote
        self.entry = entry
        self._dispatcher = None

    @property
    def dispatcher(self):
        if self._dispatcher is None:
            load_numba()
            with _lock:
                if self._dispatcher is None:
                    from .cache import prepare
                    from .dispatcher import make_dispatcher

                    state = prepare()
                    cache = self.cache and state.folder is not None
                    if cache and state.read_only:
                        from .cache import read_only_miss
                        from .dispatcher import tuned

                        if not tuned():  # stock Numba cannot load from a folder it
                            cache = False  # cannot write: compiled in memory
                            read_only_miss("stock Numba loads only from a folder it can "
                                           "write")
                    self._dispatcher = make_dispatcher(self.py_func, self.options,
                                                       self.specialise_constants, cache)
        return self._dispatcher

    def __call__(self, *args, **kwargs):
        result = self.dispatcher(*args, **kwargs)
        if self.entry:
            from .cache import _state

            if _state is not None and _state.unsealed:
                _state.seal()
        return result

    def __getattr__(self, name: str):
        if name.startswith("__"):  # copy, pickle, inspect: not the dispatcher's business
            raise AttributeError(name)
        return getattr(self.dispatcher, name)  # signatures, overloads, _numba_type_, ...

    def __reduce__(self):
        return _find_kernel, (self.__module__, self.__qualname__)

    def __repr__(self) -> str:
        return f"<kernel {self.__module__}.{self.__qualname__}>"


def _find_kernel(module: str, qualname: str):
    target = importlib.import_module(module)
    for part in qualname.split("."):
        target = getattr(target, part)
    return target


class NumbaObject:
    """An object of a module that imports Numba (a Numba extension: an intrinsic, a function
    with an overload), named where a kernel uses it, and imported with Numba: kernels/
    embree.py's intrinsics, kernels/geometry_ref.py's reference."""

    def __init__(self, module: str, name: str) -> None:
        self.module = module
        self.name = name

    def resolve(self):
        load_numba()
        return getattr(importlib.import_module(self.module), self.name)

    def __call__(self, *args, **kwargs):
        return self.resolve()(*args, **kwargs)

    def __repr__(self) -> str:
        return f"<{self.module}.{self.name}, imported with Numba>"


def numba_object(module: str, name: str):
    """``name`` of ``module`` (a full module name), for a kernel to use: imported when Numba
    is (at once when it is already)."""
    made = NumbaObject(module, name)
    return made.resolve() if _swapped else made


def overload(function, *, forceinline: bool = False, **options):
    """Numba's ``numba.extending.overload``, registered when Numba is loaded. With the tuned
    dispatcher the implementation is compiled with ``forceinline`` as given, the same for
    every caller (Numba would pass on each caller's own), and without a C wrapper
    (jit/dispatcher.py ``overload_options``); an implementation that is a kernel's body
    (:func:`body`) is given that kernel's ``forceinline``."""
    options["forceinline"] = forceinline

    def decorate(implementation):
        overloads_by_function[function] = (implementation, options)

        def register():
            register_overload(function, implementation, options)

        with _lock:
            if _numba_loaded:
                register()
            else:
                _deferred.append(register)
        return implementation

    return decorate


def register_overload(function, implementation, options: dict) -> None:
    """Register ``implementation`` as Numba's overload of ``function`` with whitted's
    ``options`` (those :func:`overload` was given; kernels/strict.py registers its twins'
    the same way)."""
    from numba.extending import overload as numba_overload

    from .dispatcher import overload_options

    options = dict(options)
    forceinline = options.pop("forceinline", False)
    options["jit_options"] = {**overload_options(forceinline), **options.get("jit_options", {})}
    numba_overload(function, **options)(implementation)


def body(target):
    """The Python function of kernel ``target`` (a Kernel or its dispatcher), for an overload
    to return as its implementation. Numba compiles an overload's implementation as a
    function of its own, linked into its callers: a lambda that calls the kernel is one more
    level whose module links the kernel's (and all below it) and has LLVM optimise it all
    again, as every separately compiled caller does (docs/performance.md, the overload-body
    round). Returned as the implementation, the kernel's own code is that function, and the
    level is gone. Its options are the overload's (``forceinline`` as the kernel's, given to
    :func:`overload`: the tuned dispatcher's); fast-math and the error model are its
    callers', as a kernel's callers' are the same as the kernel's (an IEEE twin's callers are
    twins: kernels/strict.py)."""
    return target.py_func


def kernel(fn=None, *, entry: bool = False, **options):
    """A render kernel (the options: the module docstring); ``entry=True`` for one that
    Python calls."""
    opts = {"nopython": True, "error_model": "numpy", "nogil": True, "_nrt": False,
            "fastmath": set(FAST_MATH), "no_cfunc_wrapper": True}
    opts.update(options)
    # always set: Numba lets a callee compiled while an alwaysinline kernel compiles inherit
    # the flag, so a kernel would be inlined or not depending on which caller compiled it
    # first (in this process, or in another from whose cache it loads)
    opts["forceinline"] = False
    if opts.get("inline") == "always":  # inlined by LLVM, not by Numba (module docstring)
        del opts["inline"]
        opts["forceinline"] = True
    if opts.pop("numba_inline", False):  # inlined by Numba into its one caller
        opts["inline"] = "always"
    cache = opts.pop("cache", True)
    specialise_constants = opts.pop("specialise_constants", False)

    def make(f):
        if _jit_disabled():
            return f
        made = Kernel(f, opts, specialise_constants, cache, entry)
        kernels_by_function[f] = made
        if _swapped and not entry:
            return made.dispatcher
        _defining_modules.add(f.__module__)
        return made

    return make if fn is None else make(fn)


def builder(fn=None, **options):
    """The decorator of the kernels that build acceleration data and parse files: Numba's own
    defaults (no fast-math, Python's error model, the Numba runtime so they may allocate
    their results), compiled and cached like every kernel, and called from Python (entry
    points)."""
    opts = {"error_model": "python", "_nrt": True, "fastmath": False, "entry": True}
    opts.update(options)
    return kernel(fn, **opts)
