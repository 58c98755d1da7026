"""Pointing at objects in the picture: the renderer's object-id image (``render_aovs``) of
the current scene, computed on a background thread at about the picture's size, answers
"which object is at (u, v)" and draws the selected object's outline."""

from __future__ import annotations

import contextlib
import threading

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QImage

from ..render.api import render_aovs
from ..scene import Scene

OUTLINE_RGBA = (255, 150, 20, 255)
MAX_SIDE = 480  # pixels of the id image's longer side


def id_size(scene: Scene, max_side: int = MAX_SIDE) -> tuple[int, int]:
    w, h = scene.render.width, scene.render.height
    scale = min(1.0, max_side / max(w, h))
    return max(1, round(w * scale)), max(1, round(h * scale))


#: one id image at a time in this process: the picture's and a CSG child's buffers (and the
#: warm-up) never load or run the id kernel at once on two threads
_ID_LOCK = threading.Lock()


def object_ids(scene: Scene, width: int, height: int) -> np.ndarray:
    """(height, width) int32: the index in ``scene.objects`` seen through each pixel's
    centre, -1 where no object is."""
    with _ID_LOCK:
        return render_aovs(scene, width=width, height=height, samples=1)["id"]


def id_at(ids: np.ndarray, u: float, v: float) -> int:
    h, w = ids.shape
    x = min(max(int(u * w), 0), w - 1)
    y = min(max(int(v * h), 0), h - 1)
    return int(ids[y, x])


def solo_child(scene: Scene, key: tuple) -> Scene:
    """``scene`` with the CSG object of ``key`` = ("objects", i, k, ...) replaced by its
    descendant at ``key`` alone, in the same place (inside a one-child union carrying each
    ancestor's transform): the id image of this scene outlines that child itself."""
    from ..scene.shapes import CSG

    chain = [scene.objects[key[1]]]
    for k in key[2:]:
        chain.append(chain[-1].objects[k])
    node = chain[-1]
    for ancestor in reversed(chain[:-1]):
        node = CSG(operation="union", objects=[node], transform=ancestor.transform)
    objects = list(scene.objects)
    objects[key[1]] = node
    return scene.model_copy(update={"objects": objects})


def outline_mask(ids: np.ndarray, index) -> np.ndarray:
    """Where object ``index`` (or any of a list of indices) is seen."""
    if isinstance(index, int):
        return ids == index
    return np.isin(ids, np.atleast_1d(np.asarray(index, np.int64)))


def outline_image(ids: np.ndarray, index, thickness: int = 1, *,
                  mask: np.ndarray | None = None) -> QImage | None:
    """A transparent image with the outline of object ``index`` (or of each object of a
    list of indices, or of ``mask``; None if none is seen)."""
    mask = outline_mask(ids, index) if mask is None else mask
    if not mask.any():
        return None
    inner = mask.copy()
    for _ in range(thickness):
        shrunk = inner.copy()
        shrunk[1:, :] &= inner[:-1, :]
        shrunk[:-1, :] &= inner[1:, :]
        shrunk[:, 1:] &= inner[:, :-1]
        shrunk[:, :-1] &= inner[:, 1:]
        inner = shrunk
    edge = mask & ~inner
    h, w = ids.shape
    rgba = np.zeros((h, w, 4), np.uint8)
    rgba[edge] = OUTLINE_RGBA
    image = QImage(w, h, QImage.Format.Format_RGBA8888)
    rows = np.frombuffer(image.bits(), np.uint8).reshape(h, image.bytesPerLine())
    rows[:, : 4 * w] = rgba.reshape(h, 4 * w)
    return image


class IdBuffer(QObject):
    """The object-id image of the latest scene, kept current on a background thread.
    ``ready`` fires (on the UI thread) when a new one is there."""

    ready = Signal()

    def __init__(self, parent=None, delay_ms: int = 120) -> None:
        super().__init__(parent)
        self.scene: Scene | None = None  # what ``ids`` shows
        self.ids: np.ndarray | None = None
        self._wanted: Scene | None = None
        self._result: tuple[Scene, np.ndarray] | None = None
        self._busy = False
        self._lock = threading.Lock()
        self._delay = QTimer(self)
        self._delay.setSingleShot(True)
        self._delay.setInterval(delay_ms)
        self._delay.timeout.connect(self._start)
        self._poll = QTimer(self)
        self._poll.setInterval(30)
        self._poll.timeout.connect(self._collect)

    def warm_up(self, scene: Scene) -> None:
        """Load the id kernel now, on a background thread (loading it holds Python's lock
        for a second or so: better while the editor starts than in a render's first second
        after the first click)."""
        small = scene.with_settings(width=4, height=3)

        def work() -> None:
            with contextlib.suppress(Exception):  # the preview reports a broken scene
                object_ids(small, 4, 3)

        threading.Thread(target=work, name="whitted-ids-warm-up", daemon=True).start()

    def request(self, scene: Scene) -> None:
        """Compute the ids of ``scene`` soon (a burst of edits computes once)."""
        if scene is self.scene or scene is self._wanted:
            return
        self._wanted = scene
        self._delay.start()

    def _start(self) -> None:
        if self._busy or self._wanted is None:
            if self._wanted is not None:
                self._delay.start()
            return
        scene, self._wanted = self._wanted, None
        self._busy = True

        def work() -> None:
            try:
                ids = object_ids(scene, *id_size(scene))
            except Exception:  # noqa: BLE001 - a scene the preview also reports
                ids = None
            with self._lock:
                self._result = (scene, ids)

        threading.Thread(target=work, name="whitted-ids", daemon=True).start()
        self._poll.start()

    def _collect(self) -> None:
        with self._lock:
            result, self._result = self._result, None
        if result is None:
            return
        self._busy = False
        self._poll.stop()
        if result[1] is not None:
            self.scene, self.ids = result
            self.ready.emit()
        if self._wanted is not None:
            self._delay.start()

    def ids_for(self, scene: Scene) -> np.ndarray:
        """The ids of ``scene`` now (computed here if the background ones are older)."""
        if self.scene is not scene or self.ids is None:
            self.ids = object_ids(scene, *id_size(scene))
            self.scene = scene
        return self.ids
