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
"""

from __future__ import annotations

import gc


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
