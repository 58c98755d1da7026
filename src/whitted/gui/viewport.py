"""The picture: the render or the preview with the render's aspect ratio, fitted to the widget
or shown at 1:1 and zoomed, with what is drawn over it (the selection's outline, lights, the
camera's target) and the mouse and keyboard of a 3-D view:

- a click selects what is under the pointer (the window picks through the object-id image);
  a press only becomes a drag past the system's drag distance, so a shaky click moves nothing
- left-drag (or middle-drag) orbits, right-drag or Shift-drag pans, the wheel zooms toward
  the pointer; Ctrl+wheel and Ctrl+drag zoom and pan the picture itself
- while a tool runs (a G/R/S move) the mouse and its keys (X, Y, Z, a typed value, Enter,
  Esc) go to it, before the window's shortcuts; otherwise keys are the window's actions

Positions handed out are in the picture's own coordinates: (u, v) in 0..1 from its top-left
corner, whatever its zoom."""

from __future__ import annotations

import itertools

from PySide6.QtCore import QEvent, QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QImage, QKeyEvent, QMouseEvent, QPainter, QWheelEvent
from PySide6.QtWidgets import QApplication, QSizePolicy, QWidget

ORBIT_DEG_PER_PX = 0.4
ZOOM_PER_NOTCH = 0.9
PICTURE_ZOOM_STEP = 1.25
MIN_DRAG_PX = 6  # at least this, or the platform's drag distance if larger
_drags = itertools.count(1)


