"""Full renders and the interactive preview, both through :class:`whitted.RenderJob` on its
own background threads (the kernels release the GIL, so the event loop keeps running). The
controller polls the job's framebuffer from a QTimer on the UI thread: no Qt object is touched
from a render thread."""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QImage

from ..compile.scene import compile_scene  # built here once, reused by the previews of a drag
from ..output.colour import encode_ldr
from ..output.image import Image
from ..render.api import Progress, RenderJob, available_threads, warm_up_kernels
from ..scene import Scene
from .render_eta import CostClock, CostMap

POLL_MS = 15
BACKDROP_DIM = 0.6  # the preview under unrendered tiles, dimmed so the finished ones stand out
#: preview pixel budget: starts here, adapts so that a preview takes about PREVIEW_TARGET_S
PREVIEW_PIXELS = 160 * 120
PREVIEW_MIN_PIXELS, PREVIEW_MAX_PIXELS = 64 * 48, 480 * 360
PREVIEW_TARGET_S = 0.15
#: while the user drags (orbit, slider, G/R/S) a preview aims at this, for >= 10 updates/s
INTERACTIVE_TARGET_S = 0.04
REFINE_FACTOR = 4  # each idle refinement step has this many times the pixels
PREVIEW_DEPTH = 2
PREVIEW_SHADOW_SAMPLES = 4
PREVIEW_PHOTONS = 20_000  # caustic photons per pass of a preview


def qimage_of(rgb: np.ndarray) -> QImage:
    """A QImage (owning its memory) with the pixels of an (H, W, 3) uint8 array."""
    h, w, _ = rgb.shape
    image = QImage(w, h, QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.bits(), np.uint8).reshape(h, image.bytesPerLine())
    rows[:, : 3 * w] = rgb.reshape(h, 3 * w)
    return image


def to_qimage(pixels: np.ndarray, transfer: str, tonemap: str) -> QImage:
    """Display values of a linear float framebuffer."""
    return qimage_of(Image(pixels, transfer=transfer, tonemap=tonemap).to_srgb8())


def preview_scene(scene: Scene, pixels: int) -> Scene:
    """The scene at low resolution (same aspect ratio), shallow depth, one sample."""
    s = scene.render
    scale = min(1.0, math.sqrt(pixels / (s.width * s.height)))
    width = max(1, round(s.width * scale))
    height = max(1, round(s.height * scale))
    # caustics with fewer photons (their default radius grows to match): the same light
    caustics = s.caustics.model_copy(update={"photons": min(s.caustics.photons,
                                                            PREVIEW_PHOTONS)})
    return scene.with_settings(width=width, height=height, samples=1,
                               max_depth=min(s.max_depth, PREVIEW_DEPTH),
                               shadow_samples=min(s.shadow_samples, PREVIEW_SHADOW_SAMPLES),
                               caustics=caustics)


@dataclass
class _Active:
    job: RenderJob
    kind: str  # "preview" or "render"
    started: float
    scene: Scene
    pixels: int = 0  # a preview's pixel budget
    refining: bool = False  # an idle refinement step (not a first look at an edit)
    reused: bool = False  # the compiled geometry of an earlier preview was reused
    thread: threading.Thread | None = None  # a preview's own thread

    @property
    def running(self) -> bool:
        if self.thread is not None:
            return self.thread.is_alive()
        return self.job.running
    latest: Progress | None = None
    shown_tiles: int = -1
    first_pixels: float | None = None
    #: tiles finished since the last poll (appended by the render threads)
    new_tiles: deque = field(default_factory=deque)
    display: np.ndarray | None = None  # uint8 display values, updated tile by tile
    backdrop: np.ndarray | None = None  # shown where no tile has arrived yet (the preview)
    cost: CostMap | None = None  # a preview's: what each part of the picture cost
    clock: CostClock | None = None  # a render's: the time left from the tiles' cost

    def on_progress(self, p: Progress) -> None:
        """Called on a render thread: only plain stores, a deque append and a sum."""
        self.new_tiles.append(p.new_tiles)
        if self.clock is not None:
            self.clock.done(p.new_tiles)
        self.latest = p

    def on_preview_progress(self, p: Progress) -> None:
        """Called on a preview's thread: the rays each part of the picture cost."""
        self.cost.learn(p.new_tiles, p.rays, p.tile_rays)

    def display_image(self) -> QImage:
        """The display picture: the dimmed preview (or black) where no tile has arrived yet,
        re-encoding only the tiles finished since the last call."""
        job = self.job
        s = job.settings
        fb = job.framebuffer
        if self.display is None:
            fits = self.backdrop is not None and self.backdrop.shape == fb.shape
            self.display = self.backdrop.copy() if fits else np.zeros(fb.shape, np.uint8)
        while self.new_tiles:
            for x0, y0, x1, y1 in self.new_tiles.popleft():
                self.display[y0:y1, x0:x1] = encode_ldr(fb[y0:y1, x0:x1], transfer=s.transfer,
                                                        tonemap=s.tonemap)
        return qimage_of(self.display)


