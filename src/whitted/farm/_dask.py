"""dask.distributed, an optional dependency (``pip install 'whitted[farm]'``): imported here
only, so the rest of whitted starts without it and the farm says in one line what is missing."""

from __future__ import annotations

INSTALL_HINT = "install whitted[farm] (pip install 'whitted[farm]')"

try:
    import distributed
    from distributed import Client, Future, LocalCluster, WorkerPlugin, as_completed, get_worker
except ImportError as _missing:  # pragma: no cover - depends on the installed extras
    # worded as the other extras' lines (whitted stefan, whitted gui, MP4 films)
    _why = ("which is not installed" if _missing.name in ("distributed", "dask")
            else f"which cannot be imported ({_missing})")
    raise ImportError(f"the render farm needs dask.distributed, {_why}: {INSTALL_HINT}") \
        from None

__all__ = ["Client", "Future", "LocalCluster", "WorkerPlugin", "as_completed", "distributed",
           "get_worker", "INSTALL_HINT"]
