"""The interpreter's frame stack kept from mapping and unmapping memory while Numba compiles.

CPython 3.11 and 3.12 (and 3.13 and 3.14 before their later releases) keep a thread's Python
frames in 16-KiB chunks. A chunk comes from the interpreter's arena allocator (``mmap``) when
a frame does not fit in the chunk before it, and goes back (``munmap``) as soon as the frame
at its start returns. So a call made again and again at a depth where its frame just misses
the current chunk maps a chunk, faults its pages in and unmaps it every time. Numba's
compiler, deep and recursive, did that about 180,000 times in the default scene's first
compile (``strace``): some 2 s of system time, and 5-10 % of the compile's CPU in all
(docs/performance.md, the frame-stack round).

:func:`install` puts two small functions in front of the interpreter's arena allocator,
through Python's documented ``PyObject_GetArenaAllocator``/``PyObject_SetArenaAllocator``. They
are compiled from a few lines of LLVM IR with llvmlite's public binding API:

- a request of one standard chunk (16 KiB) takes the chunk kept for reuse, if one is kept
  (later CPython releases keep one chunk themselves);
- other requests of up to 64 KiB come from ``PyMem_RawMalloc``. Their address is 16 bytes
  past a page boundary, which tells them apart from the interpreter's own blocks: those are
  always page-aligned (``mmap``, or ``VirtualAlloc`` on Windows);
- anything else goes to the interpreter's allocator, as before.

A freed block of the interpreter's own goes back to it. A freed standard chunk is kept when
none is (an atomic exchange, so the functions need no lock), and any other is given back to
``PyMem_RawFree``. The pymalloc arenas (1 MiB) are not touched.

It is installed at the start of the first compile in a process (a listener of Numba's
``numba:compile`` event, registered with the kernels' other listeners): a process that only
loads kernels from the cache pays nothing. It stays installed, so blocks taken before and
after it are each freed by the allocator they came from, and its code is never released
(llvmlite's engine detached). An install that fails is not tried again, and changes
nothing. It is left out where the
interpreter's blocks might not be page-aligned, and where it could not help: not CPython, a
free-threaded build, a 32-bit one, or another platform than Linux, macOS and Windows.
"""

from __future__ import annotations

import contextlib
import ctypes
import sys
import sysconfig
import threading

#: the interpreter's frame-stack chunk (CPython's ``_PY_DATA_STACK_CHUNK_SIZE``)
CHUNK = 16 * 1024
#: requests of at most this many bytes are served here (module docstring)
SMALL = 64 * 1024
#: where this allocator's blocks start, past a page boundary (the interpreter's never do)
TAG = 16

_IR = r"""
@old_alloc = global i8* null
@old_free = global i8* null
@old_ctx = global i8* null
@raw_malloc = global i8* null
@raw_free = global i8* null
@spare = global i64 0

define i8* @whitted_arena_alloc(i8* %ctx, i64 %size) {
entry:
  %standard = icmp eq i64 %size, CHUNK
  br i1 %standard, label %take_spare, label %check_small
take_spare:
  %spare_i = atomicrmw xchg i64* @spare, i64 0 seq_cst
  %has_spare = icmp ne i64 %spare_i, 0
  br i1 %has_spare, label %give_spare, label %check_small
give_spare:
  %spare = inttoptr i64 %spare_i to i8*
  ret i8* %spare
check_small:
  %small = icmp ule i64 %size, SMALL
  br i1 %small, label %from_raw, label %from_old
from_raw:
  %total = add i64 %size, PADDED
  %malloc_p = load i8*, i8** @raw_malloc
  %malloc = bitcast i8* %malloc_p to i8* (i64)*
  %block = call i8* %malloc(i64 %total)
  %failed = icmp eq i8* %block, null
  br i1 %failed, label %no_memory, label %tag
no_memory:
  ret i8* null
tag:
  %block_i = ptrtoint i8* %block to i64
  %up = add i64 %block_i, 4095
  %page = and i64 %up, -4096
  %result_i = add i64 %page, TAG
  %slot_i = add i64 %page, 8
  %slot = inttoptr i64 %slot_i to i8**
  store i8* %block, i8** %slot
  %result = inttoptr i64 %result_i to i8*
  ret i8* %result
from_old:
  %alloc_p = load i8*, i8** @old_alloc
  %alloc = bitcast i8* %alloc_p to i8* (i8*, i64)*
  %old_ctx = load i8*, i8** @old_ctx
  %old = call i8* %alloc(i8* %old_ctx, i64 %size)
  ret i8* %old
}

define void @whitted_arena_free(i8* %ctx, i8* %p, i64 %size) {
entry:
  %p_i = ptrtoint i8* %p to i64
  %offset = and i64 %p_i, 4095
  %mine = icmp eq i64 %offset, TAG
  br i1 %mine, label %check_standard, label %to_old
check_standard:
  %standard = icmp eq i64 %size, CHUNK
  br i1 %standard, label %keep, label %to_raw
keep:
  %kept = cmpxchg i64* @spare, i64 0, i64 %p_i seq_cst seq_cst
  %was_empty = extractvalue { i64, i1 } %kept, 1
  br i1 %was_empty, label %done, label %to_raw
to_raw:
  %slot_i = sub i64 %p_i, 8
  %slot = inttoptr i64 %slot_i to i8**
  %block = load i8*, i8** %slot
  %free_p = load i8*, i8** @raw_free
  %free = bitcast i8* %free_p to void (i8*)*
  call void %free(i8* %block)
  br label %done
to_old:
  %old_free_p = load i8*, i8** @old_free
  %old_free = bitcast i8* %old_free_p to void (i8*, i8*, i64)*
  %old_ctx = load i8*, i8** @old_ctx
  call void %old_free(i8* %old_ctx, i8* %p, i64 %size)
  br label %done
done:
  ret void
}
""".replace("PADDED", str(4096 + TAG)).replace("CHUNK", str(CHUNK)).replace(
    "SMALL", str(SMALL)).replace("TAG", str(TAG))


