"""Loading kernels from Numba's on-disk cache, and calling them, with less work than Numba does.

Four steps of Numba's own work do what a kernel never needs; whitted replaces them
(process-wide, on importing kernels/jit.py). Each keeps Numba's behaviour for whatever does
need the skipped work, and the cache stays in Numba's format.

**Environments without importing their modules.** Numba's ``_rebuild_env`` unpickles the
environment of each function in a cached library and imports the function's module to hand
its globals to the environment. Only code compiled in object mode reads them, which no
kernel is (``nopython=True``). The one module a render's cached kernels named and nobody had
imported was ``numba.np.arrayobj`` (the builders' ``np.empty``), whose import brought NumPy's
masked arrays and Numba's string types along: 25-30 ms of every render's start-up. An
environment of a module not imported yet gets a globals dict holding only the module's
name, as Numba's own is recognised by (``can_cache``).

**Bitcode parsed when it is needed.** A cached library holds its machine code and its LLVM
bitcode, and Numba parses the bitcode at load for two things: the names the library defines
(``get_pointer_to_function`` answers only for those: the entry points), and a module to link
into a later compile that calls one of its functions. Parsing was half of all kernel
loading: 21.6 of 43 ms in a render of seed000 (AMD EPYC). The names are read from the
machine code's ELF symbol table instead: its defined global and weak symbols, which are the
names the JIT can resolve. The bitcode also names functions inlined away and private
constants, which have no address in the machine code; asking for one gives 0 either way (a
test checks both on every kernel a render loads). The bitcode is parsed the first time the
library is linked into another. An object file that is not ELF (another platform) loads Numba's way.

**Arrays typed without importing NumPy's masked arrays.** The first call of a kernel types
its arguments, and Numba's ``typeof`` of an array first asks whether it is a
``np.ma.MaskedArray``, which makes NumPy import ``numpy.ma`` (7 ms at every start-up). An
array whose type is exactly ``np.ndarray`` cannot be one; it is typed as Numba types it, and
anything else (a subclass) still goes to Numba's own function.

**Twins are never turned into machine code.** A kernel other kernels call is compiled as a
twin (kernels/jit.py), and its callers link the twin's LLVM module into their own: the
twin's own machine code is never run. Numba still generates it when the twin's library is
finalised (0.95 of the 18.35 s of a one-process cold compile, AMD EPYC) and stores it in the
cache. A library whose name ends in :data:`TWIN_SUFFIX` is finalised without being added to
the JIT, and cached with an empty object code beside its bitcode; loaded, it is kept for
linking only. Numba's ``set_env``, which writes a function's environment pointer into the
JIT's copy of its global, skips a global the JIT does not have (a twin's) instead of writing
to address 0. A twin's code runs only inside its callers, whose environment is theirs.
"""

from __future__ import annotations

import sys

import numpy as np
from llvmlite import binding as ll
from numba.core import codegen, environment, types
from numba.core.typing import typeof as numba_typeof
from numba.np import numpy_support

from .elf import elf_symbols

# ------------------------------------------------------------------ environments

_numba_rebuild_env = environment._rebuild_env


def _rebuild_env(modname, consts, env_name):
    """Numba's ``_rebuild_env`` without importing a module nobody has imported."""
    if modname is None or modname in sys.modules:
        return _numba_rebuild_env(modname, consts, env_name)
    env = environment.lookup_environment(env_name)
    if env is None:
        env = environment.Environment({"__name__": modname})
        env.consts[:] = consts
        env.env_name = env_name
        environment.Environment._memo[env_name] = env
    return env


# pickles under Numba's name: cache files written after this load without whitted too
_rebuild_env.__module__ = _numba_rebuild_env.__module__
_rebuild_env.__qualname__ = _numba_rebuild_env.__qualname__
environment._rebuild_env = _rebuild_env

# ------------------------------------------------------------------ bitcode on demand

def elf_defined_symbols(obj: bytes) -> set[str] | None:
    """The global and weak symbols an ELF64 little-endian object file defines: the names the
    JIT linker can resolve in it (kernels/elf.py). None when ``obj`` is not such a file."""
    symbols = elf_symbols(obj)
    return None if symbols is None else symbols[0]


