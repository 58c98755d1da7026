"""How much more memory this process may take: the machine's free memory (Linux's
MemAvailable), and the process's own limits, which a shell's ``ulimit -v`` (RLIMIT_AS, the
address space) or ``ulimit -d`` (RLIMIT_DATA) set and which end an allocation beyond them
with an error however much the machine has free. Checks before heavy work (an image's
framebuffer, a photon map) compare their estimate with :func:`memory_room` and name
whichever bound is the tighter."""

from __future__ import annotations

from dataclasses import dataclass

from ..machine import free_memory, memory_limits, status_bytes

__all__ = ["MemoryRoom", "memory_room"]


@dataclass(frozen=True)
class MemoryRoom:
    """``bytes`` the process may still allocate, and ``what`` bounds it, in words that end
    a sentence: ``"is free"`` or ``"is left under the process's address-space limit of 3.8
    GiB (ulimit -v)"``."""

    bytes: int
    what: str

    def describe(self) -> str:
        """``1.2 GiB is free`` and the like."""
        return f"{self.bytes / 2**30:.1f} GiB {self.what}"


_free_memory = free_memory  # module names of their own: tests stand in for them
_status_kib = status_bytes

#: the words for each limit of :func:`whitted.machine.memory_limits`
_LIMIT_WORDS = {"RLIMIT_AS": "address-space limit", "RLIMIT_DATA": "data-size limit"}


def _limits() -> list[tuple[int, int, str]]:
    """(soft limit, bytes used against it, its words) of RLIMIT_AS and RLIMIT_DATA when set."""
    return [(soft, used, _LIMIT_WORDS[name])
            for name, soft, used in memory_limits(lambda field: _status_kib(field))]


def memory_room() -> MemoryRoom | None:
    """The memory this process may still take (the tighter of the machine's free memory and
    its own limits), or None when neither is known."""
    free = _free_memory()
    best = MemoryRoom(free, "is free") if free is not None else None
    for soft, used, words in _limits():
        room = max(0, soft - used)
        if best is None or room < best.bytes:
            flag = "-v" if words.startswith("address") else "-d"
            best = MemoryRoom(room, f"is left under the process's {words} of "
                                    f"{soft / 2**30:.1f} GiB (ulimit {flag})")
    return best
