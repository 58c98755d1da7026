"""The interpreter's frame-stack chunks reused instead of mapped again (jit/frame_stack.py).

Page faults are counted, not time: a chunk that is mapped again faults its first page in
again, one fault per call that crosses the chunk's boundary; a chunk kept for reuse does not.
"""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from whitted.jit import frame_stack

SRC = str(Path(__file__).resolve().parents[1] / "src")
CALLS = 50

# A call made CALLS times at every depth of a fine ladder (frames 8 bytes apart), and the
# largest number of page faults one such loop made: CALLS where a call's frame just misses
# the current chunk and the interpreter maps a new one each time.
PROBE = textwrap.dedent("""
    import resource, sys

    def faults():
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt

    def leaf():
        return 1

    PADS = []
    for k in range(16):
        names = "".join(f"    v{i} = {i}\\n" for i in range(k))
        ns = {"leaf": leaf}
        exec(f"def pad(m):\\n{names}    for _ in range(m):\\n        leaf()\\n", ns)
        PADS.append(ns["pad"])

    def down(d, k, m):
        if d:
            return down(d - 1, k, m)
        before = faults()
        PADS[k](m)
        return faults() - before

    if sys.argv[1:] == ["install"]:
        from whitted.jit import frame_stack
        assert frame_stack.install()
    print(max(down(d, k, CALLS) for d in range(160) for k in range(16)))
""").replace("CALLS", str(CALLS))

needs_it = pytest.mark.skipif(not frame_stack.supported(),
                              reason="this interpreter's frame stack is left as it is")
jit_on = pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"),
                            reason="nothing is compiled with NUMBA_DISABLE_JIT")


def run(code: str, *args: str) -> str:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (SRC, os.environ.get("PYTHONPATH")) if p))
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


@needs_it
@pytest.mark.skipif(sys.platform == "win32", reason="page faults counted with resource")
def test_a_call_at_a_chunk_boundary_faults_every_time_without_it_and_not_with_it():
    without = int(run(PROBE))
    if without < CALLS:
        pytest.skip(f"this interpreter keeps a chunk itself ({without} faults in {CALLS} calls)")
    assert int(run(PROBE, "install")) <= CALLS // 10


@needs_it
@jit_on
def test_installed_at_the_first_compile_not_before():
    code = textwrap.dedent("""
        from whitted.jit import frame_stack, kernel, load_numba

        @kernel(entry=True, cache=False)
        def plus_one(x):
            return x + 1

        load_numba()
        print(frame_stack.installed())
        print(plus_one(41))
        print(frame_stack.installed())
    """)
    assert run(code).split() == ["False", "42", "True"]


@needs_it
def test_a_chunk_freed_is_the_next_one_handed_out():
    """The chunk kept for reuse: freed, then asked for again, the same memory, where the
    interpreter would have unmapped it and mapped another (the gain; docs/performance.md)."""
    code = textwrap.dedent("""
        import ctypes
        from whitted.jit import frame_stack as fs

        assert fs.install()
        current = fs.current_allocator()
        alloc = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)(
            current.alloc)
        free = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)(
            current.free)
        a = alloc(current.ctx, fs.CHUNK)  # takes the kept chunk, if one is kept
        free(current.ctx, a, fs.CHUNK)  # kept
        b = alloc(current.ctx, fs.CHUNK)
        free(current.ctx, b, fs.CHUNK)
        c = alloc(current.ctx, fs.CHUNK + 8)  # another size: not the kept one
        free(current.ctx, c, fs.CHUNK + 8)
        print(a == b, c != b)
    """)
    assert run(code).split() == ["True", "True"]


@needs_it
def test_blocks_from_before_and_after_are_freed_by_the_allocator_they_came_from():
    # chunks mapped by the interpreter before it is installed (deep in a recursion) and
    # taken from it after, freed in any order, from several threads at once, with the
    # pymalloc arenas (1 MiB, the interpreter's) taken and freed meanwhile
    code = textwrap.dedent("""
        import sys, threading
        from whitted.jit import frame_stack

        sys.setrecursionlimit(20_000)

        def deep(n, at=-1):
            if n == at:
                assert frame_stack.install()
            return 0 if n == 0 else 1 + deep(n - 1, at)

        assert deep(3000, at=1500) == 3000
        for _ in range(3):
            assert deep(3000) == 3000
            junk = [[i] * 8 for i in range(300_000)]
            del junk
        results = []

        def work():
            results.append(sum(deep(2500) for _ in range(5)))

        threads = [threading.Thread(target=work) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        print(results)
    """)
    assert run(code).strip() == "[12500, 12500, 12500, 12500]"


@needs_it
@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([1, 64, 4096, 16384, 16385, 65536, 65537,
                                           1 << 20]),
                          st.booleans()), min_size=1, max_size=12))
def test_every_block_is_whole_writable_and_tagged_by_where_it_came_from(requests):
    """The installed functions called directly: a block of up to 64 KiB is this allocator's
    (16 bytes past a page boundary), a larger one the interpreter's (page-aligned); every
    byte can be written; freed early or late, in any order."""
    assert frame_stack.install()
    current = frame_stack.current_allocator()
    alloc = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)(current.alloc)
    free = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p,
                            ctypes.c_size_t)(current.free)
    live = []
    for size, free_now in requests:
        p = alloc(current.ctx, size)
        assert p
        assert p % 4096 == (frame_stack.TAG if size <= frame_stack.SMALL else 0)
        ctypes.memset(p, 0xA5, size)
        assert ctypes.string_at(p + size - 1, 1) == b"\xa5"
        if free_now:
            free(current.ctx, p, size)
        else:
            live.append((p, size))
    for p, size in reversed(live):
        free(current.ctx, p, size)


def test_left_out_where_it_could_be_wrong_or_useless(monkeypatch):
    import sysconfig
    import types

    monkeypatch.setattr(sys, "implementation", types.SimpleNamespace(name="pypy"))
    assert not frame_stack.supported()
    monkeypatch.undo()
    real = sysconfig.get_config_var
    monkeypatch.setattr(sysconfig, "get_config_var",
                        lambda name: 1 if name == "Py_GIL_DISABLED" else real(name))
    assert not frame_stack.supported()
    monkeypatch.undo()
    monkeypatch.setattr(sys, "platform", "aix")
    assert not frame_stack.supported()
