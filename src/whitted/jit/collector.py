"""Python's cyclic garbage collector paused while Numba compiles.

A compile makes millions of short-lived objects (Numba's IR, its types, llvmlite's IR
builders), and the collector, started every 700 allocations, runs hundreds of times per
compile; its full collections walk every object the process holds (Numba, NumPy, the
kernels loaded so far), and a cold compile of the default scene spent about 9 % of its CPU
in them (docs/performance.md, the collector round). Nearly all a compile makes is freed by
reference counting alone, so while Numba compiles the collector is paused: from the start of
the outermost compile (Numba's documented ``numba:compile`` event; Numba compiles one
function at a time, the callees nested inside their caller's event) to its end, exception or
not. It is left as it was when the program had turned it off itself, and the cycles a
compile leaves are collected by the collector's next run after it.

That run is not cheap: a cold compile of the default scene's render kernel leaves some
940,000 objects behind, 720,000 of them garbage cycles (Numba's IR, types and builders), and
the collection that finds them took 0.66-0.76 s, 4 % of the compile, on the development
machine (docs/performance.md, the leftovers round). A process that ends once its work is
done, and so never needs that memory back, can call :func:`keep_leftovers`: from then on, at
the end of each compile everything the process holds is frozen (``gc.freeze``: never
scanned, never freed), the compile's leftovers with it, while

- the process's peak memory is under its budget (:func:`leftover_budget`: an eighth of the
  machine's memory, shared among the processes that ``WHITTED_COMPILE_PROCESSES`` says
  compile side by side, as ``whitted warm``'s workers do, and at most
  :data:`LEFTOVER_BUDGET`),
- and a quarter of the machine's memory is still there for this process (Linux's
  MemAvailable, and what is left under a ``ulimit -v`` or ``ulimit -d``; the address space
  counts what Numba and LLVM reserve, several times what is resident, so under such a limit
  below about a quarter of the machine nothing is frozen). A container's own memory limit
  is not read: there the machine's figures are the host's, and the peak budget is what
  bounds the freezing.

Past either, compiles are collected as before. Frozen cycles keep their finalizers (a
``__del__``, a ``weakref.finalize``) from running until the process ends: nothing of
whitted's relies on them for more than memory (the cache's locks are released explicitly).
The whitted command calls it (not its editor), and so does its compile helper; a library
user's long-lived process keeps the default.
"""

from __future__ import annotations

import gc
import os

from ..machine import free_memory, memory_limits, peak_memory, total_memory

#: The most peak resident memory (bytes) under which a process that called
#: :func:`keep_leftovers` freezes a compile's leftovers instead of collecting them
#: (:func:`leftover_budget`). A cold compile of a render kernel peaks at about 0.5 GB and
#: leaves some 0.15 GB of garbage, so a process freezes those of its first few compiles and
#: collects the rest.
LEFTOVER_BUDGET = 1536 * 1024 * 1024

#: how many processes compile side by side on this machine (set by ``whitted warm`` for itself
#: and its workers): each freezes within its share of the budget
PROCESSES_ENV = "WHITTED_COMPILE_PROCESSES"

_keep = [False]  # whether this process keeps (freezes) a compile's leftovers


def keep_leftovers(keep: bool = True) -> None:
    """Freeze what each later compile leaves instead of collecting it, within the budget of
    the module docstring: for a process that ends once its work is done. ``keep=False``
    restores the default."""
    _keep[0] = keep


def _processes() -> int:
    """How many processes share the budget: ``WHITTED_COMPILE_PROCESSES`` (a whole number
    from 1), else 1."""
    try:
        count = int(os.environ.get(PROCESSES_ENV, "1"))
    except ValueError:
        return 1
    return max(1, count)


def leftover_budget() -> int:
    """The peak memory (bytes) under which a compile's leftovers are frozen: an eighth of
    the machine's memory divided among the processes compiling side by side, at most
    :data:`LEFTOVER_BUDGET`; 0 where the machine's memory is not known."""
    machine = total_memory()
    if not machine:
        return 0
    return min(LEFTOVER_BUDGET, machine // 8 // _processes())


def _memory_to_spare() -> bool:
    """Whether a quarter of the machine's memory is still there for this process: free on
    the machine (where the system says: Linux) and under the process's own limits."""
    machine = total_memory() or 0
    room = free_memory()
    for _, soft, used in memory_limits():
        room = soft - used if room is None else min(room, soft - used)
    return room is None or room >= machine // 4


def _freeze_leftovers() -> bool:
    """Whether the leftovers of the compile that has just ended are to be frozen."""
    if not _keep[0]:
        return False
    peak = peak_memory()
    return peak is not None and peak < leftover_budget() and _memory_to_spare()


class _Paused:
    """The state of the pause: how deep in nested compiles, and whether it turned the
    collector off (so that it turns it on again)."""

    def __init__(self) -> None:
        self.depth = 0
        self.paused = False

    def start(self) -> None:
        if self.depth == 0 and gc.isenabled():
            self.paused = True  # first: an interrupt between the two still ends in enable()
            gc.disable()
        self.depth += 1

    def end(self) -> None:
        self.depth = max(0, self.depth - 1)
        if self.depth == 0 and self.paused:
            try:
                try:
                    freeze = _freeze_leftovers()
                except Exception:  # never a reason to fail a compile: collected as before
                    freeze = False
                if freeze:
                    gc.freeze()  # never scanned: everything so far, this compile's leftovers too
            finally:
                gc.enable()
                self.paused = False


def collector_listener():
    """A listener of Numba's compile events (``numba.core.event``) that pauses the collector
    while the outermost compile runs (module docstring)."""
    from numba.core import event

    state = _Paused()

    class PauseCollector(event.Listener):
        def on_start(self, ev) -> None:
            state.start()

        def on_end(self, ev) -> None:
            state.end()

    return PauseCollector()
