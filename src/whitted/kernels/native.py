"""Calling cached kernels from Python without importing Numba.

A warm render spends its start-up importing Numba (0.13 s of 0.72 s for the timing scene,
AMD EPYC), making its dispatchers and loading kernels through them, only to run machine
code that Numba's cache already holds. This module runs that machine code itself, with
llvmlite alone (the library Numba compiles with): it loads the object code into an MCJIT
engine of its own and calls the function's Python wrapper, the code Numba generated to
unpack the arguments, run the kernel and hand back its result, exactly as Numba's dispatcher
does.

**The index** (``native/`` in the kernel cache folder). When an entry point (a kernel that
Python calls: ``@builder``, ``@kernel(entry=True)``, kernels/jit.py) is called through
Numba, whitted writes what a later process needs to call the same code: the library's object
code as Numba caches it, the names of its wrapper and environment, and the key of the call's
argument types. One file per kernel and key, written whole or not at all.

**The key** (:func:`argument_key`) holds what Numba types an argument by: an array's dtype,
dimensions, layout (C, F or neither), whether it is writeable and aligned; a scalar's kind
(bool, int64, float64, complex128, a NumPy scalar's dtype); a tuple's or named tuple's
elements (and the named tuple's class and fields); None. Numba's wrapper trusts the types it was
compiled for: an array of another dtype would be read as if it were that one. So an argument
of any other kind (a subclass of ndarray, a list, a Python int beyond 64 bits) has no key, and
the call goes to Numba. The file's name also holds the CPU (name and features, as LLVM reports
them), the Python, NumPy, Numba and llvmlite installs, so machine code never crosses them.

**Linking.** Numba's objects refer to the Python C API, the C maths library, Numba's C
helpers (``numba_*``, from ``numba/_helperlib``, ``numba/_dynfunc``) and its runtime
(``NRT_*``, from ``numba/core/runtime/_nrt_python``, which the builders allocate with). The
three extension modules are loaded from their files without importing the ``numba``
package, and their addresses given to LLVM under the names Numba gives them. Every
undefined symbol of an object is checked before the object is added (LLVM aborts the process
on one it cannot resolve); one that is missing sends the call to Numba.

**When not.** Only on Linux (ELF objects), with ``NUMBA_*`` settings that do not change code
(the cache folder, threads, SLP), no ``.numba_config.yaml`` in the working folder, and unless
``WHITTED_NATIVE=0``. An exception raised inside a kernel arrives as Numba raises it, without
Numba being imported: its details are unpickled by the engine's ``numba_unpickle``.

Measured, AMD EPYC (Zen 4), ``whitted render benchmarks/seed000.toml -t 2``, whole process:
see docs/performance.md ("Fifth speed round").
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.machinery
import importlib.util
import os
import pickle
import sys
import threading
from pathlib import Path

import numpy as np

from .elf import elf_symbols

FORMAT = 1
#: NUMBA_* settings that leave the machine code as it is
HARMLESS_SETTINGS = frozenset({"NUMBA_CACHE_DIR", "NUMBA_SLP_VECTORIZE", "NUMBA_NUM_THREADS",
                               "NUMBA_THREADING_LAYER", "NUMBA_DEFAULT_NUM_THREADS"})

_lock = threading.RLock()
_enabled: bool | None = None
_engine = None  # the _Engine, made on first use
_calls: dict = {}  # (kernel, key) -> callable, or None when the index has none
_remembered: set = set()  # (kernel, key) written (or found) by this process


def enabled() -> bool:
    global _enabled
    if _enabled is None:
        _enabled = (sys.platform.startswith("linux")
                    and os.environ.get("WHITTED_NATIVE", "1") != "0"
                    and not any(k.startswith("NUMBA_") and k not in HARMLESS_SETTINGS
                                for k in os.environ)
                    and not os.path.exists(".numba_config.yaml")
                    and importlib.util.find_spec("llvmlite") is not None)
    return _enabled


# ------------------------------------------------------------------ argument keys

_ndarray, _number_or_bool = np.ndarray, (np.number, np.bool_)
_SCALARS = {bool: "bool", int: "int64", float: "float64", complex: "complex128"}


def _key(value):
    kind = type(value)
    if kind is _ndarray:
        flags = value.flags
        layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
        return ("a", value.dtype.str if value.dtype.fields is None else repr(value.dtype),
                value.ndim, layout, flags.writeable, flags.aligned)
    if kind is tuple:
        return ("t", *map(_key, value))
    scalar = _SCALARS.get(kind)
    if scalar is not None:
        if kind is int and not -(1 << 63) <= value < (1 << 63):
            raise _NoKey
        return scalar
    if value is None:
        return "none"
    if isinstance(value, tuple) and hasattr(kind, "_fields"):  # a named tuple
        return ("n", kind.__module__, kind.__qualname__, kind._fields, *map(_key, value))
    if isinstance(value, _number_or_bool):  # NumPy's scalars, but not records (np.void)
        return ("s", value.dtype.str)
    raise _NoKey


class _NoKey(Exception):
    pass


def argument_key(args: tuple):
    """What Numba types ``args`` by (module docstring), or None for an argument of a kind the
    key does not cover."""
    try:
        return tuple(map(_key, args))
    except _NoKey:
        return None


# ------------------------------------------------------------------ the index


def _install_stamp(module: str) -> tuple:
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return (module, None)
    folder = os.path.dirname(spec.origin)
    stamp = [module]
    for name in sorted(os.listdir(folder)):
        if name.endswith((".so", ".pyd")) or name in ("__init__.py", "_version.py"):
            st = os.stat(os.path.join(folder, name))
            stamp.append((name, st.st_size, st.st_mtime_ns))
    return tuple(stamp)


_fingerprint: str | None = None


def fingerprint() -> str:
    """The CPU, Python, NumPy, Numba and llvmlite that machine code in the index is for."""
    global _fingerprint
    if _fingerprint is None:
        from llvmlite import binding as ll

        parts = (FORMAT, sys.version, sys.implementation.cache_tag, np.__version__,
                 _install_stamp("numba"), _install_stamp("llvmlite"), ll.get_process_triple(),
                 ll.get_host_cpu_name(), ll.get_host_cpu_features().flatten())
        _fingerprint = hashlib.sha256(repr(parts).encode()).hexdigest()[:16]
    return _fingerprint


def index_folder() -> Path:
    from .._cache import configure_kernel_cache

    return Path(configure_kernel_cache()) / "native"


_stamps: dict = {}


@functools.cache
def _whitted_sources() -> str:
    """The hash of whitted's kernel sources (once per process: 1 ms)."""
    from .._cache import kernel_source_hash

    return kernel_source_hash()


