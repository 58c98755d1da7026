"""dask.distributed, an optional dependency (``pip install 'whitted[farm]'``): imported here
only, so the rest of whitted starts without it and the farm says in one line what is missing."""

from __future__ import annotations

INSTALL_HINT = "the render farm needs dask.distributed: pip install 'whitted[farm]'"

try:
    import distributed
    from distributed import Client, Future, LocalCluster, WorkerPlugin, as_completed, get_worker
except ImportError as _missing:  # pragma: no cover - depends on the installed extras
    raise ImportError(f"{INSTALL_HINT} ({_missing})") from None

__all__ = ["Client", "Future", "LocalCluster", "WorkerPlugin", "as_completed", "distributed",
           "get_worker", "INSTALL_HINT"]
