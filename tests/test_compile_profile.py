"""benchmarks/compile_profile.py: compile times attributed from Numba's compile events."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numba
from numba.core import event

ROOT = Path(__file__).resolve().parents[1]


def _compile_profile():
    spec = importlib.util.spec_from_file_location(
        "compile_profile", ROOT / "benchmarks" / "compile_profile.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_callee_counts_in_its_callers_inclusive_time_only():
    @numba.njit(cache=False)
    def leaf(x):
        return x * 2.0 + 1.0

    @numba.njit(cache=False)
    def caller(x):
        return leaf(x) - leaf(x + 1.0)

    with event.install_recorder("numba:compile") as rec:
        assert caller(1.0) == (3.0 - 5.0)
    rows = _compile_profile().compile_times(rec.buffer)
    names = [row[0].rsplit(".", 1)[-1] for row in rows]
    assert names == ["leaf", "caller"]  # the callee's compile ends first, inside the caller's
    (_, leaf_sig, leaf_inc, leaf_exc), (_, caller_sig, caller_inc, caller_exc) = rows
    assert leaf_sig == caller_sig == "(float64,)"
    assert leaf_inc == leaf_exc > 0.0  # compiles nothing inside it
    assert caller_inc > leaf_inc
    assert abs(caller_exc - (caller_inc - leaf_inc)) < 1e-9
    # the exclusive times add up to the outermost compile's inclusive time
    assert abs(leaf_exc + caller_exc - caller_inc) < 1e-9