def kernel_stamp(kernel) -> str | None:
    """What the kernel's machine code depends on besides its arguments, as Numba's own cache
    index keys it and more: the function's compiled bytecode (constants, names, lines
    included), its source file's size and modification time (the module's other globals,
    which Numba freezes into the code), and whitted's kernel sources (the kernels it calls,
    in other files). None for a kernel the index does not take: one compiled with
    ``cache=False``, or a closure (its cells are frozen into the code too)."""
    stamp = _stamps.get(kernel, False)
    if stamp is False:
        function = kernel.py_func
        if not kernel.cache or function.__closure__:
            stamp = None
        else:
            import marshal

            code = function.__code__
            try:
                st = os.stat(code.co_filename)
                source = (st.st_size, st.st_mtime_ns)
            except OSError:
                source = None
            digest = hashlib.sha256(marshal.dumps(code))
            digest.update(repr((source, _whitted_sources())).encode())
            stamp = digest.hexdigest()
        _stamps[kernel] = stamp
    return stamp


def _entry_path(kernel, key) -> Path | None:
    stamp = kernel_stamp(kernel)
    if stamp is None:
        return None
    name = f"{kernel.__module__}.{kernel.__qualname__}"
    digest = hashlib.sha256(repr((name, key, stamp, fingerprint())).encode()).hexdigest()
    return index_folder() / f"{name}-{digest[:24]}.bin"


def machine_code(kernel, args: tuple):
    """A callable running ``kernel`` on arguments like ``args`` (called with the tuple) from
    the native index, or None: not enabled, no key, nothing in the index, or anything about
    the entry this process cannot link."""
    if not enabled():
        return None
    key = argument_key(args)
    if key is None:
        return None
    found = _calls.get((kernel, key), False)
    if found is not False:
        return found
    with _lock:
        found = _calls.get((kernel, key), False)
        if found is False:
            found = _calls[(kernel, key)] = _load(kernel, key)
            if found is not None:
                _remembered.add((kernel, key))
    return found


def _load(kernel, key):
    try:
        path = _entry_path(kernel, key)
        if path is None:
            return None
        data = path.read_bytes()
    except Exception:  # noqa: BLE001 - no entry, or no CPU answer from LLVM: Numba's way
        return None
    try:
        entry = pickle.loads(data)
        if entry["format"] != FORMAT or entry["key"] != key:
            return None
        return _get_engine().add(entry)
    except Exception:  # noqa: BLE001 - a damaged or foreign file: Numba does the call
        return None


