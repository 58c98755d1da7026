"""The first plugin a worker runs for whitted, one that needs nothing of whitted there.

A worker without whitted (or with an install that fails to import) cannot unpickle the
:class:`~whitted.farm.worker.WhittedWorker` plugin: a worker that joins mid-job then closes
itself at once, and the client would never learn why. :class:`WhittedProbe` is pickled *by
value* (cloudpickle's ``register_pickle_by_value``), so any worker with dask.distributed can
load it; registered before ``WhittedWorker``, it runs first in every worker that joins (or
restarts), and:

- tries ``import whitted.farm.worker``; when that fails it logs a ``missing`` event on the
  topic :data:`EVENT_TOPIC` naming the worker (address and name) and the error, before the
  worker goes away: the client says so in one line (:mod:`whitted.farm.watch`);
- with ``quiet_interrupt`` (the local clusters the command line starts), ignores SIGINT in
  the worker process: a terminal's Ctrl-C reaches every process of its group, and the client
  stops its workers itself. A worker its nanny restarts after a kill is a new process that
  did not inherit the ignored signal of the first ones; this sets it again there.

This module imports nothing of whitted (it is loaded where whitted may be missing).
"""

from __future__ import annotations

import signal
import sys
import threading

import cloudpickle

from ._dask import WorkerPlugin

PROBE_NAME = "whitted-probe"
EVENT_TOPIC = "whitted-worker"  # the topic of the WhittedWorker plugin's events too


def ignore_interrupt() -> bool:
    """Ignore SIGINT in this process (from its main thread only); whether it was set."""
    if threading.current_thread() is not threading.main_thread():
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True


class WhittedProbe(WorkerPlugin):
    """Says on :data:`EVENT_TOPIC` when a worker cannot import whitted; with
    ``quiet_interrupt``, makes the worker ignore Ctrl-C's SIGINT."""

    name = PROBE_NAME

    def __init__(self, quiet_interrupt: bool = False) -> None:
        self.quiet_interrupt = quiet_interrupt

    def setup(self, worker) -> None:  # not a coroutine: it ends before the next plugin loads
        if self.quiet_interrupt:
            ignore_interrupt()
        try:
            import whitted.farm.worker  # noqa: F401 - what the WhittedWorker plugin needs
        except Exception as exc:  # noqa: BLE001 - anything that stops whitted loading here
            text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            error = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
            worker.log_event(EVENT_TOPIC, {
                "worker": worker.address, "name": str(worker.name), "status": "missing",
                "error": error, "python": sys.executable})


cloudpickle.register_pickle_by_value(sys.modules[__name__])
