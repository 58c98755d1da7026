"""Getting a Dask client for the command line: ``--cluster local:N`` starts a LocalCluster of N
worker processes on this machine (loopback only), ``--scheduler tcp://HOST:PORT`` joins an
existing cluster whose workers have whitted installed. Either way the workers are readied by
the :class:`~whitted.farm.worker.WhittedWorker` plugin before they take work."""

from __future__ import annotations

import importlib.util
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..errors import WhittedError
from ..render.api import available_threads
from ._dask import Client, LocalCluster
from .worker import WhittedWorker


class FarmError(WhittedError):
    """A farm option or cluster the user gave cannot be used (one line, exit status 2)."""


def parse_cluster(spec: str) -> int:
    """Worker processes of a ``local:N`` (or ``local``: one per core) specification."""
    kind, _, count = spec.partition(":")
    if kind != "local":
        raise FarmError(f"--cluster: unknown cluster {spec!r} (use local:N, or --scheduler "
                        "tcp://HOST:PORT for a running one)")
    if not count:
        return available_threads()
    if not count.isdigit() or int(count) < 1:
        raise FarmError(f"--cluster: {spec!r}: N must be a whole number of workers, 1 or more")
    return int(count)


def check_farm_options(cluster: str | None, scheduler: str | None) -> None:
    """FarmError unless exactly one of the two is given (and a cluster spec is valid)."""
    if (cluster is None) == (scheduler is None):
        raise FarmError("give one of --cluster local:N and --scheduler tcp://HOST:PORT")
    if cluster is not None:
        parse_cluster(cluster)


def has_dashboard() -> bool:
    """Dask's dashboard needs bokeh (optional): without it there is simply none."""
    return importlib.util.find_spec("bokeh") is not None


def dashboard_link(client: Client) -> str | None:
    if not has_dashboard():
        return None
    try:
        info = client.scheduler_info()
    except OSError:
        return None
    return client.dashboard_link if "dashboard" in info.get("services", {}) else None


def local_cluster(workers: int, threads: int) -> LocalCluster:
    """``workers`` processes of one Dask thread each, each rendering with ``threads`` lanes."""
    return LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address="127.0.0.1:0",  # a free port (a page only with bokeh)
        env={"NUMBA_NUM_THREADS": str(threads)},
    )


@contextmanager
def farm_client(cluster: str | None = None, scheduler: str | None = None, *,
                threads: int | None = None, warm: bool = True,
                note: Callable[[str], None] | None = None) -> Iterator[Client]:
    """A client of a new local cluster (``cluster="local:N"``) or of the scheduler at
    ``scheduler``, with every worker readied (kernels warm, ``threads`` render threads each:
    by default the cores shared out among a local cluster's workers, one on a remote one)."""
    check_farm_options(cluster, scheduler)
    owned = None
    if cluster is not None:
        workers = parse_cluster(cluster)
        threads = threads or max(1, available_threads() // workers)
        owned = local_cluster(workers, threads)
        client = Client(owned)
    else:
        threads = threads or 1
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise FarmError(f"--scheduler {scheduler}: cannot reach the scheduler ({exc})"
                            ) from None
    try:
        link = dashboard_link(client)
        if note is not None:
            n = len(client.scheduler_info().get("workers", {}))
            note(f"farm: {n} worker{'s' if n != 1 else ''} at {client.scheduler.address}, "
                 f"{threads} render thread{'s' if threads != 1 else ''} each"
                 + (f"; dashboard {link}" if link else ""))
        client.register_plugin(WhittedWorker(threads=threads, warm=warm))
        yield client
    finally:
        client.close()
        if owned is not None:
            owned.close()