class RenderController(QObject):
    """``frame(QImage, kind)``: a new picture to show; ``progress(fraction, eta, text)``;
    ``started(kind)``; ``finished(kind, text)``; ``failed(kind, message)``."""

    frame = Signal(QImage, str)
    progress = Signal(float, object, str)
    started = Signal(str)
    finished = Signal(str, str)
    failed = Signal(str, str)
    kernels_ready = Signal(float)
    #: while the first run compiles the kernels: (fraction done, seconds left or None)
    kernels_progress = Signal(float, object)

    def __init__(self, parent=None, *, preview_delay_ms: int = 30) -> None:
        super().__init__(parent)
        self.full: _Active | None = None
        self.preview: _Active | None = None
        self.preview_pixels = PREVIEW_PIXELS
        self.preview_enabled = True
        self.last_image: Image | None = None  # the last full render, partial if stopped
        self.last_preview: Image | None = None
        self.previews_done = 0
        self.last_preview_seconds: float | None = None
        #: (scene, CostMap) of the last full preview: a render of that scene says its time
        #: left from what each part of the picture cost
        self.cost_map: tuple[Scene, CostMap] | None = None
        #: the user is dragging: coarse previews, no refinement until it stops
        self.interacting = False
        #: pixels of a preview at full viewport size (the refinement's goal)
        self.target_pixels = PREVIEW_MAX_PIXELS
        self.interactive_pixels = PREVIEW_PIXELS // 2
        self._requested_at: float | None = None
        #: measurements: edit -> first picture, last edit -> full-size picture (seconds)
        self.edit_to_frame: list[float] = []
        self.edit_to_full: list[float] = []
        self.first_pixels_seconds: float | None = None
        self._pending: Scene | None = None
        self._poll = QTimer(self)
        self._poll.setInterval(POLL_MS)
        self._poll.timeout.connect(self._tick)
        self._throttle = QTimer(self)
        self._throttle.setSingleShot(True)
        self._throttle.setInterval(preview_delay_ms)
        self._throttle.timeout.connect(self._start_preview)
        self._shown: _Active | None = None  # the preview on screen
        self._compiled: tuple | None = None  # (geometry key, CompiledScene) of a preview
        self._warm = threading.Event()
        self._warm_seconds = 0.0
        self._warm_started = time.perf_counter()

    # ------------------------------------------------------------------ kernels

    def warm_up(self) -> None:
        """Compile or load the kernels on a background thread (the first render waits)."""
        self._warm_started = time.perf_counter()

        def work() -> None:
            from ..jit.cache import prepare

            try:
                self._kernel_cache = prepare()  # (what the warm-up uses: it says who waits)
            except Exception:  # noqa: BLE001 - the warm-up reports a broken cache itself
                self._kernel_cache = None
            self._warm_seconds = warm_up_kernels()
            self._warm.set()

        threading.Thread(target=work, name="whitted-warm-up", daemon=True).start()
        self._poll.start()

    @property
    def kernels_loaded(self) -> bool:
        return self._warm.is_set()

    def warm_up_text(self) -> str:
        """What the picture says while the kernels load: how far a first compile is, that
        another whitted process is compiling them (this one waits, then loads its work), or
        how long the loading has taken."""
        from ..render.warm_up import compile_label, compile_progress

        elapsed = time.perf_counter() - getattr(self, "_warm_started", time.perf_counter())
        fraction = compile_progress()
        if fraction is not None:
            left = (f", about {elapsed * (1 - fraction) / fraction:.0f} s left"
                    if fraction > 0.02 else "")
            return (f"Compiling {compile_label()} (the first run only): {fraction:.0%}, "
                    f"{elapsed:.0f} s{left}")
        cache = getattr(self, "_kernel_cache", None)
        if cache is not None:
            try:
                busy = cache.others_compiling()
            except Exception:  # noqa: BLE001 - only a caption
                busy = False
            if busy:
                return ("Waiting for another whitted process, which is compiling the render "
                        f"kernels ({elapsed:.0f} s); this one then loads them…")
        return "Loading the render kernels…" + (f" {elapsed:.0f} s" if elapsed >= 1 else "")

    # ------------------------------------------------------------------ full renders

    @property
    def rendering(self) -> bool:
        return self.full is not None

    def render(self, scene: Scene) -> RenderJob:
        """Start a full render of ``scene``; the running preview (if any) is dropped."""
        self.stop()
        self._cancel_preview()
        self._pending = None
        active = _Active(RenderJob(scene, progress=None), "render", time.perf_counter(), scene)
        active.backdrop = self._backdrop(scene)
        learnt = self.cost_map
        if learnt is not None and learnt[0] == scene:  # the preview of this very picture
            s = scene.render
            active.clock = CostClock(learnt[1].scaled(s.width, s.height))
        active.job.progress = active.on_progress
        self.full = active
        self.first_pixels_seconds = None
        active.job.start()
        self._poll.start()
        self.started.emit("render")
        return active.job

    def _backdrop(self, scene: Scene) -> np.ndarray | None:
        """The last preview scaled to the render's size and dimmed, to show under the tiles
        a render has not reached yet (None before any preview). A preview seen through
        another camera (the user's own view) is not shown under the camera's tiles: a quick
        small preview through the render's camera is made instead."""
        preview = self.last_preview
        if preview is None:
            return None
        shown = self._shown.scene if self._shown is not None else None
        if shown is None or shown.camera != scene.camera:
            preview = self._quick_preview(scene)
            if preview is None:
                return None
        s = scene.render
        small = encode_ldr(preview.pixels, transfer=s.transfer, tonemap=s.tonemap)
        ys = np.arange(s.height) * small.shape[0] // s.height
        xs = np.arange(s.width) * small.shape[1] // s.width
        return (small[ys][:, xs] * BACKDROP_DIM).astype(np.uint8)

    def _quick_preview(self, scene: Scene) -> Image | None:
        """A small preview of ``scene`` made now (a few milliseconds: the compiled geometry
        of the previews is reused when only the camera differs)."""
        try:
            small = preview_scene(scene, min(self.interactive_pixels, 160 * 120))
            key = _geometry_key(small)
            cached = self._compiled
            compiled = cached[1] if cached is not None and cached[0] == key else \
                compile_scene(small, light_buffers=False)
            job = RenderJob(small)
            job.compiled = compiled
            job.run()
            return job.image
        except Exception:  # noqa: BLE001 - a backdrop only: the render shows the error
            return None

    def stop(self) -> None:
        """Stop the full render after the tiles in flight; the picture so far is kept."""
        if self.full is not None:
            self.full.job.cancel()

    # ------------------------------------------------------------------ preview

    def request_preview(self, scene: Scene) -> None:
        """Preview ``scene`` soon (edits in quick succession coalesce into one preview)."""
        if not self.preview_enabled:
            return
        if self._pending is None and self._requested_at is None:
            self._requested_at = time.perf_counter()
        self._last_edit = time.perf_counter()
        self._pending = scene
        if not self._throttle.isActive():
            self._throttle.start()

    def _start_preview(self) -> None:
        scene, self._pending = self._pending, None
        if scene is None:
            return
        if self.full is not None:
            if self.full.job.cancel_token.cancelled:  # stopping: preview once it has
                self._pending = scene
                self._throttle.start()
            return
        if self.preview is not None and not self.preview.refining \
                and self.preview.running:
            # a preview of an earlier edit is nearly there: show it, then this one (cancelling
            # it would show nothing at all while edits come faster than previews)
            self._pending = scene
            return
        self._cancel_preview()
        pixels = self.interactive_pixels if self.interacting else self.preview_pixels
        # never more pixels than the picture shows on screen: on a fast machine the adaptive
        # budget grows past it, and a drag would then show more than the idle refinement
        pixels = min(pixels, self.target_pixels)
        self._start_preview_job(scene, pixels, refining=False)

    def _start_preview_job(self, scene: Scene, pixels: int, *, refining: bool) -> None:
        """A preview on its own thread. The compiled geometry is reused while only the
        camera or the resolution changes (an orbit, a refinement): building it is most of a
        small preview's time."""
        small = preview_scene(scene, pixels)
        job = RenderJob(small)
        active = _Active(job, "preview", time.perf_counter(), scene, pixels=pixels,
                         refining=refining)
        active.cost = CostMap(small.render.width, small.render.height)
        job.progress = active.on_preview_progress
        key = _geometry_key(small)
        cached = self._compiled[1] if self._compiled is not None and \
            self._compiled[0] == key else None
        active.reused = cached is not None

        def work() -> None:
            try:
                compiled = cached
                if compiled is None:
                    # no light buffers: the same picture, and most of a preview's build
                    # time saved (135 -> 24 ms for the default scene) while an object moves
                    compiled = compile_scene(small, light_buffers=False)
                    self._compiled = (key, compiled)  # one store: read on the UI thread
                job.compiled = compiled
                job.run()
            except BaseException as exc:  # noqa: BLE001 - reported by _preview_done
                job.error = exc

        active.thread = threading.Thread(target=work, name="whitted-preview", daemon=True)
        self.preview = active
        active.thread.start()
        self._poll.start()

    def set_interacting(self, on: bool) -> None:
        """A drag started (coarse, fast previews) or ended (refine to full size)."""
        self.interacting = on
        if not on and self.preview is None and self._pending is None \
                and self._shown is not None:
            self._refine(self._shown)

    def _refine(self, done: _Active) -> None:
        """The next, larger preview of the same scene, while nothing else is asked for."""
        if self.interacting or self._pending is not None or self.full is not None \
                or not self.preview_enabled:
            return
        s = done.scene.render
        goal = min(self.target_pixels, s.width * s.height)
        if done.job.settings.width * done.job.settings.height >= goal * 0.98:
            return
        self._start_preview_job(done.scene, min(goal, done.pixels * REFINE_FACTOR),
                                refining=True)

    def _cancel_preview(self) -> None:
        if self.preview is not None:
            self.preview.job.cancel()
            self.preview = None

    # ------------------------------------------------------------------ polling

    def _tick(self) -> None:
        if not self._warm.is_set():
            self._compile_tick()
        if self._warm.is_set() and self._warm_seconds >= 0:
            self.kernels_ready.emit(self._warm_seconds)
            self._warm_seconds = -1.0
        if self.preview is not None and not self.preview.running:
            self._preview_done(self.preview)
            if self._pending is not None and self.preview is None:
                self._start_preview()  # the edits that came in meanwhile, at once
        if self.full is not None:
            self._full_tick(self.full)
        if self.full is None and self.preview is None and self._warm_seconds < 0:
            self._poll.stop()

    def _compile_tick(self) -> None:
        """A first compile's progress (render/warm_up.py), with the time left at its pace."""
        from ..render.warm_up import compile_progress

        fraction = compile_progress()
        if fraction is None:
            return
        elapsed = time.perf_counter() - self._warm_started
        left = elapsed * (1 - fraction) / fraction if fraction > 0.02 else None
        self.kernels_progress.emit(fraction, left)

    def _preview_done(self, active: _Active) -> None:
        self.preview = None
        job = active.job
        if job.error is not None:
            self.failed.emit("preview", _one_line(job.error))
            return
        if job.cancel_token.cancelled or job.image is None:
            return
        now = time.perf_counter()
        seconds = now - active.started
        render_seconds = job.stats.render_seconds + (0.0 if active.reused else
                                                     job.stats.build_seconds)
        if job.stats.compile_seconds == 0 and not active.refining:
            # adapt the resolution to the time it took (the dragging budget separately)
            target = INTERACTIVE_TARGET_S if self.interacting else PREVIEW_TARGET_S
            ratio = min(max(target / max(render_seconds, 1e-3), 0.5), 2.0)
            if self.interacting:
                self.interactive_pixels = int(np.clip(self.interactive_pixels * ratio,
                                                      PREVIEW_MIN_PIXELS, PREVIEW_MAX_PIXELS))
            else:
                self.preview_pixels = int(np.clip(self.preview_pixels * ratio,
                                                  PREVIEW_MIN_PIXELS, PREVIEW_MAX_PIXELS))
        if self._requested_at is not None:
            self.edit_to_frame.append(now - self._requested_at)
            self._requested_at = None
        s0 = active.scene.render
        full = job.settings.width * job.settings.height >= 0.98 * min(
            self.target_pixels, s0.width * s0.height)
        if full and active.refining and getattr(self, "_last_edit", None) is not None:
            self.edit_to_full.append(now - self._last_edit)
        self.last_preview = job.image
        if active.cost is not None and active.cost.complete:
            self.cost_map = (active.scene, active.cost)  # for a render's time left
        self.last_preview_seconds = seconds
        self.previews_done += 1
        s = job.settings
        self._shown = active
        self.frame.emit(to_qimage(job.framebuffer, s.transfer, s.tonemap), "preview")
        self._refine(active)

    def _full_tick(self, active: _Active) -> None:
        job = active.job
        p = active.latest
        if p is not None and p.tiles_done != active.shown_tiles:
            active.shown_tiles = p.tiles_done
            if active.first_pixels is None:
                active.first_pixels = time.perf_counter() - active.started
                self.first_pixels_seconds = active.first_pixels
            self.frame.emit(active.display_image(), "render")
            if active.clock is not None:  # from the tiles' cost, not their count
                eta = active.clock.eta(p.elapsed)
                fraction = min(active.clock.fraction, 1.0)
            else:
                eta, fraction = p.eta, p.fraction
            self.progress.emit(fraction, eta, _progress_text(p, fraction, eta))
        if job.running:
            return
        self.full = None
        if job.error is not None:
            self.failed.emit("render", _one_line(job.error))
            return
        image = job.image
        self.last_image = image
        stats = job.stats
        if image is not None:
            self.frame.emit(active.display_image(), "render")
        if stats.cancelled:
            text = f"Stopped: kept {stats.tiles_done}/{stats.tiles_total} tiles"
        else:
            text = (f"Rendered {stats.width}×{stats.height} in {stats.render_seconds:.2f} s "
                    f"({stats.total_rays:,} rays, {stats.threads} threads)")
        self.progress.emit(stats.tiles_done / max(stats.tiles_total, 1), None, text)
        self.finished.emit("render", text)

    def shutdown(self, timeout: float = 5.0) -> None:
        """Cancel everything and wait for the render threads (closing the window)."""
        self._throttle.stop()
        self._poll.stop()
        active = [a for a in (self.full, self.preview) if a is not None]
        for a in active:
            a.job.cancel()
        for a in active:
            if a.thread is not None:
                a.thread.join(timeout)
            a.job.join(timeout)
        self.full = self.preview = None


def _geometry_key(scene: Scene) -> tuple:
    """What the compiled geometry depends on (not the camera, nor the image size)."""
    return (scene.objects, scene.materials, scene.lights, scene.render.shadow_samples,
            scene.base_dir)


def _progress_text(p: Progress, fraction: float, eta: float | None) -> str:
    left = "" if eta is None else f", {_duration(eta)} left"
    return f"{fraction:.0%} ({p.tiles_done}/{p.tiles_total} tiles){left}"


def _duration(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.0f} s"
    return f"{int(seconds // 60)} min {int(seconds % 60):02d} s"


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


__all__ = ["RenderController", "available_threads", "preview_scene", "to_qimage"]