def remember(kernel, args: tuple) -> None:
    """After ``kernel`` (a :class:`.jit.Kernel`) was called through Numba with ``args``: put
    the machine code Numba ran into the index, unless it is there or cannot be (no key, no
    exact overload, no object code)."""
    if not enabled():
        return
    key = argument_key(args)
    if key is None or (kernel, key) in _remembered:
        return
    _remembered.add((kernel, key))
    try:
        entry = _entry_from_numba(kernel.dispatcher, args, key)
        if entry is None:
            return
        path = _entry_path(kernel, key)
        if path is None or path.exists():
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
        try:
            tmp.write_bytes(pickle.dumps(entry, protocol=pickle.HIGHEST_PROTOCOL))
            os.replace(tmp, path)
        finally:
            with contextlib.suppress(OSError):
                tmp.unlink()
    except Exception:  # noqa: BLE001 - a read-only cache, a full disk: Numba does the calls
        return


def _entry_from_numba(dispatcher, args: tuple, key) -> dict | None:
    types = tuple(dispatcher.typeof_pyval(a) for a in args)
    result = dispatcher.overloads.get(types)
    if result is None:  # Numba converted the arguments to another overload: no entry
        return None
    library = result.library
    # only code Numba itself would cache: none with addresses of this process baked in
    # (dynamic globals: ctypes pointers, big global arrays) and none with object-mode parts
    if library.has_dynamic_globals or any(not x.can_cache for x in result.lifted):
        return None
    obj = getattr(library, "whitted_object_code", None) or getattr(
        library, "_compiled_object", None)
    undefined = elf_undefined_symbols(obj) if obj else None
    consts = _plain_pickle(list(result.environment.consts))
    if undefined is None or consts is None:
        return None
    return {"format": FORMAT, "key": key, "object": obj,
            "wrapper": result.fndesc.llvm_cpython_wrapper_name,
            "environment": result.fndesc.env_name, "module": result.fndesc.modname,
            "consts": consts, "undefined": sorted(undefined)}


