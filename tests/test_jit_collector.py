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
from hypothesis import given, settings
from hypothesis import strategies as st
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


def test_a_process_that_keeps_leftovers_freezes_them_within_its_budget():
    seen = _run("""
        import gc, json
        import numba
        from whitted.jit import load_numba
        from whitted.jit import collector

        load_numba()
        gc.enable()
        # the machine's state out of it: an 8-GiB machine, room to spare, a small peak (each
        # case sets its own)
        collector.total_memory = lambda: 8 * 2**30
        collector._memory_to_spare = lambda: True
        collector.peak_memory = lambda: 0

        def compiled():  # a fresh function each time: a compile of its own
            @numba.njit
            def f(x):
                return x * 2.0 + 1.0
            assert f(1.0) == 3.0
            return gc.get_freeze_count()

        def more():  # how many more objects are frozen after a compile
            before = gc.get_freeze_count()
            return compiled() - before

        seen = {"before": gc.get_freeze_count(), "default": compiled()}
        held = len(gc.get_objects()) + gc.get_freeze_count()  # what the process holds
        collector.keep_leftovers()
        seen["kept"] = compiled() - held  # more than it held before: the compile's own
        seen["on"] = gc.isenabled()
        seen["gen0"] = len(gc.get_objects(0))  # what the compile left is no longer there
        collector.peak_memory = lambda: collector.leftover_budget()  # at the budget
        seen["over"] = more()
        collector.peak_memory = lambda: None  # not known: collected
        seen["unknown"] = more()
        collector.peak_memory = lambda: 0
        collector._memory_to_spare = lambda: False  # the machine short of memory
        seen["crowded"] = more()
        def broken():
            raise RuntimeError("a reader failed")
        collector._memory_to_spare = broken  # never fails the compile, collected
        seen["broken"] = more()
        seen["broken_on"] = gc.isenabled()
        collector._memory_to_spare = lambda: True
        collector.keep_leftovers(False)
        seen["off"] = more()
        print(json.dumps(seen))
    """)
    assert seen["before"] == 0 and seen["default"] == 0  # by default nothing is frozen
    assert seen["kept"] > 1_000  # the compile's own objects (Numba's IR, types) frozen
    assert seen["on"] and seen["gen0"] < 1_000
    # each later compile freezes nothing more: the count stays or falls (frozen objects
    # freed by reference counting leave it)
    for case in ("over", "unknown", "crowded", "broken", "off"):
        assert seen[case] <= 0, case
    assert seen["broken_on"]


