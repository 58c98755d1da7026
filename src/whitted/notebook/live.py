"""A render shown live in a notebook: a progress bar, a status line, the picture filling in
as tiles finish, and a Stop button.

The render runs on its own thread (:meth:`RenderJob.start`); the notebook's thread watches it
and repaints. The render's progress callback only notes which tiles finished (a list append):
converting them to sRGB, encoding the picture and sending it to the browser happen on the
watching thread, at most :data:`MAX_RATE` times a second and, all together, never more than
:data:`BUDGET` of the time since the render began (slow encodes space the updates out), so
the view slows the render by a few per cent at most. Between updates only the rows of the
tiles finished since the last one are converted.

Stopping keeps the picture so far: the Stop button (while the kernel can hear it: in
``await whitted.render_async(...)``; a running cell holds the kernel, so a plain call stops
with the notebook's interrupt, ■ or I I) cancels the job after the tiles in flight, and the
:class:`~whitted.Image` returned holds the tiles that finished.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import threading
import time
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhittedError, shorten
from ..output.colour import encode_ldr

if TYPE_CHECKING:
    from ..output.image import Image
    from ..render.api import Progress, RenderJob

__all__ = ["BUDGET", "MAX_RATE", "LiveRender", "watch", "watch_async"]

#: Picture updates a second at most.
MAX_RATE = 4.0
#: The live picture's longest side in pixels at most: a bigger render is shown every n-th
#: pixel while it runs (the browser scales it up), so an update costs the same at any size.
PREVIEW_SIDE = 512
#: The watching thread's own work (converting, encoding, sending), all updates together,
#: takes at most this part of the time since the render began: 30 ms of updates in the first
#: second hold the next one back to 1 s. (It competes with the render's lanes for the cores
#: and the GIL: a render on one core is slowed by this part at most, on more cores by less.)
BUDGET = 0.03


def _widgets():
    import ipywidgets

    return ipywidgets


def _jpeg(pixels: np.ndarray) -> bytes:
    from PIL import Image as PILImage

    buf = io.BytesIO()
    PILImage.fromarray(pixels).save(buf, format="JPEG", quality=88)
    return buf.getvalue()


def _png(pixels: np.ndarray) -> bytes:
    from PIL import Image as PILImage

    buf = io.BytesIO()
    PILImage.fromarray(pixels).save(buf, format="PNG", compress_level=3)
    return buf.getvalue()


def _seconds(s: float) -> str:
    return f"{s:.1f} s" if s < 60 else f"{int(s // 60)} min {int(s % 60):02d} s"


class LiveRender:
    """The view of one render job: ``widget`` (an ipywidgets box) to display, :meth:`update`
    from the watching thread, :meth:`finish` at the end. ``stop``: show the Stop button."""

    def __init__(self, job: RenderJob, *, title: str = "", stop: bool = True,
                 picture: bool = True) -> None:
        w = _widgets()
        self.job = job
        s = job.settings
        self.width, self.height = s.width, s.height
        self._lock = threading.Lock()
        self._rows: list[tuple[int, int]] = []  # image rows with tiles finished, not painted
        #: every ``step``-th pixel of each row and column makes the live picture
        self.step = max(1, -(-max(self.width, self.height) // PREVIEW_SIDE))
        self._display = np.zeros((-(-self.height // self.step), -(-self.width // self.step), 3),
                                 np.uint8)
        self.updates = 0  # picture updates sent
        self.view_seconds = 0.0  # the watching thread's time in update()
        self.longest_update = 0.0  # the longest update() (seconds)
        self._next = 0.0  # perf_counter() of the next allowed picture update
        self.started = time.perf_counter()
        self.stop_requested = False
        self.compile_bar: bool | str = "auto"  # the compile bar's setting before this render
        self._eta: float | None = None  # the render's estimate of the time left
        self._expected: dict[str, float] = {}  # a first compile's expected seconds, by kind
        name = f"{title}: " if title else ""
        self.bar = w.FloatProgress(value=0.0, min=0.0, max=100.0, description="preparing",
                                   bar_style="info",
                                   layout=w.Layout(width=f"{max(self.width, 320)}px",
                                                   max_width="100%"))
        self.status = w.Label(value=f"{name}{self.width}x{self.height}")
        self.picture = w.Image(value=_jpeg(self._display), format="jpeg",
                               layout=w.Layout(width=f"{self.width}px", max_width="100%",
                                               height="auto"))
        self.stop_button = w.Button(description="Stop", icon="stop", button_style="danger",
                                    tooltip="Stop the render after the tiles in flight; "
                                            "the picture so far is kept")
        self.stop_button.on_click(lambda _button: self.request_stop())
        self.title = name
        #: said after the progress while it runs (how to stop it when there is no button)
        self.hint = "" if stop else ": interrupt the kernel (■) to stop, keeping the picture"
        children = [w.HBox([self.bar, self.stop_button] if stop else [self.bar]), self.status]
        if picture:
            children.append(self.picture)
        self.widget = _Box(children, self)

    # ------------------------------------------------------------------ from the render
    def progress(self, p: Progress) -> None:
        """The render's progress callback (on its lanes' threads): note the rows to paint."""
        self._eta = p.eta
        tiles = p.new_tiles
        if len(tiles):
            with self._lock:
                self._rows.append((int(tiles[:, 1].min()), int(tiles[:, 3].max())))

    def request_stop(self) -> None:
        self.stop_requested = True
        self.job.cancel()
        self.stop_button.disabled = True
        self.stop_button.description = "Stopping"

    # ------------------------------------------------------------------ on the watcher
    def wait_seconds(self) -> float:
        """How long the watcher sleeps before its next :meth:`update`."""
        return max(0.02, self._next - time.perf_counter())

    def update(self) -> None:
        """Progress and status now; the picture when the rate and the budget allow."""
        now = time.perf_counter()
        if now < self._next:
            return
        job = self.job
        elapsed = now - self.started
        if job.tiles_total == 0:  # compiling the kernels or the scene, or shooting photons
            from ..render.warm_up import compile_label, compile_progress

            fraction = compile_progress()
            if fraction is not None:
                label = compile_label()
                if label not in self._expected:
                    from ..jit.progress import expected_seconds

                    self._expected[label] = expected_seconds(label)
                self.bar.description = "compiling"
                self.bar.value = 100.0 * fraction
                self.status.value = (f"{self.title}compiling {label} (the first render only, "
                                     f"kept for later ones; about "
                                     f"{_seconds(self._expected[label])}): {_seconds(elapsed)}")
            else:
                self.status.value = f"{self.title}preparing the scene: {_seconds(elapsed)}"
        else:
            self.bar.description = "rendering"
            fraction = job.fraction
            self.bar.value = 100.0 * fraction
            left = f", {_seconds(self._eta)} left" if self._eta and fraction < 1 else ""
            self.status.value = (f"{self.title}{self.width}x{self.height}: "
                                 f"{100 * fraction:.0f} % ({job.tiles_done}/{job.tiles_total} "
                                 f"tiles), {_seconds(elapsed)}{left}{self.hint}")
            self._paint()
        spent = time.perf_counter() - now
        self.view_seconds += spent
        self.longest_update = max(self.longest_update, spent)
        self._next = max(now + 1.0 / MAX_RATE, self.started + self.view_seconds / BUDGET)

    def _paint(self, final: bool = False) -> None:
        with self._lock:
            rows, self._rows = self._rows, []
        if not rows and not final:
            return
        job = self.job
        if final:
            self.picture.format = "png"
            self.picture.value = _png(job.srgb())
            self.updates += 1
            return
        if rows:
            n = self.step
            top = min(r[0] for r in rows) // n  # preview rows
            bottom = -(-max(r[1] for r in rows) // n)
            s = job.settings
            self._display[top:bottom] = encode_ldr(
                job.framebuffer[top * n:bottom * n:n, ::n], bits=8, transfer=s.transfer,
                tonemap=s.tonemap)
        self.picture.value = _jpeg(self._display)
        self.updates += 1

    def finish(self, keep_picture: bool = False) -> None:
        """The end: the bar and the status say how the job ended; the picture (and the Stop
        button) go, since the :class:`~whitted.Image` returned shows itself, unless
        ``keep_picture``."""
        job = self.job
        stats = job.stats
        self.stop_button.layout.display = "none"
        if job.failed:
            self.bar.bar_style = "danger"
            self.bar.description = "failed"
            error = job.error
            text = str(error) if isinstance(error, WhittedError) else (
                f"{type(error).__name__}: {error}")
            self.status.value = shorten(f"{self.title}{text}", 300)
        elif job.cancelled:
            self.bar.bar_style = "warning"
            self.bar.description = "stopped"
            self.bar.value = 100.0 * job.fraction
            self.status.value = (f"{self.title}stopped at {100 * job.fraction:.0f} % "
                                 f"({stats.tiles_done}/{stats.tiles_total} tiles): the "
                                 "picture keeps the tiles that finished")
        else:
            self.bar.bar_style = "success"
            self.bar.description = "done"
            self.bar.value = 100.0
            self.status.value = f"{self.title}{stats.summary()}"
        if keep_picture and not job.failed:
            self._paint(final=True)
        else:
            self.widget.children = self.widget.children[:2]


class _Box:
    """Made on first use: ipywidgets' VBox with a one-line text form (what a frontend that
    shows no widgets prints)."""

    def __new__(cls, children, view: LiveRender):
        w = _widgets()

        class RenderBox(w.VBox):
            def __repr__(self) -> str:
                return f"whitted render: {view.status.value}"

        box = RenderBox(children)
        box.view = view  # the LiveRender behind it (its counters: updates, view_seconds)
        return box


def _start(job: RenderJob, view: LiveRender) -> None:
    """Start ``job`` with ``view`` noting its tiles; the view shows a first compile, so the
    compile's own bar (jit/progress.py) is off until :func:`_end`."""
    from ..jit.progress import compile_bar_setting, show_compile_bar

    view.compile_bar = compile_bar_setting()
    show_compile_bar(False)
    user = job.progress

    def both(p: Progress) -> None:
        view.progress(p)
        if user is not None:
            user(p)

    job.progress = both
    job.start()


