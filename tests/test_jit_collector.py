"""Python's cyclic garbage collector is paused while Numba compiles (jit/collector.py), and
only then: on again after the compile, whether it succeeded or failed, and left off where
the program had turned it off itself."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import pytest
from numba.core import event
from numba.core.errors import TypingError

from whitted.jit import load_numba
from whitted.jit.collector import _Paused

load_numba()

SRC = Path(__file__).resolve().parents[1] / "src"


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


def _run(script: str) -> dict:
    """``script`` run in a fresh interpreter (gc.freeze is for the whole process); the JSON
    object it prints last."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])])}
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.splitlines()[-1])


@pytest.mark.skipif(not hasattr(os, "sysconf") or sys.platform == "win32",
                    reason="the peak memory is read with the resource module")
def test_a_process_that_keeps_leftovers_freezes_them_within_its_budget():
    seen = _run("""
        import gc, json
        import numba
        from whitted.jit import load_numba
        from whitted.jit import collector

        load_numba()
        gc.enable()

        def compiled():  # a fresh function each time: a compile of its own
            @numba.njit
            def f(x):
                return x * 2.0 + 1.0
            assert f(1.0) == 3.0
            return gc.get_freeze_count()

        seen = {"before": gc.get_freeze_count(), "default": compiled()}
        collector.keep_leftovers()
        seen["kept"] = compiled()
        seen["on"] = gc.isenabled()
        seen["gen0"] = len(gc.get_objects(0))  # what the compile left is no longer there
        budget = collector.LEFTOVER_BUDGET
        collector.LEFTOVER_BUDGET = 0  # over budget: collected again
        seen["over"] = compiled() - seen["kept"]
        collector.LEFTOVER_BUDGET = budget
        spare = collector._memory_to_spare
        collector._memory_to_spare = lambda: False  # the machine short of memory: collected
        seen["crowded"] = compiled() - seen["kept"]
        collector._memory_to_spare = spare
        seen["spare"] = spare()
        collector.keep_leftovers(False)
        seen["off"] = compiled() - seen["kept"]
        seen["budget"] = collector.leftover_budget()
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (2**30, resource.getrlimit(resource.RLIMIT_AS)[1]))
        seen["limited"] = collector.leftover_budget()
        print(json.dumps(seen))
    """)
    assert seen["before"] == 0 and seen["default"] == 0  # by default nothing is frozen
    assert seen["kept"] > 10_000  # the compile's own objects among them (Numba's IR, types)
    assert seen["on"] and seen["gen0"] < 1_000
    # nothing more frozen (frozen objects freed by reference counting leave the count)
    assert seen["over"] <= 0 and seen["crowded"] <= 0 and seen["off"] <= 0
    machine = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    assert seen["budget"] == min(1536 * 1024 * 1024, machine // 8)
    assert seen["limited"] == 2**30 // 4  # under ulimit -v 1 GiB
    try:
        free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except ValueError:  # not said on this system: never a reason to collect
        assert seen["spare"]
    else:
        if abs(free - machine / 4) > machine / 16:  # not at the edge, where it could move
            assert seen["spare"] == (free >= machine / 4)


def test_the_command_keeps_leftovers_but_not_the_editor_nor_an_in_process_run():
    seen = _run("""
        import json, sys
        import whitted.cli.main as cli
        import importlib
        warm_up = importlib.import_module("whitted.render.warm_up")
        from whitted.jit import collector

        seen = {}
        for name, argv, own_process in (("version", ["--version"], True),
                                        ("gui", ["gui", "--help"], True),
                                        ("in-process", ["--version"], False)):
            collector.keep_leftovers(False)
            cli.EXIT_AT_ONCE_WHEN_ABANDONED = own_process
            sys.argv = ["whitted", *argv]
            try:
                cli.main()
            except SystemExit:
                pass
            seen[name] = collector._keep[0]
        collector.keep_leftovers(False)
        warm_up.precompile_for_render = lambda *a: seen.setdefault("helper", collector._keep[0])
        warm_up._helper_main(["plain"])  # the compile helper's process
        print(json.dumps(seen))
    """)
    assert seen == {"version": True, "gui": False, "in-process": False, "helper": True}
