"""What runs in a Dask worker: the plugin that readies each worker once, and the tasks.

:class:`WhittedWorker` is a Dask ``WorkerPlugin``: when a worker joins (or when the plugin is
registered with workers already running) it sets how many threads whitted renders with in that
worker (Dask pins OpenMP and BLAS threads, not Numba's nor whitted's render lanes), and loads
the render kernels from the worker's Numba cache, compiling them there on a cold cache
(:func:`whitted.render.warm_up.warm_up_kernels`). That happens before the worker runs its first
task, so no frame pays for it and no two frames on one worker compile twice.

Before any of that it compares the worker's renderer fingerprint (whitted's version, a hash of
all its source, the versions of Numba, llvmlite and NumPy, the CPU target the kernels are
compiled for: :mod:`whitted.fingerprint`) with the client's, which the plugin carries:
a worker running another whitted is never given a task. A worker offers the Dask resource
:data:`RESOURCE` (one unit per Dask thread) only once it is readied, and every whitted task
asks for one unit: a worker that is still compiling, runs another whitted, or cannot load
whitted at all (the plugin fails to unpickle there) takes no task. What the plugin finds is
logged as a Dask event on the topic :data:`EVENT_TOPIC` (``ready``, ``mismatch``,
``compiling`` with the fraction done), and every finished frame and band as one on
:data:`PROGRESS_TOPIC`: the client watches those for stalls (:mod:`whitted.farm.watch`).

The tasks are plain functions of this module (workers import them from their own whitted):
:func:`render_band` renders some rows of a still, :func:`render_frame_chunk` some frames of a
film, :func:`hold` gives back the scene it was submitted with (the scene is a task's result,
not scattered data, so that a worker that lost it gets it again: see :mod:`.film`).
"""

from __future__ import annotations

import asyncio
import os
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..render.api import RenderStats
from ..scene.scene import Scene
from ._dask import WorkerPlugin
from .assets import AssetManifest, materialise, worker_scene

PLUGIN_NAME = "whitted-worker"
#: the Dask resource a readied worker offers, one unit per Dask thread; each task takes one
RESOURCE = "whitted"
TASK_RESOURCES = {RESOURCE: 1}
EVENT_TOPIC = "whitted-worker"  # ready / mismatch / compiling, one event each
PROGRESS_TOPIC = "whitted-progress"  # a frame or band finished on a worker
COMPILE_NOTE_SECONDS = 2.0  # how often a compiling worker says how far it is
_threads = 1  # render threads of this worker process (set by the plugin)
_warm_seconds: float | None = None


