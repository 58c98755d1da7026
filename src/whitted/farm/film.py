"""The render farm's executor of a film: the missing frames as Dask tasks, each frame written
here as it arrives.

A film is one pipeline (:func:`whitted.animation.film.render_film`: plan, the missing frames,
render, assemble, resume); :class:`DaskFrames` is the executor that renders the missing frames
on a cluster. Every frame's still and the hash its PNG records are worked out on the client
(:func:`~whitted.animation.film.missing_frames`, where the files have the paths the hash
names). First one frame a task for each Dask thread of the cluster, then, once a frame's time
is measured, runs of consecutive frames sized by :func:`chunk_size`. Tasks are ``pure=False``
with ``retries`` and ask for the ``whitted`` resource (only readied workers with the client's
renderer take them); a worker lost mid-task only costs its tasks a new run elsewhere, and the
client's watch (:mod:`.watch`) moves the tasks of a stalled worker and ends a run the cluster
cannot finish with one line.

A task renders its frames with the worker's :class:`~whitted.animation.frames.FrameRenderer`
(kernels loaded once per worker, compiled geometry reused between consecutive frames) and
returns each frame as the PNG the local executor writes, byte for byte: the same writer, the
same pixels, the client's hash, the worker's renderer fingerprint (the client's). The client
takes results in the order they finish and writes each frame atomically, once. A frame that
fails (a bad model file, a kernel error) is reported, not retried: the run goes on, saves
every other frame, and then ends with one line naming the frame and the reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..animation.film import FrameFailed, FrameJob
from ..animation.frames import FrameResult
from ..scene.scene import Scene
from ._dask import Client
from .transfer import AssetMode, Shipment, ship_assets
from .worker import render_frame_chunk

if TYPE_CHECKING:
    from ..animation.film import Finished, Tell
    from ..render.api import CancelToken

RETRIES = 2
#: a task holds at least this much work when frames are short (Dask's ~10 ms a task is noise)
TASK_SECONDS = 2.0
#: and every render thread gets at least this many tasks when frames allow, so that the last
#: round of tasks, when threads run out of work one by one, is short
ROUNDS = 4

__all__ = ["DaskFrames", "FarmReport", "FrameFailed", "chunk_size"]


def chunk_size(frames: int, threads: int, frame_seconds: float | None) -> int:
    """Frames per task for ``frames`` frames on ``threads`` render threads in all (the Dask
    threads of every worker) when a frame takes ``frame_seconds`` (measured; None: not yet,
    then 1). Enough frames that a task holds :data:`TASK_SECONDS` of work, few enough that
    each thread gets :data:`ROUNDS` tasks: the last round, when threads finish one by one,
    lasts at most one task (TASK_SECONDS, or one frame when frames are long)."""
    if frame_seconds is None or frames <= 0:
        return 1
    wanted = math.ceil(TASK_SECONDS / max(frame_seconds, 1e-6))
    most = max(1, frames // (ROUNDS * max(1, threads)))
    return max(1, min(wanted, most))


@dataclass
class FarmReport:
    """What :class:`DaskFrames` did (``FilmResult.report``)."""

    tasks: int = 0
    chunk: int = 1  # the most frames a task held
    threads: int = 0  # the cluster's Dask threads when the tasks were sized
    asset_bytes: int = 0  # the scene's files sent to the workers
    render_cpu_seconds: float = 0.0  # the task threads' CPU time, summed
    workers: dict[int, str] = field(default_factory=dict)  # frame -> the worker that made it
    failed: dict[int, str] = field(default_factory=dict)  # frame -> why not


class _Stop:
    """A :class:`~whitted.render.api.CancelToken` as the watch's ``is_set()``."""

    def __init__(self, cancel: CancelToken | None) -> None:
        self.cancel = cancel

    def is_set(self) -> bool:
        return self.cancel is not None and self.cancel.cancelled


class DaskFrames:
    """The executor of :func:`whitted.animation.film.render_film` on the Dask cluster behind
    ``client`` (its workers readied: :func:`whitted.farm.ready_cluster`). ``chunk``: frames
    a task (default: sized from the measured frame time, :func:`chunk_size`); ``assets``: how
    the scene's files reach the workers ("auto", "ship", "shared", or a :class:`Shipment`);
    ``retries`` of a task whose worker was lost; ``note``: one line for each thing a wrangler
    should know (a worker that cannot render, a stalled one); ``stall_floor``: the least
    seconds before a worker is called stalled (:mod:`whitted.farm.watch`). Raises
    :class:`~whitted.farm.ClusterLost` when the cluster cannot go on (what arrived is
    written). ``report`` (a :class:`FarmReport`) says what it did."""

    def __init__(self, client: Client, *, chunk: int | None = None,
                 assets: AssetMode | Shipment = "auto", retries: int = RETRIES,
                 note: Callable[[str], None] | None = None,
                 stall_floor: float | None = None) -> None:
        self.client = client
        self.chunk = chunk
        self.assets = assets
        self.retries = retries
        self.note = note
        self.stall_floor = stall_floor
        self.report = FarmReport()

    def render_frames(self, scene: Scene, jobs: list[FrameJob], *, finished: Finished,
                      tell: Tell | None, cancel: CancelToken | None) -> bool:
        if not jobs:
            return True
        report = self.report
        done = _render_on_cluster(self, scene, jobs, finished, _Stop(cancel))
        if done and report.failed:
            frame = min(report.failed)
            raise FrameFailed(frame, report.failed[frame])
        return done


