"""The window's side of rendering: Render / Stop, the progress bar with the time left, the
picture's caption, and the preview's size (the picture's size on screen, recomputed whenever
the picture is laid out or resized). A full render looks through the scene's camera (what the
file renders), so the picture switches to camera view."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, QTimer
from PySide6.QtWidgets import QLabel, QProgressBar


class RenderControl(QObject):
    def __init__(self, window) -> None:
        super().__init__(window)
        self.window_ = window
        self.controller = window.controller
        self.viewport = window.viewport
        self.progress = QProgressBar(window)
        self.progress.setRange(0, 1000)
        self.progress.setMaximumWidth(220)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p%")
        self.eta = QLabel("", window)
        bar = window.statusBar()
        bar.addPermanentWidget(self.eta)
        bar.addPermanentWidget(self.progress)
        self.progress.hide()  # only while a render runs
        c = self.controller
        c.frame.connect(self.viewport.show_image)
        c.frame.connect(self._frame_shown)
        c.progress.connect(self._progress)
        c.finished.connect(self._finished)
        c.failed.connect(self._failed)
        c.kernels_ready.connect(self._kernels_ready)
        c.kernels_progress.connect(self._kernels_progress)
        self.viewport.installEventFilter(self)  # laid out, resized: a new preview size

    @property
    def acts(self):
        return self.window_.acts

    def eventFilter(self, watched, event) -> bool:  # noqa: N802 - Qt's name
        if watched is self.viewport and event.type() in (QEvent.Type.Resize, QEvent.Type.Show):
            before = self.controller.target_pixels
            self.update_preview_target()
            if self.controller.target_pixels > before and self.controller.preview_enabled:
                self.controller.request_preview(self.window_.shown_scene())  # sharper now
        return False

    def update_preview_target(self) -> None:
        """Previews refine, when the input stops, up to the picture's size on screen."""
        r = self.viewport.fit_rect()
        ratio = self.viewport.devicePixelRatioF()
        self.controller.target_pixels = max(1, int(r.width() * r.height() * ratio * ratio))

    def start_render(self) -> None:
        window = self.window_
        window.files.commit_pending_edit()
        if not window.navigation.camera_view:
            window.navigation.toggle_camera_view()  # the render is the camera's picture
        self.controller.render(window.timeline.still(window.doc.scene))
        self.progress.setValue(0)
        self.progress.show()
        self.eta.setText("starting…")
        self.update_actions()

    def stop_render(self) -> None:
        if self.controller.rendering:
            self.controller.stop()
            self.eta.setText("stopping…")
            self.window_.statusBar().showMessage("Stopping…")
            self.viewport.caption = "Stopping…"
            self.viewport.update()
            self.acts["stop"].setEnabled(False)  # until it has stopped

    def update_actions(self) -> None:
        running = self.controller.rendering
        self.acts["render"].setEnabled(not running)
        self.acts["stop"].setEnabled(running)

    def forget(self) -> None:
        """A new scene: nothing said about the last one's render stays."""
        self.window_.statusBar().clearMessage()
        self.eta.setText("")
        self.progress.hide()
        self.viewport.caption = ""

    def toggle_preview(self, on: bool) -> None:
        self.controller.preview_enabled = on
        if on:
            self.controller.request_preview(self.window_.shown_scene())

    def _progress(self, fraction: float, eta, text: str) -> None:
        self.progress.setValue(round(fraction * 1000))
        self.eta.setText(text)

    def _frame_shown(self, image, kind: str) -> None:
        self.viewport.caption = "preview" if kind == "preview" else ""

    def _finished(self, kind: str, text: str) -> None:
        if self.viewport.caption == "Stopping…":
            self.viewport.caption = ""
            self.viewport.update()
        self.window_.statusBar().showMessage(text, 8000)  # said once, not twice
        self.progress.hide()
        self.eta.setText("")
        self.update_actions()

    def _failed(self, kind: str, message: str) -> None:
        self.viewport.caption = f"cannot render: {message}"
        self.viewport.update()
        self.window_.statusBar().showMessage(f"Cannot {kind}: {message}", 8000)
        if not self.controller.rendering:
            self.progress.hide()
        self.update_actions()

    def _kernels_progress(self, fraction: float, left) -> None:
        """A first compile of the kernels: the status bar's progress bar and the time left
        (the picture's caption says it too, ``show_warm_up``)."""
        if self.controller.rendering:
            return
        self.progress.setValue(round(fraction * 1000))
        self.progress.show()
        self.eta.setText("compiling the kernels" + (f": about {left:.0f} s left"
                                                     if left is not None else ""))

    #: the captions of the kernels' loading (replaced as it goes, cleared when ready)
    WARM_UP_CAPTIONS = ("Loading", "Compiling", "Waiting for another whitted")

    def show_warm_up(self) -> None:
        """While the kernels load, the picture says how it goes (twice a second)."""
        if not hasattr(self, "_warm_timer"):
            self._warm_timer = QTimer(self)
            self._warm_timer.setInterval(500)
            self._warm_timer.timeout.connect(self._warm_up_tick)
        self._warm_timer.start()
        self._warm_up_tick()

    def _warm_up_tick(self) -> None:
        if self.controller.kernels_loaded:
            self._warm_timer.stop()
            return
        caption = self.viewport.caption
        if not caption or caption.startswith(self.WARM_UP_CAPTIONS):
            text = self.controller.warm_up_text()
            if text != caption:
                self.viewport.caption = text
                self.viewport.update()

    def _kernels_ready(self, seconds: float) -> None:
        if hasattr(self, "_warm_timer"):
            self._warm_timer.stop()
        if self.viewport.caption.startswith(self.WARM_UP_CAPTIONS):
            self.viewport.caption = ""
            self.viewport.update()
        if not self.controller.rendering:
            self.progress.hide()
            self.eta.setText("")
        if seconds > 1:
            self.window_.statusBar().showMessage(f"Render kernels ready ({seconds:.0f} s)", 4000)


__all__ = ["RenderControl"]
