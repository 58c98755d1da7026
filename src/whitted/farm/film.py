"""A film's frames as Dask tasks; the client writes each frame as it arrives.

The client works out, for every frame asked for, the still (``scene.at_frame``) and the hash
the animation feature records in a frame's PNG (:func:`whitted.animation.frames.frame_digest`,
computed here, where the files have the paths the hash names). A frame whose PNG already
holds that hash, recorded by this renderer, is done (resume); the others go to the workers:
first one frame a task for each Dask thread of the cluster, then, once a frame's time is
measured, runs of consecutive frames sized by :func:`chunk_size`. Tasks are ``pure=False``
with ``retries`` and ask for the ``whitted`` resource (only readied workers with the client's
renderer take them); a worker lost mid-task only costs its tasks a new run elsewhere, and the
client's watch (:mod:`.watch`) moves the tasks of a stalled worker and ends a run the cluster
cannot finish with one line.

A task renders its frames with the worker's :class:`~whitted.animation.frames.FrameRenderer`
(kernels loaded once per worker, compiled geometry reused between consecutive frames) and
returns each frame as the PNG the local ``whitted animate`` writes, byte for byte: the same
writer, the same pixels, the client's hash, the worker's renderer fingerprint (the client's).
The client takes results in the order they finish and writes each frame atomically, once. A
frame that fails (a bad model file, a kernel error) is reported, not retried: the run goes
on, saves every other frame, and then ends with one line naming the frame and the reason.
The film is encoded only when the whole numbered sequence is on disk, in frame order.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import WhittedError
from ..scene.scene import Scene
from ._dask import Client
from .transfer import AssetMode, Shipment, ship_assets
from .worker import render_frame_chunk

RETRIES = 2
#: a task holds at least this much work when frames are short (Dask's ~10 ms a task is noise)
TASK_SECONDS = 2.0
#: and every render thread gets at least this many tasks when frames allow, so that the last
#: round of tasks, when threads run out of work one by one, is short
ROUNDS = 4


class FrameFailed(WhittedError):
    """A frame could not be rendered: ``frame`` and the reason, in one line."""

    def __init__(self, frame: int, reason: str) -> None:
        prefix = f"frame {frame}:"  # a reason that names its frame already is not told twice
        super().__init__(reason if reason.startswith(prefix) else f"{prefix} {reason}")
        self.frame = frame
        self.reason = reason


@dataclass
class FilmResult:
    """What :func:`render_film` did."""

    frames: list[int]  # every frame asked for, in order
    paths: list[Path]  # their PNG files, in frame order
    rendered: list[int] = field(default_factory=list)  # frames written, in arrival order
    kept: list[int] = field(default_factory=list)  # frames already on disk (resume)
    failed: dict[int, str] = field(default_factory=dict)
    tasks: int = 0
    chunk: int = 1
    asset_bytes: int = 0
    render_seconds: float = 0.0  # the workers' time per frame, summed
    render_cpu_seconds: float = 0.0  # their task threads' CPU time, summed
    wall_seconds: float = 0.0
    film: Path | None = None
    warnings: list[str] = field(default_factory=list)
    interrupted: bool = False  # stopped by ``cancel``: what arrived is written, no film
    workers: dict[int, str] = field(default_factory=dict)  # frame -> the worker that made it
    threads: int = 0  # the cluster's Dask threads when the tasks were sized


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
class FilmPlan:
    """Which frames of a film are done and which are to render (no cluster needed)."""

    frames: list[int]
    stills: list[Scene]
    digests: list[str]
    paths: list[Path]
    todo: list[int]  # indices into the lists above: the frames to render
    kept: list[int]  # frames already on disk from the same scene and settings


def plan_film(scene: Scene, frames_dir: str | Path, *, frames: Sequence[int] | None = None,
              force: bool = False, **settings: Any) -> FilmPlan:
    """Each frame's still, hash and file; the frames whose PNG already holds their hash are
    kept (unless ``force``)."""
    from ..animation.film import frame_name
    from ..animation.frames import frame_digest, frame_is_current, still_for_frame

    folder = Path(frames_dir)
    count = scene.frame_count
    chosen = list(range(count) if frames is None else frames)
    stills = [still_for_frame(scene, k, **settings) for k in chosen]
    digests = [frame_digest(still, k) for still, k in zip(stills, chosen, strict=True)]
    paths = [folder / frame_name(k, count) for k in chosen]
    todo, kept = [], []
    for i, (k, digest, path) in enumerate(zip(chosen, digests, paths, strict=True)):
        if not force and frame_is_current(path, digest):
            kept.append(k)
        else:
            todo.append(i)
    return FilmPlan(chosen, stills, digests, paths, todo, kept)


def render_film(
    client: Client | None,
    scene: Scene,
    frames_dir: str | Path,
    *,
    frames: Sequence[int] | None = None,
    film: str | Path | None = None,
    fps: float | None = None,
    crf: int | None = None,
    chunk: int | None = None,
    assets: AssetMode | Shipment = "auto",
    retries: int = RETRIES,
    force: bool = False,
    progress: Callable[[int, int, int | None], None] | None = None,
    plan: FilmPlan | None = None,
    cancel: threading.Event | None = None,
    note: Callable[[str], None] | None = None,
    stall_floor: float | None = None,
    **settings: Any,
) -> FilmResult:
    """Render ``frames`` (default: all) of ``scene`` on the cluster behind ``client`` into
    ``frames_dir`` as numbered PNGs (resumable: frames already there from the same scene and
    settings are kept unless ``force``), then encode ``film`` (.mp4 or .gif) when given.

    ``settings`` replace render settings of every frame (``width``, ``height``, ``samples``,
    ``max_depth``, ``seed``), as ``whitted animate``'s options do. ``progress(done, total,
    frame)`` is called once for each frame kept (frame None) or written. ``plan``: from
    :func:`plan_film` when the caller made it already (then ``client`` may be None when no
    frame is left to render). ``cancel``: set it to stop (the frames that arrived are written,
    ``result.interrupted`` is True, no film is encoded). ``note``: one line for each thing a
    wrangler should know (a worker that cannot render, a stalled one). ``stall_floor``: the
    least seconds before a worker is called stalled (:mod:`whitted.farm.watch`). Raises
    :class:`FrameFailed` for the first frame that failed, after all the others are saved, and
    :class:`~whitted.farm.watch.ClusterLost` when the cluster cannot go on (what arrived is
    written)."""
    from ..files import atomic_write

    started = time.perf_counter()
    folder = Path(frames_dir)
    folder.mkdir(parents=True, exist_ok=True)
    if plan is None:
        plan = plan_film(scene, folder, frames=frames, force=force, **settings)
    chosen, stills, digests, paths, todo = (plan.frames, plan.stills, plan.digests,
                                            plan.paths, plan.todo)
    result = FilmResult(chosen, paths, kept=list(plan.kept),
                        film=Path(film) if film is not None else None)
    for done in range(1, len(plan.kept) + 1):
        if progress is not None:
            progress(done, len(chosen), None)
    if todo and client is None:
        raise ValueError(f"{len(todo)} frames to render and no client")

    if todo:
        _render_missing(client, scene, stills, chosen, digests, paths, todo, result,
                        chunk=chunk, assets=assets, retries=retries, settings=settings,
                        progress=progress, write=atomic_write, cancel=cancel, note=note,
                        stall_floor=stall_floor)
    result.wall_seconds = time.perf_counter() - started
    if result.interrupted:
        return result
    if result.failed:
        frame = min(result.failed)
        raise FrameFailed(frame, result.failed[frame])
    if film is not None:
        from ..output.video import DEFAULT_CRF, encode_film

        rate = fps or (scene.animation.fps if scene.animation is not None else 24.0)
        encode_film(paths, film, rate, crf=DEFAULT_CRF if crf is None else crf)
        result.wall_seconds = time.perf_counter() - started
    return result


def _render_missing(client, scene, stills, chosen, digests, paths, todo, result, *, chunk,
                    assets, retries, settings, progress, write, cancel, note,
                    stall_floor) -> None:
    from ..compile.embree import with_concrete_mesh_tracer
    from .watch import STALL_FLOOR, Watch, cancel_quietly, run_tasks
    from .worker import TASK_RESOURCES, scene_argument

    watch = Watch(client, note, stall_floor=STALL_FLOOR if stall_floor is None
                  else stall_floor)
    tasks: dict[Any, list[int]] = {}
    try:
        info = client.scheduler_info(n_workers=-1)
        threads = max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))
        result.threads = threads
        shipment = (assets if isinstance(assets, Shipment)
                    else ship_assets(client, [stills[i] for i in todo], assets))
        position = {i: n for n, i in enumerate(todo)}  # shipment.needs is indexed like todo
        # the scene as a task's result: a worker that lost it (killed, restarted) gets it
        # again, computed from the task, from wherever it still is
        scene_future = scene_argument(client, with_concrete_mesh_tracer(scene))

        def submit(run: list[int], workers: list[str] | None = None):
            manifest, blobs = shipment.for_scenes([position[i] for i in run])
            return client.submit(render_frame_chunk, scene_future, [chosen[i] for i in run],
                                 [digests[i] for i in run], settings, manifest, blobs,
                                 pure=False, retries=retries, resources=TASK_RESOURCES,
                                 workers=workers, allow_other_workers=False)

        # sizing: a first round of one frame a task, one for each render thread; the rest,
        # in chunks sized from the first frame's measured time (chunk_size), once it is known
        later = list(todo)
        if chunk:
            first, later = later, []
            runs = [first[i:i + chunk] for i in range(0, len(first), chunk)]
        else:
            first, later = later[:threads], later[threads:]
            runs = [[i] for i in first]
        for run in runs:
            tasks[submit(run)] = run
        result.tasks, result.chunk, result.asset_bytes = len(runs), chunk or 1, shipment.bytes
        where = {chosen[i]: paths[i] for i in todo}
        done = [len(result.kept)]

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
                    result.failed[chosen[i]] = _reason(exc)
                return
            watch.record(o.seconds for o in outcomes if o.png is not None)
            interrupt = None
            for outcome in outcomes:  # each written, even after a Ctrl-C in the progress
                if outcome.png is None:
                    result.failed[outcome.frame] = outcome.error
                    continue
                write(where[outcome.frame],
                      lambda tmp, data=outcome.png: Path(tmp).write_bytes(data))
                result.rendered.append(outcome.frame)
                result.workers[outcome.frame] = outcome.worker
                result.render_seconds += outcome.seconds
                result.render_cpu_seconds += outcome.cpu_seconds
                result.warnings.extend(w for w in outcome.warnings
                                       if w not in result.warnings)
                done[0] += 1
                if progress is not None and interrupt is None:
                    try:
                        progress(done[0], len(chosen), outcome.frame)
                    except KeyboardInterrupt as exc:
                        interrupt = exc
            if interrupt is not None:
                raise interrupt

        def between() -> None:
            if not later or not (result.rendered or result.failed):
                return
            measured = (result.render_seconds / len(result.rendered)
                        if result.rendered else None)
            size = chunk_size(len(later), threads, measured)
            runs = [later[i:i + size] for i in range(0, len(later), size)]
            later.clear()
            for run in runs:
                tasks[submit(run)] = run
            result.tasks += len(runs)
            result.chunk = max(result.chunk, size)
            watch.frames_per_task = size

        finished = run_tasks(watch, tasks, submit, on_done, cancel=cancel, between=between)
        result.interrupted = not finished
    finally:
        watch.close()
        cancel_quietly(client, tasks)


def _reason(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
