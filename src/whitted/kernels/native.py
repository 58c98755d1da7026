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
elements (and the named tuple's class); None. Numba's wrapper trusts the types it was
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
``WHITTED_NATIVE=0``. An exception raised inside a kernel imports Numba to build it (Numba's
C helpers do); nothing else does.

Measured, AMD EPYC (Zen 4), ``whitted render benchmarks/seed000.toml -t 2``, whole process:
see docs/performance.md ("Fifth speed round").
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.machinery
import importlib.util
import os
import pickle
import struct
import sys
import threading
from pathlib import Path

import numpy as np

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
        return ("n", kind.__module__, kind.__qualname__, *map(_key, value))
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


def _entry_path(kernel, key) -> Path:
    name = f"{kernel.__module__}.{kernel.__qualname__}"
    digest = hashlib.sha256(repr((name, key, fingerprint())).encode()).hexdigest()[:24]
    return index_folder() / f"{name}-{digest}.bin"


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
        data = _entry_path(kernel, key).read_bytes()
    except OSError:
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
        if path.exists():
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

SHT_SYMTAB = 2


def elf_undefined_symbols(obj: bytes) -> set[str] | None:
    """The symbols an ELF64 little-endian object file needs from elsewhere; None when it is
    not such a file."""
    if obj[:4] != b"\x7fELF" or obj[4] != 2 or obj[5] != 1:
        return None
    (shoff,) = struct.unpack_from("<Q", obj, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", obj, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", obj, shoff + i * shentsize)
                for i in range(shnum)]
    names: set[str] = set()
    for _name, kind, _flags, _addr, offset, size, link, _info, _align, entsize in sections:
        if kind != SHT_SYMTAB or entsize == 0:
            continue
        strings = sections[link][4]
        for at in range(offset + entsize, offset + size, entsize):  # entry 0 is null
            st_name, _st_info, _other, st_shndx = struct.unpack_from("<IBBH", obj, at)
            if st_shndx == 0 and st_name:
                end = obj.index(b"\0", strings + st_name)
                names.add(obj[strings + st_name:end].decode())
    return names


# ------------------------------------------------------------------ the engine


def _extension(package_dir: str, relative: str, name: str):
    """Numba's extension module ``relative`` (a path under the numba package), loaded from its
    file under the plain name ``name`` and kept out of ``sys.modules``: the ``numba`` package
    is not imported. Its C functions are the ones Numba's copy uses (one shared library)."""
    import glob

    (path,) = glob.glob(os.path.join(package_dir, relative + ".*.so")) or [None]
    if path is None:
        raise ImportError(relative)
    loader = importlib.machinery.ExtensionFileLoader(name, path)
    spec = importlib.util.spec_from_file_location(name, path, loader=loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


class _Engine:
    """llvmlite's MCJIT holding the loaded kernels, with Numba's symbols registered."""

    def __init__(self) -> None:
        import builtins
        import ctypes

        from llvmlite import binding as ll

        spec = importlib.util.find_spec("numba")
        package_dir = os.path.dirname(spec.origin)
        helperlib = _extension(package_dir, "_helperlib", "_helperlib")
        dynfunc = _extension(package_dir, "_dynfunc", "_dynfunc")
        nrt = _extension(package_dir, os.path.join("core", "runtime", "_nrt_python"),
                         "_nrt_python")
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
        self._unpickle = ctypes.CFUNCTYPE(ctypes.py_object, ctypes.c_void_p, ctypes.c_int,
                                          ctypes.c_void_p)(self._unpickle_constant)
        if "numba.core.serialize" not in sys.modules:  # else Numba's own helper is as cheap
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
        self.engine = ll.create_mcjit_compiler(ll.parse_assembly(""), machine)
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
        key = (data, ctypes.string_at(hashed, 20))  # the pickle's SHA-1 beside its address
        value = self._unpickled.get(key)
        if value is None:
            value = self._unpickled[key] = pickle.loads(ctypes.string_at(data, size))
        return value

    def _resolve(self, name: str) -> bool:
        if name in self.registered:
            return True
        address = self.symbols.get(name) or (self.maths.get(name) if not
                                             name.startswith(("numba_", "NRT_")) else None)
        if address:
            self.ll.add_symbol(name, address)
        elif not self.ll.address_of_symbol(name):
            return False
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
