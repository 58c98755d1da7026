"""How much more memory this process may take: the machine's free memory (Linux's
MemAvailable), and the process's own limits, which a shell's ``ulimit -v`` (RLIMIT_AS, the
address space) or ``ulimit -d`` (RLIMIT_DATA) set and which end an allocation beyond them
with an error however much the machine has free. Checks before heavy work (an image's
framebuffer, a photon map) compare their estimate with :func:`memory_room` and name
whichever bound is the tighter."""

from __future__ import annotations

from dataclasses import dataclass

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


def _free_memory() -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _status_kib(field: str) -> int | None:
    """A ``kB`` field of /proc/self/status (``VmSize``, ``VmData``), in bytes."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _limits() -> list[tuple[int, int, str]]:
    """(soft limit, bytes used against it, its words) of RLIMIT_AS and RLIMIT_DATA when set."""
    try:
        import resource
    except ImportError:  # not on POSIX
        return []
    out = []
    for name, field, words in (("RLIMIT_AS", "VmSize", "address-space limit"),
                               ("RLIMIT_DATA", "VmData", "data-size limit")):
        kind = getattr(resource, name, None)
        if kind is None:
            continue
        try:
            soft, _ = resource.getrlimit(kind)
        except (ValueError, OSError):
            continue
        if soft == resource.RLIM_INFINITY or soft < 0:
            continue
        used = _status_kib(field)
        out.append((soft, used or 0, words))
    return out


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
