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
done, and so never needs that memory back, can call :func:`keep_leftovers`: from then on, a
compile's leftovers are frozen (``gc.freeze``: never scanned, never freed) instead, while the
process's peak memory stays under a budget (:func:`leftover_budget`) and a quarter of the
machine's memory is still free; past either, they are collected as before. The whitted
command does that (not its editor); a library user's long-lived process keeps the default.
"""

from __future__ import annotations

import gc
import os
import sys

#: The most peak resident memory (bytes) under which a process that called
#: :func:`keep_leftovers` freezes a compile's leftovers instead of collecting them; an eighth of
#: the machine's memory where that is less (:func:`leftover_budget`). A cold compile of a
#: render kernel peaks at about 0.5 GB and leaves some 0.15 GB of garbage, so a process
#: freezes those of its first few compiles and collects the rest.
LEFTOVER_BUDGET = 1536 * 1024 * 1024

_keep = [False]  # whether this process keeps (freezes) a compile's leftovers


def keep_leftovers(keep: bool = True) -> None:
    """Freeze what each later compile leaves instead of collecting it, while the process's
    peak memory is under :func:`leftover_budget` (module docstring): for a process that ends
    once its work is done. ``keep=False`` restores the default."""
    _keep[0] = keep


def _peak_memory() -> int | None:
    """This process's peak resident memory in bytes, or None where it cannot be read."""
    try:
        import resource
    except ImportError:  # Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024  # bytes on macOS, KiB elsewhere


def leftover_budget() -> int:
    """The peak memory (bytes) under which a compile's leftovers are frozen: an eighth of
    the machine's memory, a quarter of the process's address-space or data limit (``ulimit
    -v``, ``ulimit -d``) where one is set, and at most :data:`LEFTOVER_BUDGET`."""
    try:
        import resource

        budget = min(LEFTOVER_BUDGET,
                     os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 8)
        for limit in (resource.RLIMIT_AS, resource.RLIMIT_DATA):
            soft = resource.getrlimit(limit)[0]
            if soft != resource.RLIM_INFINITY:
                budget = min(budget, soft // 4)
    except (ImportError, AttributeError, ValueError, OSError):  # not a POSIX system
        return 0
    return budget


def _memory_to_spare() -> bool:
    """Whether a quarter of the machine's memory is still free (where the system says: Linux),
    so that processes compiling side by side (``whitted warm``'s workers) stop freezing
    before they crowd the machine."""
    try:
        free = os.sysconf("SC_AVPHYS_PAGES")
        machine = os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):  # not said here (macOS, Windows)
        return True
    return free >= machine // 4


def _freeze_leftovers() -> bool:
    """Whether the leftovers of the compile that has just ended are to be frozen."""
    if not _keep[0]:
        return False
    peak = _peak_memory()
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
            self.paused = False
            try:
                if _freeze_leftovers():
                    gc.freeze()  # never scanned: everything so far, this compile's leftovers too
            finally:
                gc.enable()


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
