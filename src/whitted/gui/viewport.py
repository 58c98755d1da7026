"""The picture: the render or the preview, scaled to fit with the render's aspect ratio, and
the mouse camera controls (drag: orbit; right-, middle- or Shift-drag: pan; wheel: zoom)."""

from __future__ import annotations

import itertools

from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QImage, QMouseEvent, QPainter, QWheelEvent
from PySide6.QtWidgets import QSizePolicy, QWidget

ORBIT_DEG_PER_PX = 0.4
ZOOM_PER_NOTCH = 0.9
_drags = itertools.count(1)


class Viewport(QWidget):
    """``orbit(dyaw, dpitch, drag)``, ``pan(dx, dy, drag)`` (fractions of the picture's
    height) and ``zoom(factor)`` ask the window to move the camera; ``drag`` numbers one
    mouse drag, so that its moves make one undo step."""

    orbit = Signal(float, float, int)
    pan = Signal(float, float, int)
    zoom = Signal(float)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.image: QImage | None = None
        self.kind = ""
        self.aspect = 4 / 3  # width / height of the render
        self.caption = ""
        self._last: QPointF | None = None
        self._mode = ""
        self._drag = 0
        self.setMinimumSize(320, 240)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.setMouseTracking(False)
        self.setToolTip("drag: orbit · right/Shift-drag: pan · wheel: zoom")

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        return QSize(640, 480)

    def set_aspect(self, width: int, height: int) -> None:
        self.aspect = width / height
        self.update()

    def show_image(self, image: QImage, kind: str) -> None:
        self.image = image
        self.kind = kind
        self.update()

    def picture_rect(self) -> QRectF:
        """Where the picture goes: as large as fits, with the render's aspect ratio."""
        w, h = self.width() - 8, self.height() - 8
        if w <= 0 or h <= 0:
            return QRectF()
        if w / h > self.aspect:
            pw, ph = h * self.aspect, h
        else:
            pw, ph = w, w / self.aspect
        return QRectF((self.width() - pw) / 2, (self.height() - ph) / 2, pw, ph)

    def paintEvent(self, event) -> None:  # noqa: N802
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(48, 48, 52))
        rect = self.picture_rect()
        if self.image is not None and not self.image.isNull():
            p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, self.kind == "preview")
            p.drawImage(rect, self.image)
        else:
            p.fillRect(rect, QColor(20, 20, 22))
        if self.caption:
            p.setPen(QColor(230, 230, 230))
            p.drawText(rect.adjusted(6, 4, -6, -4),
                       Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop, self.caption)
        p.end()

    # ------------------------------------------------------------------ mouse

    def mousePressEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        button = event.button()
        shift = bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier)
        if button == Qt.MouseButton.LeftButton and not shift:
            self._mode = "orbit"
        elif button in (Qt.MouseButton.RightButton, Qt.MouseButton.MiddleButton) or (
                button == Qt.MouseButton.LeftButton and shift):
            self._mode = "pan"
        else:
            return
        self._last = event.position()
        self._drag = next(_drags)
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        if self._last is None:
            return
        d = event.position() - self._last
        self._last = event.position()
        if d.x() == 0 and d.y() == 0:
            return
        if self._mode == "orbit":
            self.orbit.emit(d.x() * ORBIT_DEG_PER_PX, d.y() * ORBIT_DEG_PER_PX, self._drag)
        else:
            height = max(self.picture_rect().height(), 1.0)
            self.pan.emit(d.x() / height, d.y() / height, self._drag)
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        self._last = None
        self._mode = ""

    def wheelEvent(self, event: QWheelEvent) -> None:  # noqa: N802
        notches = event.angleDelta().y() / 120
        if notches:
            self.zoom.emit(ZOOM_PER_NOTCH ** notches)
        event.accept()