def test_the_budget_is_an_eighth_of_the_machine_shared_among_the_processes(monkeypatch):
    from whitted.jit import collector
    from whitted.machine import total_memory

    machine = total_memory()
    if machine is None:
        pytest.skip("the system does not say how much memory the machine has")
    monkeypatch.delenv(collector.PROCESSES_ENV, raising=False)
    assert collector.leftover_budget() == min(1536 * 2**20, machine // 8)
    monkeypatch.setenv(collector.PROCESSES_ENV, "3")
    assert collector.leftover_budget() == min(1536 * 2**20, machine // 24)
    monkeypatch.setattr(collector, "total_memory", lambda: 8 * 2**30)
    assert collector.leftover_budget() == 2**30 // 3  # an 8-GiB machine, three processes
    monkeypatch.setattr(collector, "total_memory", lambda: None)
    assert collector.leftover_budget() == 0  # not known: nothing frozen


@settings(max_examples=60, deadline=None)
@given(st.one_of(st.text(max_size=12), st.integers(min_value=-10**30, max_value=10**30)
                 .map(str), st.sampled_from(["0", "-1", "nan", "inf", "1e300", " 2 ", ""])))
def test_any_process_count_gives_a_budget_within_bounds(value):
    from whitted.jit import collector

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(collector, "total_memory", lambda: 16 * 2**30)
        if "\x00" in value:
            return  # no environment variable can hold it
        patch.setenv(collector.PROCESSES_ENV, value)
        budget = collector.leftover_budget()
    assert 0 <= budget <= collector.LEFTOVER_BUDGET
    try:
        count = int(value)
    except ValueError:
        count = 1
    assert budget == min(collector.LEFTOVER_BUDGET, 2 * 2**30 // max(1, count))


def test_memory_to_spare_is_a_quarter_of_the_machine_free_and_under_the_limits(monkeypatch):
    from whitted.jit import collector

    gib = 2**30
    monkeypatch.setattr(collector, "total_memory", lambda: 16 * gib)
    monkeypatch.setattr(collector, "memory_limits", lambda: [])
    monkeypatch.setattr(collector, "free_memory", lambda: None)
    assert collector._memory_to_spare()  # not said (macOS, Windows): the budget alone
    monkeypatch.setattr(collector, "free_memory", lambda: 4 * gib)
    assert collector._memory_to_spare()
    monkeypatch.setattr(collector, "free_memory", lambda: 4 * gib - 1)
    assert not collector._memory_to_spare()
    # ulimit -v 6 GiB with 3 GiB of address space in use: 3 GiB left, under a quarter
    monkeypatch.setattr(collector, "free_memory", lambda: 12 * gib)
    monkeypatch.setattr(collector, "memory_limits", lambda: [("RLIMIT_AS", 6 * gib, 3 * gib)])
    assert not collector._memory_to_spare()
    monkeypatch.setattr(collector, "memory_limits", lambda: [("RLIMIT_AS", 9 * gib, 3 * gib)])
    assert collector._memory_to_spare()
    monkeypatch.setattr(collector, "free_memory", lambda: None)  # the limit alone
    monkeypatch.setattr(collector, "memory_limits", lambda: [("RLIMIT_DATA", 5 * gib, 2 * gib)])
    assert not collector._memory_to_spare()


def test_the_memory_readers_read_this_process_and_this_machine():
    seen = _run("""
        import json, sys
        from whitted import machine
        if sys.platform.startswith("linux"):
            import resource
            hard = resource.getrlimit(resource.RLIMIT_AS)[1]
            soft = 2**40 if hard == resource.RLIM_INFINITY else min(2**40, hard)
            resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        rss = machine.status_bytes("VmRSS")  # first: the peak read after it is no less
        print(json.dumps({"peak": machine.peak_memory(), "free": machine.free_memory(),
                          "total": machine.total_memory(),
                          "limits": machine.memory_limits(), "rss": rss}))
    """)
    assert seen["total"] is None or seen["total"] > 2**28
    if sys.platform.startswith("linux"):
        assert 2**20 < seen["peak"] < 2**30  # a fresh interpreter with whitted's machine module
        assert seen["peak"] >= seen["rss"]
        assert 0 < seen["free"] <= seen["total"]
        [(name, soft, used)] = [entry for entry in seen["limits"] if entry[0] == "RLIMIT_AS"]
        assert 2**20 < used < soft  # VmSize counted against it
    else:
        assert seen["peak"] is None or seen["peak"] > 2**20


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's VmHWM")
def test_the_peak_is_the_programs_own_not_its_parents():
    """Linux carries a parent's peak over into the resource module's figure of a program it
    starts; the peak whitted reads is the program's own."""
    seen = _run("""
        import json, os, resource, subprocess, sys
        block = bytearray(256 * 2**20)
        block[::4096] = bytes(len(block) // 4096)  # every page written: resident
        child = subprocess.run([sys.executable, "-c", "import json, resource; "
                                "from whitted.machine import peak_memory; "
                                "print(json.dumps([peak_memory(), "
                                "resource.getrusage(resource.RUSAGE_SELF).ru_maxrss]))"],
                               capture_output=True, text=True, env=dict(os.environ),
                               check=True)
        peak, maxrss = json.loads(child.stdout)
        print(json.dumps({"peak": peak, "maxrss": maxrss * 1024}))
    """)
    assert seen["peak"] < 128 * 2**20
    assert seen["maxrss"] > 256 * 2**20  # what the resource module would have said


def test_the_peak_without_proc_comes_from_the_resource_module(monkeypatch):
    resource = pytest.importorskip("resource")
    from whitted import machine

    monkeypatch.setattr(machine, "status_bytes", lambda field: None)
    usage = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # bytes on macOS, else KiB
    peak = machine.peak_memory()
    assert peak >= (usage if sys.platform == "darwin" else usage * 1024)
    assert peak > 2**20  # bytes: this test process holds more than a megabyte


def test_the_command_keeps_leftovers_but_not_the_editor_nor_an_in_process_run():
    seen = _run("""
        import json, sys
        import whitted.cli.main as cli
        import whitted.program as program  # the whole program: the editor's command too
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
                program.main()
            except SystemExit:
                pass
            seen[name] = collector._keep[0]
        collector.keep_leftovers(False)
        warm_up.precompile_for_render = lambda *a: seen.setdefault("helper", collector._keep[0])
        warm_up._helper_main(["plain"])  # the compile helper's process
        print(json.dumps(seen))
    """)
    assert seen == {"version": True, "gui": False, "in-process": False, "helper": True}