def set_worker_threads(threads: int) -> None:
    """Render with ``threads`` lanes in this process (Numba's pool keeps its size)."""
    global _threads
    _threads = max(1, int(threads))
    import numba

    # Numba re-reads its environment at each compile and refuses a NUMBA_NUM_THREADS that
    # differs from the pool it launched (with the size its configuration had when Numba was
    # imported); a worker may have imported Numba before Dask set its environment (a spawned
    # worker re-imports the client's main module). The environment is made to say what the
    # configuration does, and the threads a render uses are capped (public API only).
    os.environ["NUMBA_NUM_THREADS"] = str(numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(min(_threads, numba.config.NUMBA_NUM_THREADS))


def warm_worker() -> float:
    """Load (or compile) the kernels in this process; the seconds it took."""
    global _warm_seconds
    from ..render.warm_up import warm_up_kernels

    start = time.perf_counter()
    warm_up_kernels()
    _warm_seconds = time.perf_counter() - start
    return _warm_seconds


def warm_seconds() -> float | None:
    """How long this worker's warm-up took (None before it ran): for measurements."""
    return _warm_seconds


class WhittedWorker(WorkerPlugin):
    """Readies each worker: ``threads`` render threads (default 1: one worker per core is the
    usual layout), kernels loaded before the first task when ``warm``. ``fingerprint``: the
    renderer the worker must run (default: this process's, the client's); a worker with
    another one is left without the :data:`RESOURCE` that whitted's tasks need."""

    name = PLUGIN_NAME

    def __init__(self, threads: int = 1, warm: bool = True,
                 fingerprint: str | None = None) -> None:
        from ..fingerprint import renderer_fingerprint

        self.threads = threads
        self.warm = warm
        self.fingerprint = fingerprint or renderer_fingerprint()

    async def setup(self, worker) -> None:
        from ..fingerprint import renderer_fingerprint

        mine = renderer_fingerprint()
        if mine != self.fingerprint:
            worker.log_event(EVENT_TOPIC, {"worker": worker.address, "status": "mismatch",
                                           "fingerprint": mine, "wanted": self.fingerprint})
            await worker.set_resources(**{RESOURCE: 0})
            return
        set_worker_threads(self.threads)
        seconds = 0.0
        if self.warm:  # off the event loop, so the worker keeps answering the scheduler
            seconds = await self._warm(worker)
        worker.log_event(EVENT_TOPIC, {"worker": worker.address, "status": "ready",
                                       "fingerprint": mine, "warm_seconds": seconds})
        await worker.set_resources(**{RESOURCE: worker.state.nthreads})

    @staticmethod
    async def _warm(worker) -> float:
        """Warm the kernels on a thread; while a cold compile runs, say how far it is."""
        from ..render.warm_up import compile_progress

        done = asyncio.get_running_loop().run_in_executor(None, warm_worker)
        while True:
            try:
                return await asyncio.wait_for(asyncio.shield(done), COMPILE_NOTE_SECONDS)
            except TimeoutError:
                fraction = compile_progress()
                if fraction is not None:
                    worker.log_event(EVENT_TOPIC, {"worker": worker.address,
                                                   "status": "compiling",
                                                   "fraction": fraction})


def hold(value: Any) -> Any:
    """The value this task was submitted with: data every task needs (the scene) kept as a
    task's result, so that Dask computes it again on another worker when the ones holding
    it are lost (scattered data would be gone with them)."""
    return value


#: a scene that pickles to at most this many bytes travels inside each task (no worker holds
#: anything another needs); a bigger one is a task's result every task depends on
SCENE_INLINE_BYTES = 64 * 1024


def scene_argument(client: Any, scene: Scene) -> Any:
    """What tasks take as their scene: the scene itself when small (:data:`SCENE_INLINE_BYTES`),
    else the future of a :func:`hold` task: either way a worker that lost it, or a new one,
    gets it again (from the task, or computed again), never from a worker that stopped."""
    import pickle

    if len(pickle.dumps(scene, protocol=pickle.HIGHEST_PROTOCOL)) <= SCENE_INLINE_BYTES:
        return scene
    return client.submit(hold, scene, pure=False, resources=TASK_RESOURCES)


def _progress(**message: Any) -> str:
    """Tell the client (through the scheduler) that a frame or band finished here; this
    worker's address ('' outside a worker)."""
    from ._dask import get_worker

    try:
        worker = get_worker()
    except ValueError:  # not in a worker (a test calling the task directly)
        return ""
    worker.log_event(PROGRESS_TOPIC, {"worker": worker.address, **message})
    return worker.address


def _prepared(scene: Scene, manifest: AssetManifest | None,
              blobs: dict[str, bytes]) -> tuple[Scene, Callable[[str], str]]:
    """The scene re-pointed at this worker's copy of its files, and a function that turns
    the worker's file names in a message back into the client's."""
    if manifest is None:  # the workers see the client's files
        return scene, str
    tree = materialise(manifest, blobs)
    return worker_scene(scene, manifest, tree), lambda text: text.replace(
        str(tree), manifest.client_root)


def render_band(scene: Scene, start: int, stop: int, manifest: AssetManifest | None = None,
                blobs: dict[str, bytes] | None = None) -> tuple[int, np.ndarray, RenderStats]:
    """Rows [start, stop) of the still: (start, the float32 rows, the band's statistics)."""
    from ..render.api import RenderJob

    prepared, client_names = _prepared(scene, manifest, blobs or {})
    job = RenderJob(prepared, threads=_threads, rows=(start, stop))
    job.run()
    job.stats.warnings = [client_names(w) for w in job.stats.warnings]
    _progress(band=start)
    return start, job.framebuffer[start:stop].copy(), job.stats


@dataclass
class FrameOutcome:
    """One frame from a worker: its PNG's bytes, or why there are none."""

    frame: int
    png: bytes | None
    error: str = ""
    seconds: float = 0.0
    cpu_seconds: float = 0.0  # this task thread's CPU time (all of it with 1 render thread)
    warnings: list[str] = field(default_factory=list)
    worker: str = ""  # the address of the worker that rendered it


def frame_png(image: Any, digest: str, frame: int) -> bytes:
    """The bytes of the frame PNG the animation feature writes for ``image`` (its writer,
    into a temporary file: the same bytes ``whitted animate`` writes)."""
    from ..animation.frames import write_frame_png

    with tempfile.TemporaryDirectory(prefix="whitted-frame-") as tmp:
        path = Path(tmp) / "frame.png"
        write_frame_png(path, image, digest, frame)
        return path.read_bytes()


_renderers = threading.local()  # a FrameRenderer per Dask thread: geometry reused between
#                                 the consecutive frames one thread renders


def render_frame_chunk(scene: Scene, frames: list[int], digests: list[str],
                       settings: dict[str, Any], manifest: AssetManifest | None = None,
                       blobs: dict[str, bytes] | None = None) -> list[FrameOutcome]:
    """Frames ``frames`` of the animated ``scene`` (with render ``settings`` replaced), each
    as the PNG bytes that carry the client's ``digests``. A frame that fails is returned with
    its reason (the others still render); anything else raised fails the task (retried)."""
    from ..animation.frames import FrameRenderer, still_for_frame
    from ..render.api import RenderJob

    renderer = getattr(_renderers, "renderer", None)
    if renderer is None:
        renderer = _renderers.renderer = FrameRenderer(_threads)
    prepared, client_names = _prepared(scene, manifest, blobs or {})
    outcomes = []
    for frame, digest in zip(frames, digests, strict=True):
        start, cpu = time.perf_counter(), time.thread_time()
        try:
            still = still_for_frame(prepared, frame, **settings)
            compiled, _ = renderer.compile(still)
            job = RenderJob(still, threads=_threads, compiled=compiled)
            png = frame_png(job.run(), digest, frame)
        except Exception as exc:  # noqa: BLE001 - this frame's own failure, told to the client
            reason = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            outcomes.append(FrameOutcome(frame, None,
                                         client_names(reason) or type(exc).__name__))
            continue
        outcomes.append(FrameOutcome(frame, png, seconds=time.perf_counter() - start,
                                     cpu_seconds=time.thread_time() - cpu,
                                     warnings=[client_names(w) for w in job.stats.warnings]))
        outcomes[-1].worker = _progress(frame=frame, seconds=outcomes[-1].seconds)
    return outcomes
