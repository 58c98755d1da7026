"""Getting a Dask client for the command line: ``--cluster local:N`` starts a LocalCluster of N
worker processes on this machine (loopback only), ``--scheduler tcp://HOST:PORT`` joins an
existing cluster whose workers have whitted installed. Either way the workers are readied by
the :class:`~whitted.farm.worker.WhittedWorker` plugin before they take work, and a worker
that cannot be (another whitted, none at all) is named in one line and given no task."""

from __future__ import annotations

import importlib.util
import logging
import signal
import socket
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from urllib.parse import urlsplit

from ..render.api import available_threads
from ._dask import Client, LocalCluster
from .errors import ClusterLost, FarmError
from .probe import WhittedProbe
from .security import client_security, connect
from .watch import (
    FIRST_TASK_LIMIT,
    POLL_SECONDS,
    STALL_FLOOR,
    Watch,
    mismatch_reason,
    missing_reason,
)
from .worker import WhittedWorker

#: seconds to wait for a scheduler that does not answer (a refused connection fails at once)
CONNECT_SECONDS = 10

__all__ = ["ClusterLost", "FarmError", "check_farm_options", "farm_client", "local_cluster",
           "parse_cluster", "reach_scheduler"]


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


def reach_scheduler(address: str, timeout: float = CONNECT_SECONDS) -> None:
    """Open (and close) a TCP connection to the scheduler at ``tcp://HOST:PORT``: a refused
    connection or an unknown host fails at once, with one line (Dask would retry for its
    whole timeout)."""
    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme not in ("tcp", "tls") or not parts.hostname or port is None:
        raise FarmError(f"--scheduler {address}: not an address tcp://HOST:PORT")
    try:
        with socket.create_connection((parts.hostname, port), timeout=timeout):
            pass
    except TimeoutError:
        raise ClusterLost(f"--scheduler {address}: no answer in {timeout:.0f} s (is a "
                          "scheduler running there, and the port open?)") from None
    except OSError as exc:
        raise ClusterLost(f"--scheduler {address}: cannot reach the scheduler "
                          f"({exc.strerror or exc})") from None


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


def local_cluster(workers: int, threads: int, dask_threads: int = 1) -> LocalCluster:
    """``workers`` processes of ``dask_threads`` Dask threads each (1: the command line's), each
    task rendering with ``threads`` lanes. They ignore Ctrl-C's SIGINT (the client stops them
    itself: a terminal's Ctrl-C reaches every process of its group, and each printed its
    traceback): it is ignored here while they start, and a process started with SIGINT
    ignored keeps it so (Python and asyncio then install no handler of their own). A worker
    its nanny starts again after a kill is spawned by the nanny, in this process, once the
    caller's handler is back: :func:`farm_client` registers the
    :class:`~whitted.farm.probe.WhittedProbe` with ``quiet_interrupt``, which ignores SIGINT
    in every worker that (re)joins. They log only what is critical: a worker stopped while it
    readies or renders (the client closing the cluster after a Ctrl-C) logs its cancelled
    work as errors, and the client says what happened in its own lines."""
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        return LocalCluster(
            n_workers=workers, threads_per_worker=dask_threads, processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",  # a free port (a page only with bokeh)
            env={"NUMBA_NUM_THREADS": str(threads)},
            silence_logs=logging.CRITICAL,  # not a stopped worker's cancelled work
        )
    finally:
        if main:  # the caller's handler (the interrupt guard's) again
            signal.signal(signal.SIGINT, previous)


def ready_cluster(client: Client, plugin: WhittedWorker,
                  note: Callable[[str], None] | None = None,
                  probe: WhittedProbe | None = None, *,
                  stall_floor: float = STALL_FLOOR) -> list[str]:
    """Register ``probe`` (default :class:`WhittedProbe`: a worker that cannot import
    whitted, now or when it joins later, says so before it goes) and ``plugin`` (every worker
    readied: kernels loaded, or compiled with progress told through ``note``); name each
    worker that cannot render in one line, once. Returns the ready workers; raises
    :class:`ClusterLost` when there is none.

    Never waits forever: a registration waits for every worker the scheduler lists, so a
    listed worker that answers nothing (one that failed to start and stays ``closing``, one
    stopped) is removed from the scheduler (:meth:`Watch.drop_dead`); a worker still
    readying after ``stall_floor`` seconds while none compiles is left to join the job later
    (its tasks come once it offers the ``whitted`` resource), or, when no worker is ready, the
    readying ends with one line."""
    watch = Watch(client, note, stall_floor=stall_floor)  # cold workers' progress, mismatches
    try:
        failures = _register(client, [probe or WhittedProbe(), plugin], watch)
        try:
            info = client.scheduler_info(n_workers=-1)
        except (OSError, TimeoutError) as exc:
            raise watch.lost(exc) from None
        workers = {w: d for w, d in info.get("workers", {}).items() if w not in watch.dropped}
        ready = watch.ready_workers(info)
        states = _states(client, [w for w in workers if w not in ready])
    finally:
        watch.close()
    failure = failures[0] if failures else None
    why = (str(failure) if type(failure) is Exception else f"{type(failure).__name__}: "
           f"{failure}") if failure is not None else ""
    reasons = dict(watch.dropped)
    for worker in workers:
        if worker in ready:
            continue
        state = states.get(worker) or {}
        if state.get("status") == "missing":
            reasons[worker] = missing_reason(state)
        elif state.get("status") == "mismatch":
            reasons[worker] = mismatch_reason(worker, state)
        elif state.get("status") == "compiling" or (not state and not why):
            reasons[worker] = (f"worker {worker} has not finished loading whitted in "
                               f"{stall_floor:.0f} s")
        else:
            reasons[worker] = f"worker {worker} cannot load whitted ({why or 'no answer'})"
    if not ready:
        raise ClusterLost("no worker can render: "
                          + ("; ".join(reasons.values()) or "no workers"))
    for worker, reason in reasons.items():
        watch.tell(worker, f"farm: {reason}: it gets no tasks")
    return ready


