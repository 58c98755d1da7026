"""Watching a cluster while a farm job waits for its tasks: never wait forever.

The client waits for its tasks in short steps (:data:`POLL_SECONDS`) and between them looks
at the cluster (:class:`Watch`):

- **Workers that cannot render.** A worker whose renderer fingerprint differs from the
  client's, or that cannot load whitted at all, never offers the ``whitted`` resource, so it
  is never given a task (:mod:`.worker`); the watch names it in one line, once for each
  client (:func:`told_workers`). When no worker can render (none is ready or compiling
  kernels) for :data:`STALL_FLOOR` seconds, the job ends with one line saying why (every
  worker lost, or which ones run what).
- **Workers that no longer answer.** A Dask worker that fails to start (one without whitted
  cannot load the whitted plugin) closes itself, but may stay listed by the scheduler as
  ``closing`` without answering anything: every plugin registration (a broadcast to all
  listed workers) would then wait for it forever, and Dask drops it only after its
  ``worker-ttl`` (5 minutes by default). Such a worker (one that said it cannot load
  whitted and is closing, or one whose heartbeat stopped for the stall floor) is removed from
  the scheduler (``Client.retire_workers(..., close_workers=False, remove=True)``: nothing is
  asked of it) and named once (:meth:`Watch.drop_dead`).
- **Stalls.** A worker that holds whitted tasks is *stalled* when it has sent no heartbeat to
  the scheduler, or finished no frame or band, for the stall limit::

      limit = max(STALL_FLOOR, STALL_FACTOR * frames_per_task * frame_seconds)

  where ``frame_seconds`` is the longest time of a frame (band) finished so far in this job;
  for a worker that has finished none yet (its first task also compiles the scene's geometry
  and loads kernels), the progress limit is :data:`FIRST_TASK_LIMIT`; heartbeats always keep
  the floor. A stalled worker (hung, stopped with SIGSTOP, swapping) is excluded: its
  tasks are submitted again for the other ready workers only, and the first result of a
  task is the one kept. When no other worker is left, the job ends with one line.
- **Tasks left without a worker.** Dask gives a task that no worker could take when it was
  scheduled (every worker lost, or still readying) to the first worker that *joins* with the
  resource, but a worker offers it only once readied, after joining: such a task would wait
  forever beside an idle ready worker. A task that is on no worker for :data:`KICK_SECONDS`
  while a ready worker has a free thread is submitted again (the first result is kept).
- **The scheduler lost.** The client's connection gone for good ends the job with one line.

Every such ending is a :class:`~whitted.farm.errors.ClusterLost` (exit status 3):
what the farm had finished (frames written, bands) is kept.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
import weakref
from collections.abc import Callable, Iterable
from concurrent.futures import CancelledError
from typing import Any

from ._dask import Client, Future, distributed
from .errors import ClusterLost
from .worker import EVENT_TOPIC, PROGRESS_TOPIC, RESOURCE

POLL_SECONDS = 0.5
STALL_FLOOR = 30.0  # seconds: never less than this before a worker is called stalled
STALL_FACTOR = 10.0  # times the expected time of a task
FIRST_TASK_LIMIT = 600.0  # seconds without a finished frame, before a worker's first one
KICK_SECONDS = 5.0  # a task on no worker this long, beside an idle ready worker: again
#: a worker the scheduler lists with one of these statuses is going (one that failed to start
#: can stay "closing" for good, answering nothing)
GONE_STATUSES = frozenset({"closing", "closed", "failed"})

_told: weakref.WeakKeyDictionary[Any, set[str]] = weakref.WeakKeyDictionary()
_told_lock = threading.Lock()


def told_workers(client: Client) -> set[str]:
    """The workers already named to the user by jobs of ``client`` (each is named once,
    whichever job, or the readying of the cluster, found it first)."""
    with _told_lock:
        try:
            return _told.setdefault(client, set())
        except TypeError:  # not weakly referable: this job's own set
            return set()


def ready_workers(info: dict[str, Any]) -> list[str]:
    """The workers of ``client.scheduler_info()`` that the whitted plugin readied."""
    return [w for w, d in info.get("workers", {}).items()
            if d.get("resources", {}).get(RESOURCE, 0) > 0]


class Watch:
    """What the client knows of the workers while a job runs: their state from the whitted
    plugin's events, their progress, which ones are excluded as stalled."""

    def __init__(self, client: Client, note: Callable[[str], None] | None = None, *,
                 stall_floor: float = STALL_FLOOR) -> None:
        if not (isinstance(stall_floor, int | float) and math.isfinite(stall_floor)
                and stall_floor > 0):
            raise ValueError(f"stall_floor: {stall_floor!r} is not a positive number of "
                             "seconds")
        self.client = client
        self.note = note or (lambda line: None)
        self.stall_floor = stall_floor
        self.started = time.monotonic()
        self._lock = threading.Lock()
        self.states: dict[str, dict[str, Any]] = {}  # worker -> its last plugin event
        self.told = told_workers(client)  # workers named already (once each)
        self.dropped: dict[str, str] = {}  # workers removed from the scheduler, and why
        self.compiling_since: dict[str, tuple[float, float]] = {}  # worker -> (first, last)
        self.last_progress: dict[str, float] = {}  # worker -> when it last finished one
        self.seconds: list[float] = []  # each finished frame's (band's) time
        self.first_seen: dict[str, float] = {}
        self.heartbeats: dict[str, tuple[float, float]] = {}  # worker -> (last_seen, since)
        self.busy_since: dict[str, float] = {}  # worker -> when it got its newest task
        self.given: dict[tuple[str, str], float] = {}
        self.excluded: set[str] = set()
        self.no_worker_since: float | None = None
        self.unplaced: dict[str, float] = {}  # our task key -> since when it is on no worker
        self.frames_per_task = 1
        self.result_seconds = stall_floor  # the longest wait for a finished task's result
        # what happened before this job: the workers still listed that cannot render are named
        # as the job first looks at the cluster (once for this client)
        for _, message in client.get_events(EVENT_TOPIC):
            self.states[message.get("worker", "?")] = message
        client.subscribe_topic(EVENT_TOPIC, self._on_worker_event)
        client.subscribe_topic(PROGRESS_TOPIC, self._on_progress)

    def close(self) -> None:
        for topic in (EVENT_TOPIC, PROGRESS_TOPIC):
            with contextlib.suppress(Exception):  # a lost scheduler: nothing to unsubscribe
                self.client.unsubscribe_topic(topic)

    # ------------------------------------------------------------------ events (any thread)

    def _on_worker_event(self, event: tuple[float, dict[str, Any]]) -> None:
        _, message = event
        worker = message.get("worker", "?")
        with self._lock:
            before = self.states.get(worker) or {}
            self.states[worker] = message
        if message.get("status") == "missing":  # it cannot load whitted, and is going
            self.tell(worker, f"farm: {missing_reason(message)}: it gets no tasks")
        elif message.get("status") == "compiling":  # a cold worker: say so, in tenths
            now = time.monotonic()
            with self._lock:
                first, _ = self.compiling_since.get(worker, (now, now))
                self.compiling_since[worker] = (first, now)
            tenth = int(10 * message.get("fraction", 0.0))
            if before.get("status") != "compiling" or int(10 * before["fraction"]) != tenth:
                self.note(f"farm: worker {worker} is compiling the kernels (a cold cache: "
                          f"first run of this whitted there): {10 * tenth}%")

    def tell(self, worker: str, line: str) -> bool:
        """Say ``line`` about ``worker`` unless it was named already; whether it was said."""
        with self._lock:
            if worker in self.told:
                return False
            self.told.add(worker)
        self.note(line)
        return True

    def compiling(self, workers: Iterable[str], now: float) -> list[str]:
        """The workers compiling kernels now: they said so in the last stall floor, and began
        less than :data:`FIRST_TASK_LIMIT` ago (a compile that never ends is not waited
        for)."""
        with self._lock:
            states, since = dict(self.states), dict(self.compiling_since)
        busy = []
        for worker in workers:
            if (states.get(worker) or {}).get("status") != "compiling" or worker in self.excluded:
                continue
            first, last = since.get(worker, (-math.inf, -math.inf))
            if now - last <= self.stall_floor and now - first <= FIRST_TASK_LIMIT:
                busy.append(worker)
        return busy

    def _heartbeat_quiet(self, worker: str, identity: dict[str, Any], now: float) -> float:
        """Seconds since ``worker``'s heartbeat (its ``last_seen`` at the scheduler) last
        changed, as seen from here."""
        seen = identity.get("last_seen")
        last_seen, unchanged_since = self.heartbeats.get(worker, (None, now))
        if seen != last_seen:
            self.heartbeats[worker] = (seen, now)
            return 0.0
        return now - unchanged_since

    def dead_workers(self, workers: dict[str, Any], now: float, *,
                     silent: bool = False) -> dict[str, str]:
        """The listed workers that will answer nothing, and why: one that said it cannot
        load whitted and is closing (a worker that failed to start), one closing with no
        heartbeat for the stall floor, and with ``silent`` (while a registration waits for
        every worker) any whose heartbeat stopped for the stall floor."""
        with self._lock:
            states = dict(self.states)
        dead = {}
        for worker, identity in workers.items():
            quiet = self._heartbeat_quiet(worker, identity, now)
            state = states.get(worker) or {}
            going = identity.get("status") in GONE_STATUSES
            if going and state.get("status") == "missing":
                dead[worker] = missing_reason(state)
            elif (going or silent) and quiet > self.stall_floor:
                dead[worker] = (f"worker {worker} is {identity.get('status')} and has sent no "
                                f"heartbeat for {quiet:.0f} s")
        return dead

    def drop_dead(self, workers: dict[str, Any], now: float, *,
                  silent: bool = False) -> list[str]:
        """Remove :meth:`dead_workers` from the scheduler (nothing is asked of them: a
        registration or a job then waits for them no more) and name each once."""
        dead = {w: r for w, r in self.dead_workers(workers, now, silent=silent).items()
                if w not in self.dropped}
        if not dead:
            return []
        with contextlib.suppress(Exception):  # gone already, or the scheduler going: the same
            self.client.retire_workers(workers=list(dead), close_workers=False, remove=True)
        for worker, reason in dead.items():
            self.dropped[worker] = reason
            self.excluded.add(worker)
            self.tell(worker, f"farm: {reason}: it gets no tasks (it answers nothing: removed "
                      "from the scheduler)")
        return list(dead)

    def _on_progress(self, event: tuple[float, dict[str, Any]]) -> None:
        _, message = event
        with self._lock:
            self.last_progress[message["worker"]] = time.monotonic()
            if "seconds" in message:
                self.seconds.append(float(message["seconds"]))

    def result(self, future: Future) -> Any:
        """``future.result()``, or TimeoutError when the worker holding it does not hand it
        over within the floor of the stall limit (stopped, or gone without a word), or when
        its result was lost with its worker and the task is on no worker for
        :data:`KICK_SECONDS` (Dask would run it again only on a worker that joins)."""
        start = time.monotonic()
        orphan_since = None
        while True:
            try:
                return future.result(timeout=1.0)
            except TimeoutError:
                now = time.monotonic()
                if now - start > self.result_seconds:
                    raise
                key = future.key
                held = self.ask(self.client.who_has, [future]).get(key)
                running = any(str(key) in map(str, keys)
                              for keys in self.ask(self.client.processing).values())
                if held or running:
                    orphan_since = None
                    continue
                orphan_since = orphan_since or now
                if now - orphan_since > KICK_SECONDS:
                    raise

    def give_up_on(self, future: Future) -> list[str]:
        """Exclude the workers holding ``future``'s result (it did not come back)."""
        try:
            holders = list(self.ask(self.client.who_has, [future]).get(future.key, ()))
        except (ClusterLost, TimeoutError):
            holders = []
        for worker in holders:
            if worker not in self.excluded:
                self.excluded.add(worker)
                self.note(f"farm: worker {worker} did not hand over a finished task in "
                          f"{self.result_seconds:.0f} s; the task goes to other workers")
        return holders

    def record(self, seconds: Iterable[float]) -> None:
        """Frame (band) times learnt from results (events may come later than results)."""
        with self._lock:
            self.seconds.extend(seconds)

    # ------------------------------------------------------------------ waiting

    def wait(self, futures: Iterable[Future]) -> set[Future]:
        """The futures done after at most :data:`POLL_SECONDS` (maybe none)."""
        pending = list(futures)
        if not pending:
            return set()
        try:
            done, _ = distributed.wait(pending, timeout=POLL_SECONDS,
                                       return_when="FIRST_COMPLETED")
        except TimeoutError:
            return set()
        except (OSError, distributed.comm.CommClosedError, CancelledError) as exc:
            raise self.lost(exc if not isinstance(exc, CancelledError) else None) from None
        return set(done)

    def disconnected(self) -> bool:
        """Whether the client has lost its scheduler (Dask's calls then raise, among others,
        ``RuntimeError('ConnectionPool is closed')``)."""
        return self.client.status not in ("running", "newly-created")

    def ask(self, call, *args, **kwargs):
        """``call(*args, **kwargs)``, a question to the scheduler through the client;
        :class:`ClusterLost` when the connection is gone: a broken connection, or the client
        already closed by the loss (Dask's client then has no scheduler to ask, and its
        methods fail with AttributeError)."""
        try:
            return call(*args, **kwargs)
        except TimeoutError:  # a slow answer (an OSError too): the caller decides
            raise
        except (OSError, distributed.comm.CommClosedError) as exc:
            raise self.lost(exc) from None
        except AttributeError:
            if getattr(self.client, "scheduler", True) is None:
                raise self.lost() from None
            raise

    def lost(self, exc: BaseException | None = None) -> ClusterLost:
        """The one line for a scheduler gone: where it was, not Dask's text of the broken
        connection (its local and remote sockets, its stream's state)."""
        where = getattr(self.client.scheduler, "address", None) or "the scheduler"
        return ClusterLost(f"lost the connection to the scheduler at {where}")

    def ready_workers(self, info: dict[str, Any]) -> list[str]:
        return [w for w in ready_workers(info) if w not in self.excluded]

    def limit(self, worker: str | None = None) -> float:
        """The progress limit now, for ``worker`` (module docstring)."""
        with self._lock:
            seconds = list(self.seconds)
            started = worker is None or worker in self.last_progress
        if not seconds or not started:
            return max(self.stall_floor, FIRST_TASK_LIMIT)
        expected = self.frames_per_task * max(seconds)
        return max(self.stall_floor, STALL_FACTOR * expected)

    def check(self, keys: set[str]) -> tuple[list[str], set[str]]:
        """Look at the cluster: (the ready workers, our task keys to submit again because
        their worker is stalled or excluded). Raises :class:`ClusterLost`."""
        if self.client.status not in ("running", "connecting", "newly-created"):
            raise self.lost()
        try:
            info = self.ask(self.client.scheduler_info, n_workers=-1)
            processing = self.ask(self.client.processing)
        except TimeoutError as exc:
            raise self.lost(exc) from None
        now = time.monotonic()
        workers = info.get("workers", {})
        self.drop_dead(workers, now)
        workers = {w: d for w, d in workers.items() if w not in self.dropped}
        self._tell_unready(workers, now)
        ready = self.ready_workers(info)
        moved: set[str] = set()
        for worker, held in processing.items():
            ours = keys.intersection(str(k) for k in held)
            if not ours:
                self.busy_since.pop(worker, None)
                continue
            if worker in self.excluded:
                moved |= ours
                continue
            for key in ours:  # when the worker got each of its tasks (as seen from here)
                self.given.setdefault((worker, key), now)
            self.busy_since[worker] = max(self.given[(worker, k)] for k in ours)
            stalled = self._stalled(worker, workers.get(worker, {}), now)
            if stalled:
                self.excluded.add(worker)
                moved |= ours
                ready = [w for w in ready if w != worker]
                self.note(f"farm: worker {worker} {stalled}; its {len(ours)} task"
                          f"{'s' if len(ours) != 1 else ''} go to "
                          + (f"the other {len(ready)} worker{'s' if len(ready) != 1 else ''}"
                             if ready else "no other worker"))
        if ready:
            self.no_worker_since = None
            moved |= self._unplaced(keys, processing, ready, workers, now)
        else:
            self._no_worker(workers, now)
        return ready, moved

    def _unplaced(self, keys: set[str], processing: dict, ready: list[str],
                  workers: dict[str, Any], now: float) -> set[str]:
        """Our tasks on no worker for :data:`KICK_SECONDS` while a ready worker has a free
        thread (module docstring)."""
        placed = {str(k) for held in processing.values() for k in held}
        for key in list(self.unplaced):
            if key not in keys or key in placed:
                del self.unplaced[key]
        for key in keys - placed:
            self.unplaced.setdefault(key, now)
        free = any(len(processing.get(w, ())) < workers.get(w, {}).get("nthreads", 1)
                   for w in ready)
        if not free:
            return set()
        stuck = {k for k, since in self.unplaced.items() if now - since > KICK_SECONDS}
        for key in stuck:
            del self.unplaced[key]
        return stuck

    def _stalled(self, worker: str, identity: dict[str, Any], now: float) -> str:
        """Why ``worker`` (holding our tasks) is stalled, or ''."""
        since = self.busy_since.get(worker, now)
        quiet = self._heartbeat_quiet(worker, identity, now)
        if quiet > self.stall_floor:
            return f"sent no heartbeat for {quiet:.0f} s"
        with self._lock:
            progress = self.last_progress.get(worker)
        quiet = now - max(since, progress or since)
        limit = self.limit(worker)
        if quiet > limit:
            return (f"finished nothing for {quiet:.0f} s (the stall limit: {limit:.0f} s, "
                    "docs/farm.md)")
        return ""

    def _tell_unready(self, workers: dict[str, Any], now: float) -> None:
        """One line for each worker that will not render (once)."""
        with self._lock:
            states = dict(self.states)
        for worker, identity in workers.items():
            self.first_seen.setdefault(worker, now)
            if worker in self.told or identity.get("resources", {}).get(RESOURCE, 0) > 0:
                continue
            line = self.unready_reason(worker, states.get(worker), now)
            if line:
                self.tell(worker, f"farm: {line}: it gets no tasks")

    def unready_reason(self, worker: str, state: dict[str, Any] | None, now: float) -> str:
        if state is not None and state.get("status") == "missing":
            return missing_reason(state)
        if state is not None and state.get("status") == "mismatch":
            return mismatch_reason(worker, state)
        if state is None and now - self.first_seen.get(worker, now) > self.stall_floor:
            return (f"worker {worker} has not loaded whitted in {self.stall_floor:.0f} s "
                    "(is whitted[farm] installed there?)")
        return ""

    def _no_worker(self, workers: dict[str, Any], now: float) -> None:
        with self._lock:
            states = dict(self.states)
        if self.compiling(workers, now):
            self.no_worker_since = None
            return
        if self.no_worker_since is None:
            self.no_worker_since = now
            return
        if now - self.no_worker_since <= self.stall_floor:
            return
        if not workers and not self.dropped:
            raise ClusterLost(f"every worker was lost ({now - self.no_worker_since:.0f} s "
                              "without one)")
        reasons = list(self.dropped.values())
        for worker in workers:
            reason = (f"worker {worker} stalled" if worker in self.excluded
                      else self.unready_reason(worker, states.get(worker), now + 1e9)
                      or f"worker {worker} is not ready")
            reasons.append(reason)
        raise ClusterLost("no worker can render: " + "; ".join(reasons))


