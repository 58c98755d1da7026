"""Long work (a film, a sweep, a Stefan run) watched from a notebook: the work runs on a
thread of its own with a :class:`~whitted.CancelToken`; the notebook's thread shows its
progress (a bar, a line, a picture), a few times a second, and the notebook's interrupt
cancels the work at its next safe point, keeping what it finished."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from ..errors import WhittedError, shorten

__all__ = ["TaskView", "run_in_view", "run_watched"]

#: Seconds between two updates of a task's view.
INTERVAL = 0.25


class TaskView:
    """A bar (0..100 %), a status line and, when ``picture``, an image: ``widget`` to show.
    The work's thread sets :attr:`fraction`, :attr:`text` and :attr:`png`; :meth:`update`
    (the notebook's thread) sends what changed."""

    def __init__(self, title: str, *, picture: bool = False) -> None:
        import ipywidgets as w

        self.title = title
        self.fraction = 0.0
        self.text = ""
        self.png: bytes | None = None
        self._sent_png: bytes | None = None
        self.bar = w.FloatProgress(value=0.0, min=0.0, max=100.0, description=title,
                                   bar_style="info", layout=w.Layout(width="420px",
                                                                     max_width="100%"))
        self.status = w.Label(value="starting")
        self.picture = w.Image(format="png", layout=w.Layout(max_width="100%", height="auto"))
        children = [self.bar, self.status] + ([self.picture] if picture else [])
        view = self

        class TaskBox(w.VBox):
            def __repr__(self) -> str:
                return f"{view.title}: {view.status.value}"

        self.widget = TaskBox(children)

    def update(self) -> None:
        self.bar.value = 100.0 * min(1.0, max(0.0, self.fraction))
        if self.text:
            self.status.value = self.text
        png = self.png
        if png is not None and png is not self._sent_png:
            self.picture.value = png
            self._sent_png = png

    def end(self, text: str, style: str, fraction: float | None = None) -> None:
        if fraction is not None:
            self.fraction = fraction
        self.text = text
        self.update()
        self.bar.bar_style = style
        self.bar.description = {"success": "done", "warning": "stopped",
                                "danger": "failed"}.get(style, self.title)

    def fail(self, error: BaseException) -> None:
        text = str(error) if isinstance(error, WhittedError) else (
            f"{type(error).__name__}: {error}")
        self.end(shorten(text, 300), "danger")


def run_watched(work: Callable[[], Any], view: TaskView | None, cancel: Any) -> Any:
    """Run ``work()`` on a thread; while it runs, update ``view`` (if any) every
    :data:`INTERVAL` seconds. The notebook's interrupt sets ``cancel`` (the work stops at its
    next safe point and returns what it finished); a second one returns at once (None),
    leaving the work to stop on its own. ``work``'s error is raised here."""
    box: dict[str, Any] = {}
    ended = threading.Event()  # waited on, not Thread.join: an interrupt in it is harmless

    def target() -> None:
        try:
            box["value"] = work()
        except BaseException as exc:  # noqa: BLE001 - raised on the notebook's thread
            box["error"] = exc
        finally:
            ended.set()

    threading.Thread(target=target, name="whitted-task", daemon=True).start()
    try:
        while not ended.wait(INTERVAL):
            if view is not None:
                view.update()
        if view is not None:
            view.update()
    except KeyboardInterrupt:
        cancel.cancel()
        if view is not None:
            view.status.value = "stopping at the next safe point"
        try:
            ended.wait()
        except KeyboardInterrupt:
            return None
    if "error" in box:
        raise box["error"]
    return box.get("value")


def run_in_view(work: Callable[[], Any], view: TaskView | None, cancel: Any) -> Any:
    """``work()`` here when there is no view; else watched by ``view`` (:func:`run_watched`),
    which is told of a failure before it is raised."""
    if view is None:
        return work()
    try:
        return run_watched(work, view, cancel)
    except BaseException as exc:
        view.fail(exc)
        raise
