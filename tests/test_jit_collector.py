"""Python's cyclic garbage collector is paused while Numba compiles (jit/collector.py), and
only then: on again after the compile, whether it succeeded or failed, and left off where
the program had turned it off itself."""

from __future__ import annotations

import gc

import numba
import pytest
from numba.core import event
from numba.core.errors import TypingError

from whitted.jit import load_numba
from whitted.jit.collector import _Paused

load_numba()


class _Seen(event.Listener):
    """Whether the collector was on as each compile started and ended (registered after
    whitted's listener, which Numba tells first)."""

    def __init__(self) -> None:
        self.at_start: list[bool] = []
        self.at_end: list[bool] = []

    def on_start(self, ev) -> None:
        self.at_start.append(gc.isenabled())

    def on_end(self, ev) -> None:
        self.at_end.append(gc.isenabled())


@pytest.fixture
def seen():
    listener = _Seen()
    event.register("numba:compile", listener)
    try:
        yield listener
    finally:
        event.unregister("numba:compile", listener)


@pytest.fixture
def collector_on():
    was = gc.isenabled()
    gc.enable()
    yield
    if not was:
        gc.disable()


def test_the_collector_is_off_during_nested_compiles_and_on_after(seen, collector_on):
    @numba.njit
    def leaf(x):
        return x * 2.0 + 1.0

    @numba.njit
    def caller(x):
        return leaf(x) - 3.0

    assert caller(2.0) == 2.0
    assert seen.at_start == [False, False]  # the caller's compile, then its callee's inside
    # the callee ends inside the caller's compile; at the caller's end whitted's listener,
    # registered first, has turned the collector on again
    assert seen.at_end == [False, True]
    assert gc.isenabled()


def test_a_failed_compile_turns_the_collector_on_again(seen, collector_on):
    @numba.njit
    def wrong(x):
        return x + "text"

    with pytest.raises(TypingError):
        wrong(1.0)
    assert seen.at_start == [False]
    assert gc.isenabled()


def test_a_collector_the_program_turned_off_stays_off(seen, collector_on):
    @numba.njit
    def plain(x):
        return x - 1.0

    gc.disable()
    try:
        assert plain(3.0) == 2.0
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_the_pause_counts_nesting():
    paused = _Paused()
    was = gc.isenabled()
    gc.enable()
    try:
        paused.start()
        paused.start()
        assert not gc.isenabled()
        paused.end()
        assert not gc.isenabled()  # still inside the outer compile
        paused.end()
        assert gc.isenabled()
        paused.end()  # an unmatched end (a listener registered mid-compile) changes nothing
        assert gc.isenabled() and paused.depth == 0
    finally:
        if not was:
            gc.disable()
