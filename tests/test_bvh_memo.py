"""compile/reuse.py: the memo keeps the last ``keep`` trees and Embree rows, evicting the
oldest (an evicted Embree row's scenes are released, counted by a fake library), serves
equal inputs from memory as copies equal to fresh builds, and releases what it holds when
it goes."""

from __future__ import annotations

import gc

import numpy as np

from whitted.compile.bvh import build_bvh
from whitted.compile.reuse import BvhMemo, active_memo, cached_build_bvh


def _boxes(shift: float):
    lo = np.arange(12, dtype=np.float64).reshape(4, 3) + shift
    return lo, lo + 0.5


def test_trees_remembered_copied_and_evicted():
    memo = BvhMemo(keep=2)
    assert active_memo() is None
    with memo:
        assert active_memo() is memo
        first = cached_build_bvh(*_boxes(0.0))
        again = cached_build_bvh(*_boxes(0.0))
        fresh = build_bvh(*_boxes(0.0))
        for a, b, c in zip(first, again, fresh, strict=True):
            assert np.array_equal(a, b) and np.array_equal(a, c)
        assert first.prim_order is not again.prim_order  # a copy each time
        cached_build_bvh(*_boxes(1.0))
        cached_build_bvh(*_boxes(2.0))  # a third: the oldest (shift 0) goes
        cached_build_bvh(*_boxes(0.0))
    assert active_memo() is None
    assert (memo.built, memo.reused, memo.primitives_built, memo.primitives_reused) == (
        4, 1, 16, 4)


class _Library:
    def __init__(self):
        self.count: dict[int, int] = {}

    def retain(self, h):
        self.count[h] = self.count.get(h, 0) + 1

    def release(self, h):
        self.count[h] -= 1


def test_embree_rows_evicted_and_released_when_the_memo_goes():
    library = _Library()
    memo = BvhMemo(keep=1)

    def build(handles):
        def make():
            for h in set(handles) - {0}:
                library.count[h] = 1  # the reference the build made (the memo's)
            return handles
        return make

    assert memo.embree_row(b"a", library, build([5, 5, 0])) == [5, 5, 0]
    assert memo.embree_row(b"a", library, build([9, 9, 9])) == [5, 5, 0]  # remembered
    assert library.count == {5: 3}  # the memo's and two callers'
    memo.embree_row(b"b", library, build([7, 0, 7]))  # "a" evicted: the memo's one released
    assert library.count == {5: 2, 7: 2}
    assert (memo.built, memo.reused) == (2, 1)
    del memo
    gc.collect()
    assert library.count == {5: 2, 7: 1}  # what the memo held went with it
