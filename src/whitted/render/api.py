"""The one render API every client uses (CLI, editor, farm): tile-based, progressive,
cancellable, with progress callbacks.

>>> job = RenderJob(scene, progress=print)       # doctest: +SKIP
>>> image = job.run()                             # blocking; or job.start() for a thread
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from ..compile.params import render_params
from ..compile.scene import CompiledScene, compile_scene, scene_needs_builders
from ..errors import ArgumentError, JobStateError
from ..kernels.layout import (
    N_RAY_KINDS,
    RAY_PRIMARY,
    RAY_REFLECTION,
    RAY_REFRACTION,
    RAY_SHADOW,
)
from ..output.image import Image
from ..scene.scene import RenderSettings, Scene
from .warm_up import (
    caustics_compile,
    first_variant,
    kernel_variant,
    kernels_cached,
    stand_in_scene,
    warm_up_kernels,
)

RAY_KIND_NAMES = {
    RAY_PRIMARY: "primary",
    RAY_SHADOW: "shadow",
    RAY_REFLECTION: "reflection",
    RAY_REFRACTION: "refraction",
}
DEFAULT_TILE = 16
# a lane's run of tiles lasts at least this long when the tiles are fast: its Python between
# runs (taking tiles, counters, progress) then costs little, also with two lanes, where it
# waits for the GIL (csg at 2 threads: 24.1 -> 22.0 ms); progress still comes 50 times a
# second or more
RUN_SECONDS = 0.02
MAX_TILE = 4096
MAX_THREADS = 1024  # as RenderSettings.threads


def _whole_number(name: str, value: object, low: int, high: int) -> int:
    """``value`` as an int in low..high, else :class:`ArgumentError` naming the argument."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ArgumentError(f"{name} must be a whole number, got {value!r}")
    if not low <= int(value) <= high:
        raise ArgumentError(f"{name} must be between {low} and {high}, got {value!r}")
    return int(value)


def _as_scene(scene: object, what: str = "scene") -> Scene:
    """A Scene; a path (str or os.PathLike) is loaded as a scene file."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, str | os.PathLike):
        from ..scene.io import load_scene

        return load_scene(scene)
    raise ArgumentError(f"{what} must be a whitted.Scene or the path of a scene file, "
                        f"got {type(scene).__name__}")


class JobState(StrEnum):
    """Where a :class:`RenderJob` is: not started, running, or how it ended. A str, so
    ``job.state == "finished"`` reads as well as ``job.state is JobState.FINISHED``."""

    READY = "ready"  # made, not started
    RUNNING = "running"  # compiling or rendering
    FINISHED = "finished"  # every tile rendered
    CANCELLED = "cancelled"  # stopped by its CancelToken: the tiles finished are in the image
    FAILED = "failed"  # raised: ``job.error`` is what

    def __str__(self) -> str:
        return self.value


class CancelToken:
    """Set it from any thread to stop a render after the tiles in flight."""

    def __init__(self) -> None:
        self._event = threading.Event()

    def cancel(self) -> None:
        self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()


@dataclass
class Progress:
    """What a progress callback receives after each batch of tiles."""

    tiles_done: int
    tiles_total: int
    rays: int
    elapsed: float
    eta: float | None
    #: the tiles finished in this batch, rows of (x0, y0, x1, y1): repaint just these
    new_tiles: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 4), np.int32))
    #: the rays each of ``new_tiles`` cost (every kind together): what a part of the picture
    #: costs, whatever the batches were
    tile_rays: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, np.int64))

    @property
    def fraction(self) -> float:
        return self.tiles_done / self.tiles_total if self.tiles_total else 1.0


@dataclass
class RenderStats:
    width: int
    height: int
    threads: int
    samples: int
    max_depth: int
    build_seconds: float = 0.0
    compile_seconds: float = 0.0
    render_seconds: float = 0.0
    wall_seconds: float = 0.0
    rays: dict[str, int] = field(default_factory=dict)
    tiles_done: int = 0
    tiles_total: int = 0
    cancelled: bool = False
    warnings: list[str] = field(default_factory=list)  # from the scene's compilation
    triangles: int = 0  # mesh triangles stored (each distinct mesh once)
    photons: object = None  # compile.photon_map.PhotonStats of a render with caustics

    @property
    def total_rays(self) -> int:
        return sum(self.rays.values())

    @property
    def mrays_per_second(self) -> float:
        return self.total_rays / self.render_seconds / 1e6 if self.render_seconds > 0 else 0.0

    def summary(self) -> str:
        state = " (cancelled)" if self.cancelled else ""
        caustics = ""
        if self.photons is not None:
            caustics = (f", caustics {self.photons.shot:,} photons ({self.photons.stored:,} "
                        f"stored) in {self.photons.seconds:.2f} s")
        return (
            f"{self.width}x{self.height}{state}: wall {self.wall_seconds:.2f} s, "
            f"compile {self.compile_seconds:.2f} s, render {self.render_seconds:.3f} s, "
            f"{self.total_rays:,} rays, {self.mrays_per_second:.1f} Mrays/s, "
            f"{self.threads} thread{'s' if self.threads != 1 else ''}{caustics}"
        )


def available_threads() -> int:
    """Cores this process may use (the default thread count)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def run_lanes(fn: Callable[[int, int], object], lanes: int, pool: ThreadPoolExecutor | None):
    """Call ``fn(lane, lanes)`` for every lane and wait for all of them: lane 0 on the
    calling thread, the others concurrently on ``pool`` (the kernels release the GIL). When
    a lane raises, the others are still waited for (none writes after this returns)."""
    if lanes == 1 or pool is None:
        for lane in range(lanes):
            fn(lane, lanes)
        return
    futures = [pool.submit(fn, lane, lanes) for lane in range(1, lanes)]
    try:
        fn(0, lanes)
    finally:
        wait(futures)
    for future in futures:
        future.result()


