"""What runs in a Dask worker: the plugin that readies each worker once, and the tasks.

:class:`WhittedWorker` is a Dask ``WorkerPlugin``: when a worker joins (or when the plugin is
registered with workers already running) it sets how many threads whitted renders with in that
worker (Dask pins OpenMP and BLAS threads, not Numba's nor whitted's render lanes), and loads
the render kernels from the worker's Numba cache, compiling them there on a cold cache
(:func:`whitted.render.warm_up.warm_up_kernels`). That happens before the worker runs its first
task, so no frame pays for it and no two frames on one worker compile twice.

The tasks are plain functions of this module (workers import them from their own whitted):
:func:`render_band` renders some rows of a still, :func:`render_frame_chunk` some frames of a
film.
"""

from __future__ import annotations

import asyncio
import os
import time

import numpy as np

from ..render.api import RenderStats
from ..scene.scene import Scene
from ._dask import WorkerPlugin
from .assets import AssetManifest, materialise, worker_scene

PLUGIN_NAME = "whitted-worker"
_threads = 1  # render threads of this worker process (set by the plugin)
_warm_seconds: float | None = None


def worker_threads() -> int:
    return _threads


def set_worker_threads(threads: int) -> None:
    """Render with ``threads`` lanes in this process, and cap Numba's own pool there too."""
    global _threads
    _threads = max(1, int(threads))
    import numba
    from numba.np.ufunc import parallel

    # Numba re-reads its environment at each compile and refuses a NUMBA_NUM_THREADS that
    # differs from the pool it launched; a worker may have imported Numba before Dask set
    # its environment (a spawned worker re-imports the client's main module), so the two
    # are made to agree here, before the pool starts.
    if not getattr(parallel, "_is_initialized", False):
        os.environ["NUMBA_NUM_THREADS"] = str(_threads)
        numba.config.reload_config()
    else:
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
    usual layout), kernels loaded before the first task when ``warm``."""

    name = PLUGIN_NAME

    def __init__(self, threads: int = 1, warm: bool = True) -> None:
        self.threads = threads
        self.warm = warm

    async def setup(self, worker) -> None:
        set_worker_threads(self.threads)
        if self.warm:  # off the event loop, so the worker keeps answering the scheduler
            await asyncio.get_running_loop().run_in_executor(None, warm_worker)


def _prepared(scene: Scene, manifest: AssetManifest | None, blobs: dict[str, bytes]) -> Scene:
    if manifest is None:  # the workers see the client's files
        return scene
    return worker_scene(scene, manifest, materialise(manifest, blobs))


def render_band(scene: Scene, start: int, stop: int, manifest: AssetManifest | None = None,
                blobs: dict[str, bytes] | None = None) -> tuple[int, np.ndarray, RenderStats]:
    """Rows [start, stop) of the still: (start, the float32 rows, the band's statistics)."""
    from ..render.api import RenderJob

    job = RenderJob(_prepared(scene, manifest, blobs or {}), threads=_threads,
                    rows=(start, stop))
    job.run()
    return start, job.framebuffer[start:stop].copy(), job.stats