def _plain_pickle(values: list) -> bytes | None:
    """``values`` pickled, when they unpickle without Numba (the environment's constants:
    the dtypes of the arrays a builder returns); None otherwise."""
    import pickletools

    try:
        data = pickle.dumps(values, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # noqa: BLE001 - an object that does not pickle
        return None
    for _op, argument, _at in pickletools.genops(data):
        if isinstance(argument, str) and argument.split(".")[0] in ("numba", "llvmlite"):
            return None
    return data


# ------------------------------------------------------------------ ELF symbols

def elf_undefined_symbols(obj: bytes) -> set[str] | None:
    """The symbols an ELF64 little-endian object file needs from elsewhere (kernels/elf.py);
    None when it is not such a file."""
    symbols = elf_symbols(obj)
    return None if symbols is None else symbols[1]


# ------------------------------------------------------------------ the engine


def _extension(package_dir: str, name: str):
    """Numba's extension module ``name`` (``numba._helperlib``, ...): the one in
    ``sys.modules``, or loaded from its file without importing the ``numba`` package and put
    in ``sys.modules`` under that name, where Numba's own imports (all ``from numba import
    _helperlib`` and the like) find it. One copy per process: a second initialisation of
    ``_nrt_python`` would reset the runtime's allocator and statistics."""
    import glob

    module = sys.modules.get(name)
    if module is not None:
        return module
    relative = os.path.join(*name.split(".")[1:])
    (path,) = glob.glob(os.path.join(package_dir, relative + ".*.so")) or [None]
    if path is None:
        raise ImportError(name)
    loader = importlib.machinery.ExtensionFileLoader(name, path)
    spec = importlib.util.spec_from_file_location(name, path, loader=loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    sys.modules[name] = module
    return module


def _import_lock():
    """The import system's lock: no ``import numba`` in another thread sees the extension
    modules half registered."""
    import _imp
    import contextlib

    @contextlib.contextmanager
    def held():
        _imp.acquire_lock()
        try:
            yield
        finally:
            _imp.release_lock()

    return held()


class _Engine:
    """llvmlite's MCJIT holding the loaded kernels, with Numba's symbols registered."""

    def __init__(self) -> None:
        import builtins
        import ctypes

        from llvmlite import binding as ll

        spec = importlib.util.find_spec("numba")
        package_dir = os.path.dirname(spec.origin)
        with _import_lock():
            helperlib = _extension(package_dir, "numba._helperlib")
            dynfunc = _extension(package_dir, "numba._dynfunc")
            nrt_loaded = "numba.core.runtime._nrt_python" in sys.modules
            nrt = _extension(package_dir, "numba.core.runtime._nrt_python")
        if not nrt_loaded:
            nrt.memsys_use_cpython_allocator()  # as numba/core/runtime/nrt.py does
        symbols = {"_Py_NoneStruct": id(None)}
        for table in (helperlib.c_helpers, dynfunc.c_helpers):
            symbols.update(("numba_" + name, address) for name, address in table.items())
        symbols.update((name if name.startswith("_") else "NRT_" + name, address)
                       for name, address in nrt.c_helpers.items())
        for value in vars(builtins).values():
            if isinstance(value, type) and issubclass(value, BaseException):
                symbols["PyExc_" + value.__name__] = id(value)
        self._unpickled: dict = {}
        self._unpickle = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int,
                                          ctypes.c_void_p)(self._unpickle_constant)
        self._incref = ctypes.pythonapi.Py_IncRef
        self._incref.argtypes = (ctypes.py_object,)
        self._incref.restype = None
        symbols["numba_unpickle"] = ctypes.cast(self._unpickle, ctypes.c_void_p).value
        self.symbols = symbols
        self.maths = helperlib.c_helpers  # C maths, bound to CPython's libm as Numba does
        self.ll = ll
        self.dynfunc = dynfunc
        self.ctypes = ctypes
        ll.initialize_native_target()
        ll.initialize_native_asmprinter()
        machine = ll.Target.from_default_triple().create_target_machine(
            cpu=ll.get_host_cpu_name(), features=ll.get_host_cpu_features().flatten(),
            opt=0, reloc="default", codemodel="jitdefault")
        self.context = ll.create_context()  # not the global one Numba compiles in
        self.engine = ll.create_mcjit_compiler(ll.parse_assembly("", context=self.context),
                                               machine)
        self.environments = []  # kept alive as long as the code that points at them
        self.registered: set[str] = set()
        self.call_type = ctypes.PYFUNCTYPE(ctypes.py_object, ctypes.c_void_p,
                                           ctypes.py_object, ctypes.c_void_p)

    def _unpickle_constant(self, data: int, size: int, hashed: int):
        """``numba_unpickle``: a constant the machine code holds pickled (the ndarray class a
        builder's result is made of, an exception's details), unpickled once per place and
        kept, as Numba's helper does (numba/core/serialize.py), but without importing the
        numba package for it."""
        ctypes = self.ctypes
        interrupted = False
        while True:  # a Ctrl-C arriving here is delivered again once this has returned
            try:
                key = (data, ctypes.string_at(hashed, 20))  # the pickle's SHA-1, its address
                value = self._unpickled.get(key)
                if value is None:
                    value = self._unpickled[key] = pickle.loads(ctypes.string_at(data, size))
                self._incref(value)  # a new reference, as Numba's helper returns
                address = id(value)
                break
            except KeyboardInterrupt:
                interrupted = True
            except BaseException:  # noqa: BLE001 - NULL, as Numba's helper gives on failure
                address = None
                break
        if interrupted:
            import _thread

            _thread.interrupt_main()
        return address

    def _resolve(self, name: str) -> bool:
        """Whether ``name`` resolves, registering it as Numba would: a C maths function to
        Numba's binding of it (the same address Numba registers, whoever does it first);
        anything that already resolves (the process's own symbols, Numba's helpers once
        Numba has registered them) as it does, never replaced; else Numba's helper of that
        name (``numba_*``, ``NRT_*``) from the extension modules."""
        if name in self.registered:
            return True
        address = None if name.startswith(("numba_", "NRT_")) else self.maths.get(name)
        if address is None and not self.ll.address_of_symbol(name):
            address = self.symbols.get(name)
            if not address:
                return False
        if address is not None:
            self.ll.add_symbol(name, address)
        self.registered.add(name)
        return True

    def add(self, entry: dict):
        if not all(self._resolve(name) for name in entry["undefined"]):
            return None
        ll = self.ll
        self.engine.add_object_file(ll.ObjectFileRef.from_data(entry["object"]))
        self.engine.finalize_object()
        wrapper = self.engine.get_function_address(entry["wrapper"])
        slot = self.engine.get_global_value_address(entry["environment"])
        if not wrapper or not slot:
            return None
        environment = self.dynfunc.Environment({"__name__": entry["module"]})
        environment.consts[:] = pickle.loads(entry["consts"])  # the returned arrays' dtypes
        self.environments.append(environment)
        self.ctypes.c_void_p.from_address(slot).value = id(environment)
        call = self.call_type(wrapper)
        return lambda args: call(None, args, None)


def _get_engine() -> _Engine:
    global _engine
    if _engine is None:
        _engine = _Engine()
    return _engine