def tile_grid(width: int, height: int, tile: int = DEFAULT_TILE,
              rows: tuple[int, int] | None = None,
              region: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """All tiles of the image in row-major order, rows of (x0, y0, x1, y1); only those of the
    image rows ``rows = (start, stop)`` when given, and only those covering ``region = (x0,
    y0, x1, y1)`` (pixels, ends excluded), cut to it, when given."""
    x_start, y_start, x_stop, y_stop = (0, 0, width, height) if region is None else region
    if rows is not None:
        y_start, y_stop = max(y_start, rows[0]), min(y_stop, rows[1])
    xs = np.arange(x_start, x_stop, tile)
    ys = np.arange(y_start, y_stop, tile)
    grid = [(x, y, min(x + tile, x_stop), min(y + tile, y_stop)) for y in ys for x in xs]
    return np.array(grid, dtype=np.int32).reshape(-1, 4)


class RenderJob:
    """One render of one scene. ``framebuffer`` fills in tile by tile while it runs, so a UI
    can show it; ``run()`` blocks, ``start()`` runs it on a background thread."""

    def __init__(
        self,
        scene: Scene,
        *,
        progress: Callable[[Progress], None] | None = None,
        cancel: CancelToken | None = None,
        threads: int | None = None,
        tile_size: int = DEFAULT_TILE,
        compiled: CompiledScene | None = None,
        rows: tuple[int, int] | None = None,
        region: tuple[int, int, int, int] | None = None,
        resume: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        """``scene``: a Scene (or the path of a scene file); ``threads``: 1..1024, 0 or None
        for the scene's setting (0 there: every core); ``tile_size``: pixels per tile side,
        1..4096; ``region``: render only the pixels (x0, y0, x1, y1) (ends excluded) of the
        full-size image, the rest black; ``resume``: (the tiles already finished, a bool per
        tile of :attr:`tiles`, and the framebuffer holding them) of an earlier job of the
        same scene, region and tile size: only the others are rendered, and the image is the
        one an uninterrupted job makes, byte for byte (a pixel does not depend on the tile or
        the lane that renders it). Bad arguments raise
        :class:`~whitted.errors.ArgumentError`."""
        scene = _as_scene(scene)
        if scene.is_animated:  # an animated scene renders as its first frame
            scene = scene.at_frame(0)
        if progress is not None and not callable(progress):
            raise ArgumentError(f"progress must be callable, got {type(progress).__name__}")
        if cancel is not None and not isinstance(cancel, CancelToken):
            raise ArgumentError(f"cancel must be a CancelToken, got {type(cancel).__name__}")
        if threads is not None:
            threads = _whole_number("threads", threads, 0, MAX_THREADS)
        tile_size = _whole_number("tile_size", tile_size, 1, MAX_TILE)
        self.scene = scene
        #: the compiled ``scene`` when the caller has it already (films reuse geometry)
        self.compiled = compiled
        self.settings: RenderSettings = scene.render
        self.progress = progress
        self.cancel_token = cancel or CancelToken()
        n = threads if threads is not None else self.settings.threads
        self.threads = max(1, n or available_threads())
        self.tile_size = tile_size
        self.rendering = False  # True while tiles are being rendered (after the compile)
        #: render only the image rows [start, stop) (the farm's bands); the other rows stay 0
        self.rows = None if rows is None else _checked_rows(rows, self.settings.height)
        self.region = None if region is None else _checked_region(
            region, self.settings.width, self.settings.height)
        #: the job's tiles, rows of (x0, y0, x1, y1), in the order they are taken
        self.tiles = tile_grid(self.settings.width, self.settings.height, self.tile_size,
                               self.rows, self.region)
        #: which of :attr:`tiles` are finished (kept in the framebuffer)
        self.tiles_finished = np.zeros(len(self.tiles), bool)
        self.framebuffer = np.zeros((self.settings.height, self.settings.width, 3), np.float32)
        if resume is not None:
            finished, framebuffer = resume
            finished = np.asarray(finished, dtype=bool)
            if finished.shape != self.tiles_finished.shape or \
                    np.shape(framebuffer) != self.framebuffer.shape:
                raise ArgumentError(f"resume: {finished.shape[0] if finished.ndim else 0} "
                                    f"tiles and a {np.shape(framebuffer)} framebuffer do not "
                                    f"fit this job's {len(self.tiles)} tiles of a "
                                    f"{self.framebuffer.shape} image")
            self.tiles_finished[:] = finished
            self.framebuffer[:] = framebuffer
        self.stats = RenderStats(
            width=self.settings.width,
            height=self.settings.height,
            threads=self.threads,
            samples=self.settings.samples,
            max_depth=self.settings.max_depth,
        )
        self.image: Image | None = None
        #: what the job raised (its state is then FAILED), None otherwise
        self.error: BaseException | None = None
        self._state = JobState.READY
        #: tiles rendered so far, of ``tiles_total`` (0 until the tiles are laid out)
        self.tiles_done = 0
        self.tiles_total = 0
        self._thread: threading.Thread | None = None
        self._ended = threading.Event()  # set when the background thread has ended

    def cancel(self) -> None:
        self.cancel_token.cancel()

    @property
    def state(self) -> JobState:
        """:class:`JobState`: READY, RUNNING, then FINISHED, CANCELLED or FAILED."""
        return self._state

    @property
    def finished(self) -> bool:
        """Every tile was rendered."""
        return self._state is JobState.FINISHED

    @property
    def cancelled(self) -> bool:
        """The job ended because it was cancelled (its image holds the tiles finished)."""
        return self._state is JobState.CANCELLED

    @property
    def failed(self) -> bool:
        """The job raised; :attr:`error` is the exception."""
        return self._state is JobState.FAILED

    @property
    def fraction(self) -> float:
        """The part of the image rendered so far, 0..1 (0 while compiling)."""
        return self.tiles_done / self.tiles_total if self.tiles_total else 0.0

    def partial_image(self) -> Image:
        """The picture as it is now, at any time (running or ended): a copy of the
        framebuffer as an :class:`Image` with the scene's transfer and tone map (tiles not
        rendered yet are black)."""
        return Image(self.framebuffer.copy(), transfer=self.settings.transfer,
                     tonemap=self.settings.tonemap, meta={"stats": self.stats})

    def srgb(self) -> np.ndarray:
        """The picture as it is now as display values: uint8 (H, W, 3), the scene's tone map
        and transfer (sRGB by default), tiles not rendered yet black."""
        return self.partial_image().to_srgb8()

    def _repr_png_(self) -> bytes:
        """The picture so far, for a notebook's rich display."""
        return self.partial_image()._repr_png_()

    def __repr__(self) -> str:
        s = self.settings
        state = f"failed: {self.error!r}" if self.failed else str(self._state)
        done = f", {self.tiles_done}/{self.tiles_total} tiles" if self.tiles_total else ""
        return f"<RenderJob {s.width}x{s.height} {state}{done}>"

    def start(self) -> threading.Thread:
        """Run the job on a background thread (once: :class:`JobStateError` when started
        again)."""
        if self._thread is not None or self._state is not JobState.READY:
            raise JobStateError("this render job was already started (make a new RenderJob)")

        def target() -> None:
            # what it raises is kept in self.error (state FAILED), handed to whoever waits
            try:
                with contextlib.suppress(BaseException):
                    self.run()
            finally:
                self._ended.set()

        self._thread = threading.Thread(target=target, name="whitted-render", daemon=True)
        self._thread.start()
        return self._thread

    def join(self, timeout: float | None = None) -> bool:
        """Wait for the background thread (if any) without raising its error; True when it
        has finished. (It waits on an event, not ``Thread.join``: a KeyboardInterrupt in the
        wait leaves the job's state true.)"""
        if self._thread is not None:
            return self._ended.wait(timeout)
        return True

    def wait(self, timeout: float | None = None) -> Image | None:
        """The image once the background render has ended (None while it still runs after
        ``timeout`` seconds); re-raises its error. :class:`JobStateError` before
        :meth:`start`."""
        if self._thread is None:
            if self.image is not None:  # finished by run()
                return self.image
            raise JobStateError("wait() before start(): start the job first (or call run())")
        if not self._ended.wait(timeout):
            return None
        if self.error is not None:
            raise self.error
        return self.image

    @property
    def running(self) -> bool:
        return self._thread is not None and not self._ended.is_set()

    def _report(self, done, total, counters, start, chunk, chunk_rays=None) -> None:
        if self.progress is None:
            return
        elapsed = time.perf_counter() - start
        eta = elapsed / done * (total - done) if done else None
        rays = np.zeros(len(chunk), np.int64) if chunk_rays is None else chunk_rays
        self.progress(Progress(done, total, int(counters.sum()), elapsed, eta, chunk, rays))

    def _caustics_stage(self, compiled, params, stats) -> tuple[object, float]:
        """The photon map (the render kernel is the one renders without caustics run: the
        gather is a run-time choice, kernels/caustics.py). Returns (the lights with the
        photon map, the seconds shooting photons took)."""
        from ..compile.photon_map import PhotonStats, photon_lights

        stats.photons = PhotonStats()
        lights = photon_lights(compiled, params, self.settings.caustics, self.threads,
                               lambda: self.cancel_token.cancelled, stats.photons)
        stats.warnings.extend(stats.photons.warnings)
        return lights, stats.photons.seconds

    def run(self) -> Image:
        """Render (blocking) and return the :class:`Image`; a cancelled job returns the
        tiles it finished (``state`` CANCELLED). What it raises is kept in :attr:`error`
        (``state`` FAILED) and raised. :class:`JobStateError` when run a second time."""
        if self._state is not JobState.READY:
            raise JobStateError("this render job has already run (make a new RenderJob)")
        self._state = JobState.RUNNING
        try:
            image = self._run()
        except BaseException as exc:
            self.error = exc
            self._state = JobState.FAILED
            raise
        self._state = JobState.CANCELLED if self.stats.cancelled else JobState.FINISHED
        return image

    def _run(self) -> Image:
        from ..kernels.tiles import adaptive_workspace, lane_workspace, render_tiles

        wall_start = time.perf_counter()
        stats = self.stats
        stats.compile_seconds = 0.0
        if not kernels_cached():  # a first run: the default variant (and the builders, for
            # a scene too large for their Python twins), compiled on both cores; or, for a
            # scene that runs the general kernels and is small enough for those twins (or
            # is compiled already), the general variant alone, before the scene's arrays
            # (whose light buffers then load, compiled by the helper meanwhile)
            builders = self.compiled is None and scene_needs_builders(self.scene)
            general = (kernel_variant(self.compiled) if self.compiled is not None
                       else first_variant(self.scene, builders))
            stats.compile_seconds = (warm_up_kernels(stand_in_scene(True)) if general
                                     else warm_up_kernels(builders=builders))
        compiled: CompiledScene = (self.compiled if self.compiled is not None
                                   else compile_scene(self.scene, threads=self.threads))
        stats.compile_seconds += warm_up_kernels(compiled)
        stats.build_seconds = compiled.build_seconds
        stats.warnings = list(compiled.warnings)
        stats.triangles = compiled.triangles
        params = render_params(self.scene, compiled, self.settings)
        lights = compiled.lights
        photon_seconds = 0.0
        if self.settings.caustics.photons > 0:  # the photon map (compile/photon_map.py)
            with caustics_compile():  # the first time: compiling, shown as such
                lights, photon_seconds = self._caustics_stage(compiled, params, stats)
        tiles = self.tiles
        todo = np.flatnonzero(~self.tiles_finished)  # all of them, unless resumed
        counters = np.zeros((len(tiles), N_RAY_KINDS), np.int64)
        stats.tiles_total = self.tiles_total = len(tiles)
        lanes = self.threads
        antialias = self.settings.antialias
        # uniform samples (levels -1) or adaptive anti-aliasing: a run-time choice of the
        # one render kernel (kernels/tiles.py), which warm_up_kernels loaded above
        levels = -1 if antialias is None else antialias.levels
        threshold = 0.0 if antialias is None else float(antialias.threshold)
        render_start = time.perf_counter() - photon_seconds  # shooting photons is rendering
        done = len(tiles) - len(todo)
        self.tiles_done = done
        lock = threading.Lock()
        self.rendering = True

        next_tile = 0
        most_per_call = max(1, -(-len(todo) // (64 * lanes)))  # ~64 progress updates a lane
        tile_seconds = [0.0]  # the last run's seconds a tile (0: none yet)

        def take_tiles(n: int) -> np.ndarray:
            """The next run of tiles for a lane: ``most_per_call``, or more where that would
            take less than RUN_SECONDS (the lane's Python between runs waits for the GIL
            while other lanes hold it); shorter as the image nears its end (what is left
            over twice the lanes: a quarter of it with two), so the lanes finish together
            however unevenly the work is spread over the image. (An eighth with two lanes
            made 26 runs a lane of a 1200-tile image, and its two-thread render 7 % slower.)"""
            nonlocal next_tile
            with lock:
                left = len(todo) - next_tile
                size = most_per_call
                if tile_seconds[0] > 0.0:
                    size = max(size, int(RUN_SECONDS / tile_seconds[0]))
                count = min(left, size, max(1, left // (2 * n)))
                start = next_tile
                next_tile += count
            return todo[start:start + count]

        failed = threading.Event()  # a lane raised: the others stop

        def lane_work(_lane: int, n: int) -> None:
            """A lane takes runs of tiles (in image order) until none is left, with no
            barrier between lanes, checking for cancellation and reporting progress between
            runs. Pixels do not depend on which lane renders them. A lane that fails (the
            progress callback raising, Ctrl-C in a script) stops the others at their next
            run: the error comes back without the rest of the image being rendered first."""
            try:
                render_runs(n)
            except BaseException:
                failed.set()
                raise

        def render_runs(n: int) -> None:
            nonlocal done
            work = lane_workspace(params.max_depth)
            # no tile is wider or taller than the image (tile_grid), so neither is the
            # corner memory of a lane: a 4096-pixel tile size made 400 MB per lane
            aa = (adaptive_workspace() if antialias is None
                  else adaptive_workspace(min(self.tile_size, params.width),
                                          min(self.tile_size, params.height), levels))
            while True:
                if self.cancel_token.cancelled or failed.is_set():
                    return
                idx = take_tiles(n)
                if len(idx) == 0:
                    return
                part = np.ascontiguousarray(tiles[idx])
                part_counters = np.zeros((len(idx), N_RAY_KINDS), np.int64)
                run_start = time.perf_counter()
                render_tiles(part, self.framebuffer, compiled.geometry, compiled.materials,
                             lights, params, part_counters, work, aa, threshold, levels, 0, 1)
                with lock:
                    tile_seconds[0] = (time.perf_counter() - run_start) / len(idx)
                    counters[idx] = part_counters
                    self.tiles_finished[idx] = True
                    done += len(idx)
                    self.tiles_done = done
                    self._report(done, len(tiles), counters, render_start, part,
                                 part_counters.sum(axis=1))

        pool = (ThreadPoolExecutor(lanes - 1, thread_name_prefix="whitted-lane") if lanes > 1
                else None)
        try:
            run_lanes(lane_work, lanes, pool)
        finally:
            self.rendering = False
            if pool is not None:
                pool.shutdown()
        stats.render_seconds = time.perf_counter() - render_start
        stats.tiles_done = done
        stats.cancelled = done < len(tiles)
        totals = counters.sum(axis=0)
        stats.rays = {RAY_KIND_NAMES[k]: int(totals[k]) for k in range(N_RAY_KINDS)}
        stats.wall_seconds = time.perf_counter() - wall_start
        self.image = Image(self.framebuffer, transfer=self.settings.transfer,
                           tonemap=self.settings.tonemap, meta={"stats": stats})
        return self.image


def _checked_region(region: tuple[int, int, int, int], width: int,
                    height: int) -> tuple[int, int, int, int]:
    try:
        x0, y0, x1, y1 = (_whole_number("region", v, 0, max(width, height)) for v in region)
    except (TypeError, ValueError):
        raise ArgumentError(f"region must be (x0, y0, x1, y1) in pixels, got {region!r}") \
            from None
    if not (0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height):
        raise ArgumentError(f"region ({x0}, {y0}, {x1}, {y1}) is not a part of the "
                            f"{width}x{height} image")
    return x0, y0, x1, y1


def _checked_rows(rows: tuple[int, int], height: int) -> tuple[int, int]:
    start, stop = (int(r) for r in rows)
    if not 0 <= start < stop <= height:
        raise ArgumentError(f"rows {start}:{stop} are not a range of the image's {height} rows")
    return start, stop


def render(
    scene: Scene | str | os.PathLike[str],
    *,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    **overrides: object,
) -> Image:
    """Render ``scene`` (a Scene, or the path of a scene file) and return the
    :class:`~whitted.output.Image` (float32 linear HDR).

    Keyword overrides replace render settings for this call (``width``, ``height``,
    ``samples``, ``max_depth``, ``threads``, ``seed``, ...); an unknown or bad one raises
    :class:`~whitted.errors.SceneValidationError`."""
    scene = _as_scene(scene)
    if overrides:
        scene = scene.with_settings(**overrides)
    return RenderJob(scene, progress=progress, cancel=cancel).run()


def render_aovs(scene: Scene, **overrides: object) -> dict[str, np.ndarray]:
    """Depth, normal and object-id images through the pixel centres (see the CLI's --aov)."""
    from ..kernels.tiles import lane_workspace
    from ..kernels.tiles import render_aovs as aov_kernel

    scene = _as_scene(scene)
    if overrides:
        scene = scene.with_settings(**overrides)
    if not kernels_cached():  # as RenderJob: the variant the scene runs first
        general = first_variant(scene, scene_needs_builders(scene))
        warm_up_kernels(stand_in_scene(True) if general else None)
    compiled = compile_scene(scene)
    warm_up_kernels(compiled)
    s = scene.render
    params = render_params(scene, compiled, s)
    depth = np.empty((s.height, s.width), np.float32)
    normal = np.empty((s.height, s.width, 3), np.float32)
    ids = np.empty((s.height, s.width), np.int32)
    lanes = max(1, s.threads or available_threads())

    def lane_work(lane: int, n: int) -> None:
        aov_kernel(compiled.geometry, params, depth, normal, ids, lane_workspace(0), lane, n)

    with ThreadPoolExecutor(max(1, lanes - 1)) as pool:
        run_lanes(lane_work, lanes, pool)
    return {"depth": depth, "normal": normal, "id": ids}
