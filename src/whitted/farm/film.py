"""A film's frames as Dask tasks; the client writes each frame as it arrives.

The client works out, for every frame asked for, the still (``scene.at_frame``) and the hash
the animation feature records in a frame's PNG (:func:`whitted.animation.frames.frame_digest`,
computed here, where the files have the paths the hash names). A frame whose PNG already
holds that hash is done (resume); the others go to the workers, one task per frame, or per
run of consecutive frames when frames are short (so the per-task overhead stays small beside
the work). Tasks are ``pure=False`` with ``retries``; a worker lost mid-task only costs its
tasks a new run elsewhere (Dask reschedules them; the results it held are computed again).

A task renders its frames with the worker's :class:`~whitted.animation.frames.FrameRenderer`
(kernels loaded once per worker, compiled geometry reused between consecutive frames) and
returns each frame as the PNG the local ``whitted animate`` writes, byte for byte: the same
writer, the same pixels, the client's hash. The client takes results in the order they finish
(``as_completed``) and writes each frame atomically, once. A frame that fails (a bad model
file, a kernel error) is reported, not retried: the run goes on, saves every other frame, and
then ends with one line naming the frame and the reason. The film is encoded only when the
whole numbered sequence is on disk, in frame order.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import WhittedError
from ..scene.scene import Scene
from ._dask import Client, as_completed
from .transfer import AssetMode, Shipment, ship_assets
from .worker import render_frame_chunk

RETRIES = 2
#: samples (pixels x samples per pixel) a task should hold at least: about a second of work
#: at this machine's few Mrays/s, so Dask's few milliseconds per task are noise
SAMPLES_PER_TASK = 1_000_000
TASKS_PER_WORKER = 3  # at least this many tasks a worker, so the last ones finish together


class FrameFailed(WhittedError):
    """A frame could not be rendered: ``frame`` and the reason, in one line."""

    def __init__(self, frame: int, reason: str) -> None:
        super().__init__(f"frame {frame}: {reason}")
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


def chunk_size(width: int, height: int, samples: int, frames: int, workers: int) -> int:
    """Frames per task: enough that a task holds about :data:`SAMPLES_PER_TASK` samples,
    few enough that every worker gets :data:`TASKS_PER_WORKER` tasks."""
    per_frame = max(1, width * height * samples)
    wanted = max(1, math.ceil(SAMPLES_PER_TASK / per_frame))
    most = max(1, frames // (TASKS_PER_WORKER * max(1, workers)))
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
    **settings: Any,
) -> FilmResult:
    """Render ``frames`` (default: all) of ``scene`` on the cluster behind ``client`` into
    ``frames_dir`` as numbered PNGs (resumable: frames already there from the same scene and
    settings are kept unless ``force``), then encode ``film`` (.mp4 or .gif) when given.

    ``settings`` replace render settings of every frame (``width``, ``height``, ``samples``,
    ``max_depth``, ``seed``), as ``whitted animate``'s options do. ``progress(done, total,
    frame)`` is called once for each frame kept (frame None) or written. ``plan``: from
    :func:`plan_film` when the caller made it already (then ``client`` may be None when no
    frame is left to render). Raises :class:`FrameFailed` for the first frame that failed,
    after all the others are saved."""
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
                        progress=progress, write=atomic_write)
    result.wall_seconds = time.perf_counter() - started
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
                    assets, retries, settings, progress, write) -> None:
    s = stills[todo[0]].render
    workers = max(1, len(client.scheduler_info().get("workers", {})))
    size = chunk or chunk_size(s.width, s.height, s.samples, len(todo), workers)
    runs = [todo[i:i + size] for i in range(0, len(todo), size)]
    shipment = (assets if isinstance(assets, Shipment)
                else ship_assets(client, [stills[i] for i in todo], assets))
    position = {i: n for n, i in enumerate(todo)}  # shipment.needs is indexed like todo
    from ..compile.embree import with_concrete_mesh_tracer

    [scene_future] = client.scatter([with_concrete_mesh_tracer(scene)], broadcast=True,
                                    hash=False)
    futures = {}
    for run in runs:
        manifest, blobs = shipment.for_scenes([position[i] for i in run])
        future = client.submit(render_frame_chunk, scene_future, [chosen[i] for i in run],
                               [digests[i] for i in run], settings, manifest, blobs,
                               pure=False, retries=retries)
        futures[future] = run
    result.tasks, result.chunk, result.asset_bytes = len(runs), size, shipment.bytes
    where = {chosen[i]: paths[i] for i in todo}
    done = len(result.kept)
    try:
        for future in as_completed(futures):
            if future.status == "error":  # the task itself failed, after its retries
                exc = future.exception()
                for i in futures[future]:
                    result.failed[chosen[i]] = _reason(exc)
                continue
            for outcome in future.result():
                if outcome.png is None:
                    result.failed[outcome.frame] = outcome.error
                    continue
                write(where[outcome.frame],
                      lambda tmp, data=outcome.png: Path(tmp).write_bytes(data))
                result.rendered.append(outcome.frame)
                result.render_seconds += outcome.seconds
                result.render_cpu_seconds += outcome.cpu_seconds
                result.warnings.extend(w for w in outcome.warnings
                                       if w not in result.warnings)
                done += 1
                if progress is not None:
                    progress(done, len(chosen), outcome.frame)
    finally:
        client.cancel(list(futures))


def _reason(exc: BaseException | None) -> str:
    text = str(exc).strip().splitlines()[0] if exc is not None and str(exc).strip() else ""
    return text or type(exc).__name__
