"""The editor's "Render animation…": :func:`whitted.animation.film.render_film` (what
``whitted animate SCENE -o FILM`` runs) on a background thread of the editor, with progress
the timeline polls (no Qt here).

The frames go where ``whitted animate`` puts them (``FILM_frames/0000.png`` …, the same names,
the same PNGs with the hash of what each shows), so the editor and the command resume each
other's films: a frame already on disk from the same scene and settings is kept. Stopping
keeps every finished frame. The film is encoded once every frame is there."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..animation.film import FilmPlan, FilmProgress, prepare_film, render_film
from ..render.api import CancelToken
from ..scene import Scene

__all__ = ["FilmJob"]


@dataclass
class FilmJob:
    """Render every frame of ``scene`` (read from its file: the film shows what was saved)
    and encode ``output`` (.mp4 or .gif). Fields are written by the job's thread and read by
    the editor's timer: plain numbers and strings only."""

    scene: Scene
    output: Path
    threads: int | None = None
    cancel: CancelToken = field(default_factory=CancelToken)
    total: int = 0
    done: int = 0  # frames finished (rendered or kept)
    kept: int = 0  # of those, already on disk
    frame: int | None = None  # the frame rendering now
    frame_fraction: float = 0.0  # of the frame rendering now
    encoding: bool = False
    finished: bool = False
    stopped: bool = False
    error: str | None = None
    render_seconds: float = 0.0
    rendered: int = 0
    started: float = 0.0
    seconds: float = 0.0
    frames_dir: Path | None = None
    _plan: FilmPlan | None = field(default=None, repr=False)
    _thread: threading.Thread | None = field(default=None, repr=False)

    def start(self) -> None:
        """Check the film (one-line :class:`~whitted.WhittedError` or ValueError: nothing is
        written), then render it on a thread of its own."""
        plan = prepare_film(self.scene, Path(self.output))
        if plan.paths.film is None:
            raise ValueError(f"{self.output}: a film is .mp4 or .gif")
        self._plan, self.frames_dir = plan, plan.paths.frames
        self.total = len(plan.frames)
        self.started = time.perf_counter()
        self._thread = threading.Thread(target=self._run, name="whitted-film", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop after the tiles in flight; the frame being rendered is not written."""
        self.cancel.cancel()

    def join(self, timeout: float | None = None) -> None:
        if self._thread is not None:
            self._thread.join(timeout)

    @property
    def running(self) -> bool:
        return self._thread is not None and not self.finished

    @property
    def fraction(self) -> float:
        """Of the whole film, counting the frame in progress."""
        if self.total <= 0:
            return 0.0
        return min(1.0, (self.done + (self.frame_fraction if self.frame is not None else 0))
                   / self.total)

    @property
    def eta(self) -> float | None:
        """Seconds left, from the frames rendered so far (None before the first)."""
        if self.rendered == 0:
            return None
        per_frame = self.render_seconds / self.rendered
        return per_frame * (self.total - self.done - self.frame_fraction)

    def _progress(self, p: FilmProgress) -> None:
        if p.event == "frame":
            self.frame, self.frame_fraction = p.frame, 0.0
        elif p.event == "tiles" and p.tiles is not None:
            self.frame_fraction = p.tiles.fraction
        elif p.event == "done" and p.result is not None:
            if p.result.rendered:
                self.rendered += 1
                self.render_seconds += p.result.seconds
            else:
                self.kept += 1
            self.done, self.frame, self.frame_fraction = p.done, None, 0.0
        elif p.event == "encoding":
            self.frame = None
            self.encoding = True

    def _run(self) -> None:
        try:
            assert self._plan is not None
            result = render_film(self.scene, self._plan, threads=self.threads,
                                 progress=self._progress, cancel=self.cancel)
            self.frame = None
            self.stopped = result.cancelled
        except Exception as exc:  # shown to the user in one line; the frames done stay
            text = str(exc).strip().splitlines()
            self.error = text[0] if text else type(exc).__name__
        finally:
            self.seconds = time.perf_counter() - self.started
            self.finished = True