def _end(job: RenderJob, view: LiveRender, keep_picture: bool) -> Image:
    from ..jit.progress import show_compile_bar

    show_compile_bar(view.compile_bar)
    view.finish(keep_picture=keep_picture)
    if job.failed:
        raise job.error  # type: ignore[misc]
    return job.image  # type: ignore[return-value]


def watch(job: RenderJob, view: LiveRender, *, keep_picture: bool = False) -> Image:
    """Run ``job`` on its thread and keep ``view`` current until it ends (blocking). The
    notebook's interrupt stops the render and keeps the picture so far (a second interrupt
    returns at once, leaving the job to end on its own)."""
    _start(job, view)
    try:
        while not job.join(view.wait_seconds()):
            view.update()
    except KeyboardInterrupt:
        view.request_stop()
        view.status.value = f"{view.title}stopping after the tiles in flight"
        with contextlib.suppress(KeyboardInterrupt):
            job.join()
    return _end(job, view, keep_picture)


async def watch_async(job: RenderJob, view: LiveRender, *, keep_picture: bool = False) -> Image:
    """:func:`watch` as a coroutine: the kernel hears the Stop button while it waits."""
    _start(job, view)
    try:
        while not job.join(0):
            await asyncio.sleep(view.wait_seconds())
            view.update()
    except asyncio.CancelledError:
        from ..jit.progress import show_compile_bar

        job.cancel()
        show_compile_bar(view.compile_bar)
        raise
    return _end(job, view, keep_picture)
