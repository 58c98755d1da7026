"""The BVH builder (compile/bvh.py, Numba ``@builder`` kernels) run as plain Python
(``NUMBA_DISABLE_JIT=1``, in a fresh process) gives the compiled builder's tree, node for node,
on boxes that reach its corners: many identical boxes (every centroid the same: the range is
halved), flat boxes on a line, and a random cloud. Each tree holds every primitive once,
leaves within the cap, and every node's box holds its primitives."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from whitted.compile.bvh import build_bvh, bvh_stats
from whitted.jit.python_twins import compiled

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.python_kernels

CASES = """
import numpy as np
rng = np.random.default_rng(7)
lo = rng.random((120, 3)) * 10
cases = {
    "identical": (np.zeros((40, 3)), np.ones((40, 3))),
    "flat_line": (np.stack([np.arange(30.0), np.zeros(30), np.zeros(30)], 1),
                  np.stack([np.arange(30.0) + 0.5, np.zeros(30), np.zeros(30)], 1)),
    "cloud": (lo, lo + rng.random((120, 3))),
}
"""

SCRIPT = CASES + """
import json
from whitted.compile.bvh import build_bvh
out = {}
for name, (a, b) in cases.items():
    bvh = build_bvh(a, b, max_leaf_size=4, n_bins=8)
    out[name] = {k: getattr(bvh, k).tolist() for k in bvh._fields}
print(json.dumps(out))
"""


def _check_tree(bvh, lo, hi, cap: int) -> None:
    assert sorted(bvh.prim_order.tolist()) == list(range(len(lo)))
    leaves = bvh.node_count > 0
    assert bvh.node_count[leaves].max() <= cap
    for node in np.flatnonzero(leaves):
        first, count = bvh.node_offset[node], bvh.node_count[node]
        prims = bvh.prim_order[first:first + count]
        assert (bvh.node_min[node] <= lo[prims].min(axis=0)).all()
        assert (bvh.node_max[node] >= hi[prims].max(axis=0)).all()


def test_the_builder_as_plain_python_gives_the_compiled_tree():
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NUMBA_DISABLE_JIT="1")
    run = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=600, check=True)
    plain = json.loads(run.stdout.strip().splitlines()[-1])
    scope: dict = {}
    exec(CASES, scope)
    for name, (lo, hi) in scope["cases"].items():
        with compiled():  # these inputs are small enough for the twins otherwise
            bvh = build_bvh(lo, hi, max_leaf_size=4, n_bins=8)
        for field in bvh._fields:
            assert getattr(bvh, field).tolist() == plain[name][field], (name, field)
        _check_tree(bvh, lo, hi, 16)
    # 40 boxes in one place: no split can separate them, so the range is halved down to the
    # leaf cap (16): 40 -> 20 + 20 -> 10 + 10 + 10 + 10
    same = build_bvh(*scope["cases"]["identical"], max_leaf_size=4, n_bins=8)
    assert bvh_stats(same) == {"nodes": 7, "leaves": 4, "max_depth": 2,
                               "mean_leaf_size": 10.0, "max_leaf_size": 10}


def test_the_builders_arguments():
    empty = build_bvh(np.zeros(0), np.zeros(0))
    assert empty.node_min.shape == (0, 3) and empty.prim_order.shape == (0,)
    assert bvh_stats(empty)["nodes"] == 0
    for args, message in (
        ((np.zeros((2, 3)), np.zeros((3, 3))), "bounds must be two (N, 3) arrays of the same "
                                                "shape, got (2, 3) and (3, 3)"),
        ((np.zeros((1, 3)), np.zeros((1, 3)), 0), "max_leaf_size must be >= 1, got 0"),
        ((np.zeros((1, 3)), np.zeros((1, 3)), 4, 1), "n_bins must be >= 2, got 1"),
        ((np.zeros((1, 3)), np.full((1, 3), np.inf)),
         "primitive bounds must be finite (keep unbounded primitives apart)"),
        ((np.ones((1, 3)), np.zeros((1, 3))),
         "primitive bounds must have bounds_min <= bounds_max on every axis"),
    ):
        with pytest.raises(ValueError) as info:
            build_bvh(*args)
        assert str(info.value) == message