_numba_unserialize = codegen.JITCodeLibrary._unserialize.__func__
_numba_module_for_linking = codegen.JITCodeLibrary._get_module_for_linking


def _unserialize(cls, codegen_, state):
    """``CPUCodeLibrary._unserialize`` for machine code (kind ``object``), leaving the
    bitcode unparsed, and for a twin's bitcode alone; anything else goes to Numba's."""
    name, kind, data = state
    if kind == "object" and data[0] == b"" and name.endswith(TWIN_SUFFIX):
        library = codegen_.create_library(name)
        library._unparsed_bitcode = data[1]
        library._finalized = True  # for linking only: nothing goes into the JIT
        return library
    defined = elf_defined_symbols(data[0]) if kind == "object" else None
    if not defined:
        return _numba_unserialize(cls, codegen_, state)
    object_code, shared_bitcode = data
    library = codegen_.create_library(name)
    assert isinstance(library, cls)
    library.enable_object_caching()
    library._set_compiled_object(object_code)
    library._unparsed_bitcode = shared_bitcode
    library.whitted_object_code = object_code  # for the native index (kernels/native.py)
    library._finalize_final_module()
    codegen_._engine._defined_symbols |= defined
    return library


def _get_module_for_linking(self):
    """Numba's, parsing the library's bitcode first if it was loaded without."""
    bitcode = getattr(self, "_unparsed_bitcode", None)
    if bitcode is not None and self._shared_module is None:
        self._shared_module = ll.parse_bitcode(bitcode)
        self._unparsed_bitcode = None
    return _numba_module_for_linking(self)


codegen.JITCodeLibrary._unserialize = classmethod(_unserialize)
codegen.JITCodeLibrary._get_module_for_linking = _get_module_for_linking

# ------------------------------------------------------------------ arrays typed

_numba_typeof_ndarray = numba_typeof._typeof_ndarray


def _typeof_ndarray(val, c):
    """Numba's ``_typeof_ndarray``, without its masked-array check for a plain ndarray."""
    if type(val) is not np.ndarray:
        return _numba_typeof_ndarray(val, c)
    try:
        dtype = numpy_support.from_dtype(val.dtype)
    except numba_typeof.errors.NumbaNotImplementedError:
        raise numba_typeof.errors.NumbaValueError(
            f"Unsupported array dtype: {val.dtype}") from None
    return types.Array(dtype, val.ndim, numpy_support.map_layout(val),
                       readonly=not val.flags.writeable)


numba_typeof.typeof_impl.register(np.ndarray)(_typeof_ndarray)

# ------------------------------------------------------------------ twins: no machine code

#: the end of a twin's name (kernels/jit.py ``_twin_function``), which Numba gives its library;
#: distinctive, since any Numba function in the process whose name ended so would be taken
#: for a twin and get no machine code
TWIN_SUFFIX = "__whitted_twin"

_numba_finalize_final_module = codegen.JITCodeLibrary._finalize_final_module
_numba_serialize_using_object_code = codegen.JITCodeLibrary.serialize_using_object_code


def _finalize_final_module(self):
    """Numba's, but a twin's module stays out of the JIT (no machine code)."""
    if not self.name.endswith(TWIN_SUFFIX):
        return _numba_finalize_final_module(self)
    self._finalize_dynamic_globals()
    self._verify_declare_only_symbols()
    self._finalized = True
    return None


def _serialize_using_object_code(self):
    """Numba's, with an empty object code for a twin (its bitcode is all its callers use)."""
    if not self.name.endswith(TWIN_SUFFIX):
        return _numba_serialize_using_object_code(self)
    self._ensure_finalized()
    return (self.name, "object", (b"", self._get_module_for_linking().as_bitcode()))


_numba_set_env = codegen.JITCPUCodegen.set_env


def _set_env(self, env_name, env):
    """Numba's, skipping an environment global the JIT does not hold (a twin's)."""
    if self._engine.get_global_value_address(env_name) == 0:
        return
    _numba_set_env(self, env_name, env)


codegen.JITCodeLibrary._finalize_final_module = _finalize_final_module
codegen.JITCodeLibrary.serialize_using_object_code = _serialize_using_object_code
codegen.JITCPUCodegen.set_env = _set_env