def _render_on_cluster(executor: DaskFrames, scene: Scene, jobs: list[FrameJob],
                       finished: Finished, stop: _Stop) -> bool:
    from ..compile.embree import with_concrete_mesh_tracer
    from ..files import atomic_write
    from .watch import STALL_FLOOR, Watch, cancel_quietly, run_tasks
    from .worker import TASK_RESOURCES, scene_argument

    client, report, chunk = executor.client, executor.report, executor.chunk
    watch = Watch(client, executor.note, stall_floor=STALL_FLOOR
                  if executor.stall_floor is None else executor.stall_floor)
    tasks: dict[Any, list[int]] = {}
    measured: list[float] = []
    try:
        info = client.scheduler_info(n_workers=-1)
        threads = max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))
        report.threads = threads
        shipment = (executor.assets if isinstance(executor.assets, Shipment)
                    else ship_assets(client, [job.still for job in jobs], executor.assets))
        # the scene as a task's result when big: a worker that lost it (killed, restarted)
        # gets it again, computed from the task, from wherever it still is
        scene_future = scene_argument(client, with_concrete_mesh_tracer(scene))

        def submit(run: list[int], workers: list[str] | None = None):
            manifest, blobs = shipment.for_scenes(run)  # shipment.needs is indexed like jobs
            return client.submit(render_frame_chunk, scene_future,
                                 [jobs[i].frame for i in run], [jobs[i].digest for i in run],
                                 {}, manifest, blobs, pure=False, retries=executor.retries,
                                 resources=TASK_RESOURCES, workers=workers,
                                 allow_other_workers=False)

        # sizing: a first round of one frame a task, one for each render thread; the rest,
        # in chunks sized from the first frame's measured time (chunk_size), once it is known
        later = list(range(len(jobs)))
        if chunk:
            first, later = later, []
            runs = [first[i:i + chunk] for i in range(0, len(first), chunk)]
        else:
            first, later = later[:threads], later[threads:]
            runs = [[i] for i in first]
        for run in runs:
            tasks[submit(run)] = run
        report.tasks, report.chunk, report.asset_bytes = len(runs), chunk or 1, shipment.bytes
        index = {job.frame: i for i, job in enumerate(jobs)}

        def on_done(future, run: list[int]) -> None:
            if future.status == "cancelled":  # by the scheduler: it is going
                raise watch.lost()
            try:  # "finished"; or "lost": finished, then its worker died before the result
                # came here, and Dask computes it again (watch.result waits, or gives it back)
                outcomes = watch.result(future)
            except Exception as exc:
                if future.status != "error":
                    raise
                for i in run:  # the task itself failed, after its retries
                    report.failed[jobs[i].frame] = _reason(exc)
                return
            watch.record(o.seconds for o in outcomes if o.png is not None)
            interrupt = None
            for outcome in outcomes:  # each written, even after a Ctrl-C in the progress
                if outcome.png is None:
                    report.failed[outcome.frame] = outcome.error
                    continue
                job = jobs[index[outcome.frame]]
                atomic_write(job.path, lambda tmp, data=outcome.png: Path(tmp).write_bytes(data))
                measured.append(outcome.seconds)
                report.workers[outcome.frame] = outcome.worker
                report.render_cpu_seconds += outcome.cpu_seconds
                if interrupt is None:
                    try:
                        finished(job, FrameResult(job.frame, job.path, job.digest,
                                                  rendered=True, seconds=outcome.seconds),
                                 list(outcome.warnings))
                    except KeyboardInterrupt as exc:
                        interrupt = exc
            if interrupt is not None:
                raise interrupt

        def between() -> None:
            if not later or not (measured or report.failed):
                return
            frame_seconds = sum(measured) / len(measured) if measured else None
            size = chunk_size(len(later), threads, frame_seconds)
            runs = [later[i:i + size] for i in range(0, len(later), size)]
            later.clear()
            for run in runs:
                tasks[submit(run)] = run
            report.tasks += len(runs)
            report.chunk = max(report.chunk, size)
            watch.frames_per_task = size

        return run_tasks(watch, tasks, submit, on_done, cancel=stop, between=between)
    finally:
        watch.close()
        cancel_quietly(client, tasks)


def _reason(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