class Viewport(QWidget):
    """``orbit(dyaw, dpitch, drag)``, ``pan(dx, dy, drag)`` (fractions of the picture's
    height), ``zoom(factor, u, v)`` (u, v: where the pointer is, -1 when outside) ask the
    window to move the camera; ``drag`` numbers one mouse drag, so that its moves make one
    undo step. ``clicked(u, v, modifiers)``: a click (not a drag) on the picture."""

    orbit = Signal(float, float, int)
    pan = Signal(float, float, int)
    zoom = Signal(float, float, float)
    clicked = Signal(float, float, object)
    drag_started = Signal()
    drag_finished = Signal()

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.image: QImage | None = None
        self.kind = ""
        self.render_size = (640, 480)  # the render's pixels (the preview is smaller)
        self.caption = ""
        #: None: fit the widget; else screen pixels per render pixel (1.0: 1:1)
        self.picture_scale: float | None = None
        self.picture_offset = QPointF(0, 0)  # shift of a zoomed picture's centre
        self.outline: QImage | None = None  # the selection's outline, over the picture
        #: draws over the picture: ``overlay(painter, to_widget)``, to_widget(u, v) -> QPointF
        self.overlay = None
        #: a running modal tool (a G/R/S move): gets the pointer, a click confirms it
        self.tool = None
        self.hover = QPointF(-1, -1)  # where the pointer last was (a G/R/S move starts there)
        self._press: QPointF | None = None
        self._last: QPointF | None = None
        self._mode = ""
        self._dragging = False
        self._drag = 0
        self.setMinimumSize(320, 240)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(True)
        self.setToolTip("")

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        return QSize(640, 480)

    @property
    def aspect(self) -> float:
        return self.render_size[0] / self.render_size[1]

    def set_aspect(self, width: int, height: int) -> None:
        """The render's size in pixels (its aspect ratio, and 1:1)."""
        if (width, height) != self.render_size:
            self.render_size = (width, height)
            self.update()

    def show_image(self, image: QImage, kind: str) -> None:
        self.image = image
        self.kind = kind
        self.update()

    # ------------------------------------------------------------------ picture geometry

    def fit_rect(self) -> QRectF:
        w, h = self.width() - 8, self.height() - 8
        if w <= 0 or h <= 0:
            return QRectF()
        if w / h > self.aspect:
            pw, ph = h * self.aspect, h
        else:
            pw, ph = w, w / self.aspect
        return QRectF((self.width() - pw) / 2, (self.height() - ph) / 2, pw, ph)

    def picture_rect(self) -> QRectF:
        """Where the picture goes: as large as fits with the render's aspect ratio, or at
        ``picture_scale`` screen pixels per render pixel (1:1, zoomed)."""
        if self.picture_scale is None:
            return self.fit_rect()
        pw = self.render_size[0] * self.picture_scale
        ph = self.render_size[1] * self.picture_scale
        c = QPointF(self.width() / 2, self.height() / 2) + self.picture_offset
        return QRectF(c.x() - pw / 2, c.y() - ph / 2, pw, ph)

    def to_picture(self, pos: QPointF) -> tuple[float, float] | None:
        """(u, v) of a widget position on the picture, None outside it."""
        r = self.picture_rect()
        if r.isEmpty() or not r.contains(pos):
            return None
        return ((pos.x() - r.x()) / r.width(), (pos.y() - r.y()) / r.height())

    def to_widget(self, u: float, v: float) -> QPointF:
        r = self.picture_rect()
        return QPointF(r.x() + u * r.width(), r.y() + v * r.height())

    def set_picture_scale(self, scale: float | None, about: QPointF | None = None) -> None:
        """Fit (None) or show the picture at ``scale`` (1.0: 1:1), keeping the picture point
        under ``about`` (a widget position) where it is."""
        if scale is None:
            self.picture_scale, self.picture_offset = None, QPointF(0, 0)
            self.update()
            return
        old = self.picture_rect()
        about = about if about is not None else QPointF(self.width() / 2, self.height() / 2)
        u = (about.x() - old.x()) / max(old.width(), 1e-9)
        v = (about.y() - old.y()) / max(old.height(), 1e-9)
        self.picture_scale = max(0.05, min(scale, 32.0))
        pw = self.render_size[0] * self.picture_scale
        ph = self.render_size[1] * self.picture_scale
        # place the picture so that (u, v) stays under ``about``
        centre = QPointF(about.x() - (u - 0.5) * pw, about.y() - (v - 0.5) * ph)
        self.picture_offset = centre - QPointF(self.width() / 2, self.height() / 2)
        self.update()

    def current_scale(self) -> float:
        return self.picture_rect().width() / self.render_size[0]

    def zoom_picture(self, factor: float, about: QPointF | None = None) -> None:
        self.set_picture_scale(self.current_scale() * factor, about)

    # ------------------------------------------------------------------ painting

    def paintEvent(self, event) -> None:  # noqa: N802
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(48, 48, 52))
        rect = self.picture_rect()
        if self.image is not None and not self.image.isNull():
            # a preview smaller than the picture is smoothed; a render at 1:1 or zoomed in
            # shows its pixels as they are
            smooth = self.image.width() < rect.width() and self.kind == "preview"
            p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, smooth)
            p.drawImage(rect, self.image)
        else:
            p.fillRect(rect, QColor(20, 20, 22))
        if self.outline is not None:
            p.drawImage(rect, self.outline)
        if self.overlay is not None:
            p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
            self.overlay(p, self.to_widget)
        caption = self.caption
        if self.picture_scale is not None:
            caption = f"{caption}   {self.current_scale():.0%}".strip()
        if caption:
            p.setPen(QColor(0, 0, 0))
            box = QRectF(self.rect()).adjusted(10, 8, -10, -8)
            flags = Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop
            p.drawText(box.translated(1, 1), flags, caption)
            p.setPen(QColor(235, 235, 235))
            p.drawText(box, flags, caption)
        p.end()

    # ------------------------------------------------------------------ mouse

    def _drag_distance(self) -> int:
        return max(MIN_DRAG_PX, QApplication.startDragDistance())

    def mousePressEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        self.setFocus(Qt.FocusReason.MouseFocusReason)
        button = event.button()
        mods = event.modifiers()
        if self.tool is not None:  # left confirms, right cancels the running move
            tool, self.tool = self.tool, None
            if button == Qt.MouseButton.RightButton:
                tool.cancel()
            else:
                tool.confirm()
            self.update()
            event.accept()
            return
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        ctrl = bool(mods & Qt.KeyboardModifier.ControlModifier)
        if ctrl and button == Qt.MouseButton.LeftButton:
            self._mode = "picture"  # move the zoomed picture itself
        elif button in (Qt.MouseButton.LeftButton, Qt.MouseButton.MiddleButton) and not shift:
            self._mode = "orbit"
        elif button in (Qt.MouseButton.RightButton, Qt.MouseButton.MiddleButton,
                        Qt.MouseButton.LeftButton):
            self._mode = "pan"
        else:
            return
        self._press = self._last = event.position()
        self._button = button
        self._dragging = False
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        self.hover = event.position()
        if self.tool is not None:
            uv = self.to_picture(event.position())
            self.tool.move(event.position(), uv)
            event.accept()
            return
        if self._press is None:
            return
        if not self._dragging:
            moved = event.position() - self._press
            if max(abs(moved.x()), abs(moved.y())) < self._drag_distance():
                return  # not a drag yet: a click that shook
            self._dragging = True
            self._drag = next(_drags)
            self.drag_started.emit()
        d = event.position() - self._last
        self._last = event.position()
        if d.x() == 0 and d.y() == 0:
            return
        if self._mode == "picture":
            if self.picture_scale is None:
                self.set_picture_scale(self.current_scale())
            self.picture_offset += d
            self.update()
        elif self._mode == "orbit":
            self.orbit.emit(d.x() * ORBIT_DEG_PER_PX, d.y() * ORBIT_DEG_PER_PX, self._drag)
        else:
            height = max(self.picture_rect().height(), 1.0)
            self.pan.emit(d.x() / height, d.y() / height, self._drag)
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:  # noqa: N802
        press, dragging = self._press, self._dragging
        self._press = self._last = None
        self._mode = ""
        self._dragging = False
        if press is None:
            return
        if dragging:
            self.drag_finished.emit()
        elif getattr(self, "_button", None) == Qt.MouseButton.LeftButton:
            uv = self.to_picture(press)
            u, v = uv if uv is not None else (-1.0, -1.0)
            self.clicked.emit(u, v, event.modifiers())
        event.accept()

    def wheelEvent(self, event: QWheelEvent) -> None:  # noqa: N802
        notches = event.angleDelta().y() / 120
        if notches:
            if event.modifiers() & Qt.KeyboardModifier.ControlModifier:
                self.zoom_picture(PICTURE_ZOOM_STEP ** notches, event.position())
            else:
                uv = self.to_picture(event.position())
                u, v = uv if uv is not None else (-1.0, -1.0)
                self.zoom.emit(ZOOM_PER_NOTCH ** notches, u, v)
        event.accept()

    # ------------------------------------------------------------------ keys

    def event(self, event) -> bool:  # noqa: D102 - Qt's name
        if event.type() == QEvent.Type.ShortcutOverride and self.tool is not None \
                and self.tool.wants(event):
            event.accept()  # a running move's key (X, a digit, Enter, Esc): not a shortcut
            return True
        return super().event(event)

    def fit_picture(self) -> None:
        self.set_picture_scale(None)

    def actual_pixels(self) -> None:
        self.set_picture_scale(1.0)

    def zoom_in(self) -> None:
        self.zoom_picture(PICTURE_ZOOM_STEP)

    def zoom_out(self) -> None:
        self.zoom_picture(1 / PICTURE_ZOOM_STEP)

    def keyPressEvent(self, event: QKeyEvent) -> None:  # noqa: N802
        if self.tool is not None and self.tool.key(event):
            if self.tool is not None and self.tool.done:
                self.tool = None
            self.update()
            event.accept()
            return
        super().keyPressEvent(event)