def mismatch_reason(worker: str, state: dict[str, Any]) -> str:
    """What a ``mismatch`` event of the whitted plugin says: the worker renders with another
    renderer than the client (:mod:`whitted.fingerprint`), and what differs."""
    from ..fingerprint import fingerprint_difference

    return (f"worker {worker} runs another renderer ("
            f"{fingerprint_difference(state.get('fingerprint', '?'), state.get('wanted', '?'))})")


def missing_reason(state: dict[str, Any]) -> str:
    """What a ``missing`` event of the probe (:mod:`.probe`) says: the worker (its address,
    and its name when it has another) cannot import whitted, and why."""
    worker = state.get("worker", "?")
    name = state.get("name")
    named = f" ({name})" if name and name != worker else ""
    return (f"worker {worker}{named} cannot load whitted ({state.get('error', '?')}; is "
            "whitted[farm] installed there?)")


def run_tasks(watch: Watch, tasks: dict[Future, Any],
              submit: Callable[[Any, list[str] | None], Future],
              on_done: Callable[[Future, Any], None], *,
              cancel: threading.Event | None = None,
              between: Callable[[], None] | None = None) -> bool:
    """Wait for every task of ``tasks`` (future -> its work item), calling ``on_done(future,
    item)`` for each as it finishes (``future.status`` "finished", "error" or "cancelled";
    it takes the result with ``watch.result(future)``). Work of a stalled worker, or whose
    finished result its worker does not hand over, is submitted again with ``submit(item,
    workers)``, the ready workers; ``between()`` runs after each step (it may add tasks).
    Returns False when ``cancel`` was set and tasks were left (those that had finished are
    handled first); on
    Ctrl-C (KeyboardInterrupt) the finished ones are handled too, then it is raised again."""

    def again(items: list[Any], ready: list[str]) -> None:
        # no ready worker now (a nanny restarting a killed one, a cold one joining): to any
        # worker; the watch ends the job once none has been there for the stall floor
        for item in items:
            tasks[submit(item, ready or None)] = item

    try:
        while tasks:
            if cancel is not None and cancel.is_set():
                _finish(watch, tasks, on_done)
                return not tasks  # stopped: False unless every task had finished
            for future in watch.wait(tasks):
                item = tasks.pop(future)
                try:
                    on_done(future, item)
                except TimeoutError:  # its worker holds the result and does not answer
                    watch.give_up_on(future)
                    again([item], watch.ready_workers(watch.client.scheduler_info(
                        n_workers=-1)))
            if between is not None:
                between()
            if not tasks:
                break
            ready, moved = watch.check({str(f.key) for f in tasks})
            stalled = [f for f in tasks if str(f.key) in moved]
            items = [tasks.pop(f) for f in stalled]
            for future in stalled:
                future.cancel()
            again(items, ready)
    except KeyboardInterrupt:
        _finish(watch, tasks, on_done)
        raise
    except (OSError, distributed.comm.CommClosedError, RuntimeError) as exc:
        if isinstance(exc, RuntimeError) and not watch.disconnected():
            raise
        raise watch.lost(exc) from None
    return True


def _finish(watch: Watch, tasks: dict[Future, Any],
            on_done: Callable[[Future, Any], None]) -> None:
    """Handle the tasks that already finished (their results are on the workers)."""
    watch.result_seconds = min(watch.result_seconds, 5.0)  # stopping: no long waits
    for future in [f for f in tasks if f.status == "finished"]:
        try:
            on_done(future, tasks.pop(future))
        except (OSError, distributed.comm.CommClosedError, TimeoutError):
            continue  # the cluster is going: what is written stays written


def cancel_quietly(client: Client, futures: Iterable[Future]) -> None:
    """Cancel ``futures``; a scheduler already gone has nothing left to cancel."""
    with contextlib.suppress(Exception):
        client.cancel(list(futures))