class _ArenaAllocator(ctypes.Structure):
    """CPython's ``PyObjectArenaAllocator``: ``ctx``, ``alloc(ctx, size)``,
    ``free(ctx, ptr, size)``."""

    _fields_ = [("ctx", ctypes.c_void_p), ("alloc", ctypes.c_void_p),
                ("free", ctypes.c_void_p)]


_lock = threading.Lock()
_installed = False
_tried = False


def supported() -> bool:
    """Whether this interpreter keeps its frames in chunks from a page-aligned arena
    allocator, with one global interpreter lock, on a 64-bit platform (module docstring)."""
    return (sys.implementation.name == "cpython"
            and (3, 11) <= sys.version_info[:2] < (3, 15)
            and not sysconfig.get_config_var("Py_GIL_DISABLED")
            and ctypes.sizeof(ctypes.c_void_p) == 8
            and (sys.platform.startswith("linux") or sys.platform in ("darwin", "win32")))


def installed() -> bool:
    return _installed


def _api(name: str, *argtypes):
    function = getattr(ctypes.pythonapi, name)
    function.argtypes = list(argtypes)
    function.restype = None
    return function


def current_allocator() -> _ArenaAllocator:
    """The interpreter's arena allocator as it is now (``PyObject_GetArenaAllocator``)."""
    allocator = _ArenaAllocator()
    _api("PyObject_GetArenaAllocator", ctypes.POINTER(_ArenaAllocator))(ctypes.byref(allocator))
    return allocator


def install() -> bool:
    """Put the allocator in front of the interpreter's (once per process). Returns whether it
    is installed. Where it is not supported, or llvmlite cannot compile it, nothing changes,
    and a failed install is not tried again."""
    global _installed, _tried
    with _lock:
        if _tried or not supported():
            return _installed
        _tried = True
        try:
            new = _compiled_allocator()
            put = _api("PyObject_SetArenaAllocator", ctypes.POINTER(_ArenaAllocator))
        except Exception:  # noqa: BLE001 - an optimisation only: the interpreter's stays
            return False
        put(ctypes.byref(new))
        _installed = True
        return True


def _compiled_allocator() -> _ArenaAllocator:
    """The two functions compiled, pointed at the interpreter's allocator and at
    ``PyMem_RawMalloc``/``PyMem_RawFree``: the allocator to install."""
    import llvmlite.binding as llvm

    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    module = llvm.parse_assembly(_IR)
    module.verify()
    machine = llvm.Target.from_default_triple().create_target_machine()
    engine = llvm.create_mcjit_compiler(module, machine)  # owns the module and the machine
    engine.finalize_object()
    alloc = engine.get_function_address("whitted_arena_alloc")
    free = engine.get_function_address("whitted_arena_free")
    if not alloc or not free:
        raise RuntimeError("llvmlite compiled no arena functions")
    old = current_allocator()
    for name, value in (("old_alloc", old.alloc), ("old_free", old.free),
                        ("old_ctx", old.ctx),
                        ("raw_malloc", ctypes.cast(ctypes.pythonapi.PyMem_RawMalloc,
                                                   ctypes.c_void_p).value),
                        ("raw_free", ctypes.cast(ctypes.pythonapi.PyMem_RawFree,
                                                 ctypes.c_void_p).value)):
        ctypes.c_void_p.from_address(engine.get_global_value_address(name)).value = value
    engine.detach()  # never disposed: the interpreter calls this code as long as it runs
    return _ArenaAllocator(None, alloc, free)


def frame_stack_listener():
    """A listener of Numba's compile events that installs the allocator at the start of the
    first compile (module docstring)."""
    from numba.core import event

    class InstallAtFirstCompile(event.Listener):
        def on_start(self, ev) -> None:
            if not _tried:
                with contextlib.suppress(Exception):  # never a reason for a compile to fail
                    install()

        def on_end(self, ev) -> None:
            pass

    return InstallAtFirstCompile()
