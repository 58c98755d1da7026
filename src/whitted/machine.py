"""The machine whitted runs on, named beside every speed figure: the processor's model name
(as ``lscpu`` reports it) and the load average; and its memory: the machine's, what is free,
this process's own (its peak, what counts against its limits). It imports nothing of
whitted."""

from __future__ import annotations

import os
import platform
from pathlib import Path


def cpu_name() -> str:
    """The processor's model name (Linux: /proc/cpuinfo's "model name", which ``lscpu``
    shows), else the platform's word for it."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def load_average() -> float | None:
    """The one-minute load average (None where the system has none)."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def total_memory() -> int | None:
    """The machine's memory in bytes (None where the system does not say)."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def free_memory() -> int | None:
    """The memory the machine can still give, in bytes: Linux's MemAvailable (free memory and
    the caches it can drop; not MemFree, which a full page cache keeps low), else None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def status_bytes(field: str) -> int | None:
    """A ``kB`` field of this process's /proc/self/status (``VmSize``, ``VmData``, ``VmHWM``),
    in bytes; None where there is none (not Linux)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def memory_limits(status=status_bytes) -> list[tuple[str, int, int]]:
    """(name, soft limit, bytes used against it) of the process's RLIMIT_AS (``ulimit -v``,
    against VmSize) and RLIMIT_DATA (``ulimit -d``, against VmData), those that are set;
    ``status`` reads the use (:func:`status_bytes`)."""
    try:
        import resource
    except ImportError:  # not on POSIX
        return []
    out = []
    for name, field in (("RLIMIT_AS", "VmSize"), ("RLIMIT_DATA", "VmData")):
        kind = getattr(resource, name, None)
        if kind is None:
            continue
        try:
            soft, _ = resource.getrlimit(kind)
        except (ValueError, OSError):
            continue
        if soft == resource.RLIM_INFINITY or soft < 0:
            continue
        out.append((name, soft, status(field) or 0))
    return out


def peak_memory() -> int | None:
    """This process's peak resident memory in bytes: Linux's VmHWM (this program's own; the
    resource module's figure carries a parent's peak over into a program it starts), else
    the resource module's (bytes on macOS, KiB elsewhere), None where neither is known."""
    peak = status_bytes("VmHWM")
    if peak is not None:
        return peak
    try:
        import resource
    except ImportError:  # Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if platform.system() == "Darwin" else peak * 1024
