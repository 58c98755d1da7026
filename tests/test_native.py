"""kernels/native.py: entry points called from their cached machine code without Numba."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numba import typeof

from whitted.kernels import native

REPO_ROOT = Path(__file__).resolve().parents[1]

Pair = namedtuple("Pair", "a b")


def _arrays():
    dtypes = st.sampled_from(["f8", "f4", "i4", "i8", "u1", "?", "c16", ">f8"])
    shapes = st.lists(st.integers(0, 4), min_size=0, max_size=3).map(tuple)

    def view(dtype, shape, how, writeable):
        a = np.zeros(shape, dtype)
        if how == "F":
            a = np.asfortranarray(a)
        elif how == "T" and a.ndim:
            a = a.T
        elif how == "step" and a.ndim:
            a = a[::2]
        elif how == "unaligned" and a.ndim:
            raw = np.zeros(a.nbytes + 1, np.uint8)[1:]
            a = raw.view(dtype).reshape(shape) if a.itemsize > 1 else a
        a.flags.writeable = writeable and a.flags.writeable
        return a

    return st.builds(view, dtypes, shapes, st.sampled_from(["C", "F", "T", "step",
                                                             "unaligned"]), st.booleans())


_scalars = st.one_of(st.booleans(), st.integers(-(2**63), 2**63 - 1), st.floats(),
                     st.complex_numbers(), st.none(),
                     st.builds(np.int32, st.integers(-5, 5)),
                     st.builds(np.float32, st.floats(-1, 1)),
                     st.builds(np.float64, st.floats(-1, 1)))
_values = st.recursive(st.one_of(_arrays(), _scalars),
                       lambda inner: st.one_of(st.tuples(inner, inner),
                                               st.builds(Pair, inner, inner)),
                       max_leaves=4)


def _numba_type(value):
    try:
        return typeof(value)
    except Exception:  # noqa: BLE001 - a value Numba cannot type
        return None


@given(_values, _values)
def test_argument_key_equal_only_where_numba_types_alike(a, b):
    """The safety of the whole module: two arguments with one key are typed alike by Numba
    (the wrapper compiled for one unpacks the other without checking)."""
    key_a, key_b = native.argument_key((a,)), native.argument_key((b,))
    if key_a is not None and key_a == key_b:
        assert _numba_type(a) == _numba_type(b), (a, b, key_a)
    if key_a is not None:
        assert native.argument_key((a,)) == key_a  # deterministic


def test_argument_key_refuses_kinds_it_does_not_know():
    for value in ([1.0], "text", np.ma.masked_array([1.0]), np.char.array(["a"]), 2**63,
                  object(), {"a": 1}, np.zeros(2, "V8")[0]):
        assert native.argument_key((value,)) is None, value
    assert native.argument_key((np.zeros(3), 1, 2.0, True)) == (
        ("a", "<f8", 1, "C", True, True), "int64", "float64", "bool")


def test_elf_undefined_symbols_of_a_non_elf_file_is_none():
    assert native.elf_undefined_symbols(b"not an object file") is None


def _run(script: str, cwd: Path, **settings: str) -> str:
    env = {**os.environ, **settings}
    env["PYTHONPATH"] = os.pathsep.join([str(REPO_ROOT / "src"), str(cwd),
                                         *filter(None, [env.get("PYTHONPATH")])])
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], cwd=cwd, env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    return result.stdout


PROBE = '''
from whitted.kernels.jit import builder, kernel


@builder
def total(a, scale):
    if scale < 0:
        raise ValueError("negative scale")
    s = 0.0
    for x in a:
        s += x
    return s * scale


@builder
def ramp(n):
    out = np.empty(n, np.int64)  # allocated by the Numba runtime
    for i in range(n):
        out[i] = i * i
    return out.sum()


@kernel(entry=True)
def fill(out, value):
    for i in range(out.shape[0]):
        out[i] = value
'''


def test_entry_points_run_from_the_index_in_a_fresh_process(tmp_path):
    """Called through Numba once (which records them), entry points run in the next process
    from the index, without importing Numba, with the same results; an exception inside one
    arrives as Numba raises it; a call the index cannot answer (another dtype, a damaged
    file) goes to Numba."""
    (tmp_path / "native_probe.py").write_text("import numpy as np\n" + PROBE)
    settings = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    first = _run("""
        import sys, numpy as np, native_probe as p
        out = np.zeros(4)
        p.fill(out, 2.5)
        print(p.total(np.arange(5.0), 2.0), p.ramp(5), out.tolist())
        assert "numba" in sys.modules  # compiled
    """, tmp_path, **settings)
    index = tmp_path / "cache" / "native"
    assert sorted(f.name.split("-")[0] for f in index.iterdir()) == [
        "native_probe.fill", "native_probe.ramp", "native_probe.total"]
    second = _run("""
        import sys, numpy as np, native_probe as p
        out = np.zeros(4)
        p.fill(out, 2.5)
        print(p.total(np.arange(5.0), 2.0), p.ramp(5), out.tolist())
        assert "numba" not in sys.modules, "Numba imported"
        try:
            p.total(np.arange(5.0), -1.0)
        except ValueError as e:
            assert str(e) == "negative scale", e
            assert "numba" not in sys.modules, "Numba imported to raise"
        else:
            raise AssertionError("no exception")
        assert p.total(np.arange(5, dtype=np.float32), 1.0) == 10.0  # another key: Numba
    """, tmp_path, **settings)
    assert first == second == "20.0 30 [2.5, 2.5, 2.5, 2.5]\n"
    for entry in index.iterdir():
        entry.write_bytes(entry.read_bytes()[:100])  # damaged
    damaged = _run("""
        import sys, numpy as np, native_probe as p
        print(p.total(np.arange(5.0), 2.0), p.ramp(5))
        assert "numba" in sys.modules
    """, tmp_path, **settings)
    assert damaged == "20.0 30\n"


def test_an_object_needing_a_symbol_nobody_has_is_not_loaded(tmp_path):
    """LLVM aborts the process on a symbol it cannot resolve: the engine checks them first."""
    _run("""
        from whitted.kernels import native
        engine = native._get_engine()
        assert engine.add({"undefined": ["PyTuple_Size", "whitted_no_such_symbol"],
                           "object": b"", "wrapper": "w", "environment": "e",
                           "module": "m"}) is None
        assert engine._resolve("PyTuple_Size") and engine._resolve("numba_do_raise")
        assert engine._resolve("NRT_MemInfo_alloc_aligned") and engine._resolve("sin")
    """, tmp_path)


@pytest.mark.parametrize("example", ["teapot_glass.toml", "textured.toml"])
def test_warm_render_needs_no_numba_and_gives_numbas_pixels(tmp_path, example):
    """A render of a scene seen before loads no Numba, and its image is Numba's, bit for bit
    (the OBJ reader, the BVH and normal builders, the light buffers and the render kernel
    all run from the index)."""
    scene = REPO_ROOT / "examples" / example
    script = f"""
        import sys, numpy as np, whitted
        image = whitted.render({str(scene)!r}, width=64, height=48, threads=2)
        np.save({{out!r}}, image.pixels)
        print("numba" in sys.modules)
    """
    cwd = REPO_ROOT / "examples"
    _run(script.replace("{out!r}", repr(str(tmp_path / "warm-up.npy"))), cwd)
    native_run = _run(script.replace("{out!r}", repr(str(tmp_path / "native.npy"))), cwd)
    numba_run = _run(script.replace("{out!r}", repr(str(tmp_path / "numba.npy"))), cwd,
                     WHITTED_NATIVE="0")
    assert native_run == "False\n" and numba_run == "True\n"
    np.testing.assert_array_equal(np.load(tmp_path / "native.npy"),
                                  np.load(tmp_path / "numba.npy"))


UNCACHEABLE = '''
import numpy as np
from whitted.kernels.jit import builder, kernel

BIG = np.arange(400000.0)  # over 1 MB: Numba bakes its address into the code


@builder
def pick(i):
    return BIG[i]


@kernel(entry=True, cache=False)
def plain(x):
    return x + 1.0


def make(k):
    @builder
    def shifted(x):
        return x + k
    return shifted


@builder
def edited(x):
    return x + 1.0
'''


def test_only_what_numba_would_cache_goes_into_the_index_and_edits_invalidate(tmp_path):
    """No entry for code with this process's addresses in it (a big global array), for a
    kernel compiled with ``cache=False``, or for a closure; an edit of the kernel's source
    makes the next process miss its old entry (and record the new code)."""
    (tmp_path / "uncacheable.py").write_text(UNCACHEABLE)
    settings = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    script = """
        import sys, warnings, uncacheable as u
        warnings.simplefilter("ignore")
        print(u.pick(123456), u.plain(1.0), u.make(1)(1.0), u.make(1000)(1.0), u.edited(1.0))
        print("numba" in sys.modules)
    """
    for _ in range(2):  # the second process finds only the entry it may use
        assert _run(script, tmp_path, **settings) == "123456.0 2.0 2.0 1001.0 2.0\nTrue\n"
    index = tmp_path / "cache" / "native"
    assert sorted(f.name.split("-")[0] for f in index.iterdir()) == ["uncacheable.edited"]
    source = (tmp_path / "uncacheable.py").read_text().replace("return x + 1.0\n'",
                                                               "return x + 1.0\n'")
    (tmp_path / "uncacheable.py").write_text(
        source.replace("def edited(x):\n    return x + 1.0", "def edited(x):\n    return x + 5.0"))
    edited = """
        import sys, uncacheable as u
        print(u.edited(1.0), "numba" in sys.modules)
    """
    assert _run(edited, tmp_path, **settings) == "6.0 True\n"  # missed: through Numba
    assert _run(edited, tmp_path, **settings) == "6.0 False\n"  # the new code's entry


def test_numba_shares_the_extension_modules_loaded_for_the_native_path(tmp_path):
    """The native path loads Numba's extension modules under Numba's names: Numba imported
    afterwards uses the same ones (its runtime is initialised once: statistics enabled before
    a native call stay enabled), and a native call after Numba is imported still works."""
    (tmp_path / "native_probe.py").write_text("import numpy as np\n" + PROBE)
    settings = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    _run("import numpy as np, native_probe as p; p.ramp(5)", tmp_path, **settings)
    assert _run("""
        import sys, numpy as np, native_probe as p
        assert p.ramp(5) == 30 and "numba" not in sys.modules
        helper = sys.modules["numba._helperlib"]
        import numba
        from numba.core.runtime import _nrt_python
        from numba import _helperlib
        assert _helperlib is helper
        _nrt_python.memsys_enable_stats()
        assert p.ramp(6) == 55  # another key: compiled by Numba now
        assert p.ramp(5) == 30 and _nrt_python.memsys_stats_enabled()
        print(_nrt_python.memsys_get_stats_alloc() > 0)
    """, tmp_path, **settings) == "True\n"