def _register(client: Client, plugins: list, watch: Watch) -> list[BaseException]:
    """Register ``plugins`` in turn (on a thread); meanwhile drop the listed workers that
    answer nothing, and stop waiting once the stall floor has passed with a ready worker
    and none compiling (or :data:`~whitted.farm.watch.FIRST_TASK_LIMIT` in any case). The
    registrations' errors (a worker that cannot load a plugin)."""
    failures: list[BaseException] = []
    done = threading.Event()

    def register() -> None:
        try:
            for plugin in plugins:
                try:
                    client.register_plugin(plugin)
                except Exception as exc:  # noqa: BLE001 - a worker that cannot load it
                    failures.append(exc)
        finally:
            done.set()

    threading.Thread(target=register, name="whitted-register", daemon=True).start()
    start = time.monotonic()
    while not done.wait(POLL_SECONDS):
        now = time.monotonic()
        try:
            info = client.scheduler_info(n_workers=-1)
        except (OSError, TimeoutError) as exc:
            raise watch.lost(exc) from None
        workers = info.get("workers", {})
        watch.drop_dead(workers, now, silent=True)
        waited = now - start
        if waited > FIRST_TASK_LIMIT or (waited > watch.stall_floor and watch.ready_workers(
                info) and not watch.compiling(workers, now)):
            break
    if watch.disconnected():
        raise watch.lost()
    # a broken connection to a worker removed meanwhile is no reason to name the others by
    return [f for f in failures if not isinstance(f, OSError | TimeoutError)]


def _states(client: Client, workers: list[str], wait: float = 2.0) -> dict[str, dict]:
    """The plugin's last event of each worker (a mismatch comes as an event: waited for a
    moment, it may follow the plugin's answer)."""
    from .worker import EVENT_TOPIC

    end = time.monotonic() + wait
    while True:
        states = {m.get("worker"): m for _, m in client.get_events(EVENT_TOPIC)}
        if all(w in states for w in workers) or time.monotonic() > end:
            return states
        time.sleep(0.05)


@contextmanager
def farm_client(cluster: str | None = None, scheduler: str | None = None, *,
                threads: int | None = None, warm: bool = True,
                note: Callable[[str], None] | None = None,
                status: Callable[[str], None] | None = None) -> Iterator[Client]:
    """A client of a new local cluster (``cluster="local:N"``) or of the scheduler at
    ``scheduler``, with every worker readied (kernels warm, ``threads`` render threads each:
    by default the cores shared out among a local cluster's workers, one on a remote one).
    Workers that cannot render are named through ``note`` and get no tasks; the cluster's
    size and address are told through ``status`` (default: ``note``)."""
    check_farm_options(cluster, scheduler)
    owned = None
    if cluster is not None:
        workers = parse_cluster(cluster)
        threads = threads or max(1, available_threads() // workers)
        owned = local_cluster(workers, threads)
        client = Client(owned)
    else:
        threads = threads or 1
        client_security(scheduler)  # TLS settings checked before any connection
        reach_scheduler(scheduler)
        client = connect(scheduler, CONNECT_SECONDS)
    try:
        link = dashboard_link(client)
        status = status or note
        if status is not None:
            info = client.scheduler_info(n_workers=-1).get("workers", {})
            n = len(info)
            total = sum(w.get("nthreads", 1) for w in info.values())
            status(f"farm: {n} worker{'s' if n != 1 else ''} ({total} Dask thread"
                 f"{'s' if total != 1 else ''}) at {client.scheduler.address}, "
                 f"{threads} render thread{'s' if threads != 1 else ''} a task"
                 + (f"; dashboard {link}" if link else ""))
        ready_cluster(client, WhittedWorker(threads=threads, warm=warm), note,
                      WhittedProbe(quiet_interrupt=owned is not None))
        yield client
    finally:
        _close_quietly(client, owned)


def _close_quietly(client: Client, owned: LocalCluster | None) -> None:
    """Close the client (and the cluster it started) without Dask's tracebacks: a scheduler
    already gone is no error at this point."""
    import logging

    quiet = [logging.getLogger(name) for name in ("distributed", "tornado", "asyncio")]
    levels = [log.level for log in quiet]
    for log in quiet:
        log.setLevel(logging.CRITICAL)
    try:
        client.close(timeout=5)
        if owned is not None:
            owned.close(timeout=10)
    except Exception:  # noqa: BLE001 - closing what is already gone
        pass
    finally:
        for log, level in zip(quiet, levels, strict=True):
            log.setLevel(level)
