"""The editor's timeline: a panel under the picture for animated scenes (and for the first key
of a still one).

- a frame slider (with a mark at every key) and a frame box: the preview shows that frame;
  the scene is posed there (:func:`~whitted.gui.keyframes.posed`), so the properties panel
  shows the frame's values
- Play / Stop: plays the low-resolution preview at the scene's frames per second, looping
  (frames the preview cannot keep up with are skipped, as Blender's "drop frames")
- Insert key (``I`` wherever the focus is, as in Blender): keys the selected object's
  transform (and centre), a light's position or the camera's position and look_at at the
  current frame, creating the ``[animation]`` table and its tracks as needed; one undo step
- frames and frames per second of the animation (undoable edits)
- Render animation…: saves the scene, then renders its film on a background thread
  (:mod:`whitted.gui.film_job`: the frames and the film ``whitted animate`` makes, resumable
  by either), with a progress bar over frames and tiles and the time left; Stop keeps the
  finished frames.

:func:`attach_timeline` puts it into a :class:`~whitted.gui.main_window.MainWindow`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import ValidationError
from PySide6.QtCore import QEvent, QRect, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QColor, QKeyEvent, QKeySequence, QPainter, QPolygon
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSlider,
    QSpinBox,
    QStyle,
    QStyleOptionSlider,
    QVBoxLayout,
    QWidget,
)

from ..errors import WhittedError
from ..scene import Scene, load_scene
from ..scene.animation import Animation
from .document import EditRefused, label_of, rebuild_scene
from .film_job import FilmJob
from .keyframes import (
    NEW_FPS,
    NEW_FRAMES,
    delete_keys,
    frame_still,
    insert_keys,
    key_frames,
    key_targets,
    posed,
    unkeyed_edits,
)
from .messages import friendly_message

if TYPE_CHECKING:
    from .main_window import MainWindow

FILM_FILTER = "MP4 film (*.mp4);;GIF animation (*.gif)"
INTERPOLATIONS = ("linear", "smooth", "spline", "step")
KEY_COLOUR = QColor(235, 170, 40)


class KeySlider(QSlider):
    """A horizontal frame slider with a small diamond under every frame that holds a key."""

    def __init__(self, parent=None) -> None:
        super().__init__(Qt.Orientation.Horizontal, parent)
        self.keys: list[float] = []
        self.setMinimumHeight(30)

    def set_keys(self, keys: list[float]) -> None:
        if keys != self.keys:
            self.keys = keys
            self.update()

    def _geometry(self) -> tuple[QRect, QRect]:
        opt = QStyleOptionSlider()
        self.initStyleOption(opt)
        style = self.style()
        groove = style.subControlRect(QStyle.ComplexControl.CC_Slider, opt,
                                      QStyle.SubControl.SC_SliderGroove, self)
        handle = style.subControlRect(QStyle.ComplexControl.CC_Slider, opt,
                                      QStyle.SubControl.SC_SliderHandle, self)
        return groove, handle

    def x_of(self, frame: float) -> int:
        """The widget x of a frame (the centre of the handle when it sits there)."""
        groove, handle = self._geometry()
        span = groove.width() - handle.width()
        lo, hi = self.minimum(), self.maximum()
        t = 0.0 if hi <= lo else (frame - lo) / (hi - lo)
        return round(groove.x() + handle.width() / 2 + t * span)

    def frame_at(self, x: float) -> int:
        """The frame whose handle position is nearest to widget x."""
        groove, handle = self._geometry()
        span = max(1, groove.width() - handle.width())
        lo, hi = self.minimum(), self.maximum()
        t = (x - groove.x() - handle.width() / 2) / span
        return max(lo, min(hi, round(lo + t * (hi - lo))))

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt's name
        """A click on the groove jumps to that frame (not a page step), and a drag from
        there scrubs, as a timeline does."""
        if event.button() == Qt.MouseButton.LeftButton:
            _, handle = self._geometry()
            if not handle.contains(event.position().toPoint()):
                self.setValue(self.frame_at(event.position().x()))
        super().mousePressEvent(event)

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().paintEvent(event)
        if not self.keys:
            return
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.setPen(KEY_COLOUR.darker(160))
        painter.setBrush(KEY_COLOUR)
        y = self.height() - 5
        for frame in self.keys:
            x = self.x_of(frame)
            painter.drawPolygon(QPolygon([QRect(x, y - 4, 0, 0).topLeft(),
                                          QRect(x + 4, y, 0, 0).topLeft(),
                                          QRect(x, y + 4, 0, 0).topLeft(),
                                          QRect(x - 4, y, 0, 0).topLeft()]))
        painter.end()


def _scene_keys_event(box: QSpinBox | QDoubleSpinBox, event: QEvent) -> bool:
    """Ctrl+Z / Ctrl+Shift+Z in a box holding no typed value: the window's (the scene's)
    undo and redo, as in the editor's other fields. True when handled here."""
    if event.type() == QEvent.Type.ShortcutOverride and isinstance(event, QKeyEvent) \
            and not box.lineEdit().isModified() \
            and any(event.matches(k) for k in (QKeySequence.StandardKey.Undo,
                                               QKeySequence.StandardKey.Redo)):
        event.ignore()
        return True
    return False


class SceneSpinBox(QSpinBox):
    def event(self, event: QEvent) -> bool:  # noqa: D102 - Qt's name
        return _scene_keys_event(self, event) or super().event(event)


class SceneDoubleSpinBox(QDoubleSpinBox):
    def event(self, event: QEvent) -> bool:  # noqa: D102 - Qt's name
        return _scene_keys_event(self, event) or super().event(event)


class TimelinePanel(QWidget):
    """The timeline of ``window``'s document (see the module's text). ``frame`` is the
    current frame; ``still(scene)`` is what the picture shows of ``scene`` there."""

    frame_changed = Signal(int)
    film_done = Signal(object)  # the FilmJob, finished, stopped or failed

    def __init__(self, window: MainWindow) -> None:
        super().__init__(window)
        self.window_ = window
        self.doc = window.doc
        self.frame = 0
        self._still_cache: tuple[Scene, int, Scene] | None = None
        self._stack_index = self.doc.undo_stack.index()
        self.film: FilmJob | None = None

        self.play_button = QPushButton("▶ Play", self)
        self.play_button.setToolTip("play the preview at the scene's frames per second")
        self.play_button.clicked.connect(self.toggle_play)
        self.slider = KeySlider(self)
        self.slider.setToolTip("the frame the picture shows (keys are marked)")
        self.slider.valueChanged.connect(self.set_frame)
        self.slider.sliderPressed.connect(lambda: self._interacting(True))  # scrubbing
        self.slider.sliderReleased.connect(lambda: self._interacting(self.playing))
        self.frame_box = QSpinBox(self)
        self.frame_box.setPrefix("frame ")
        self.frame_box.setToolTip("the current frame")
        self.frame_box.valueChanged.connect(self.set_frame)
        self.key_button = QPushButton("◆ Insert key (I)", self)
        self.key_button.setToolTip("key the selected item's placement (or the camera) at "
                                   "this frame")
        self.key_button.clicked.connect(self.insert_key)
        self.interpolation = QComboBox(self)
        self.interpolation.addItems(INTERPOLATIONS)
        self.interpolation.setToolTip("how a new track goes from key to key")

        self.frames_box = SceneSpinBox(self)
        self.frames_box.setRange(1, 100_000)
        self.frames_box.setToolTip("how many frames the animation has")
        self.frames_box.editingFinished.connect(self._frames_edited)
        self.fps_box = SceneDoubleSpinBox(self)
        self.fps_box.setRange(1.0, 240.0)
        self.fps_box.setDecimals(2)
        self.fps_box.setToolTip("frames per second of the film")
        self.fps_box.editingFinished.connect(self._fps_edited)
        self.film_button = QPushButton("Render animation…", self)
        self.film_button.setToolTip("save the scene, then render every frame and encode the "
                                    "film, as whitted animate does")
        self.film_button.clicked.connect(lambda: self.render_animation())
        self.film_stop = QPushButton("Stop", self)
        self.film_stop.setToolTip("stop the film render; finished frames are kept")
        self.film_stop.clicked.connect(self.stop_film)
        self.film_stop.setEnabled(False)
        self.film_progress = QProgressBar(self)
        self.film_progress.setRange(0, 1000)
        self.film_progress.setValue(0)
        self.film_progress.setFormat("%p%")
        self.film_progress.setMaximumWidth(160)
        self.film_status = QLabel("", self)

        top = QHBoxLayout()
        top.addWidget(self.play_button)
        top.addWidget(self.slider, 1)
        top.addWidget(self.frame_box)
        top.addWidget(self.key_button)
        top.addWidget(QLabel("new tracks", self))
        top.addWidget(self.interpolation)
        bottom = QHBoxLayout()
        bottom.addWidget(QLabel("Frames", self))
        bottom.addWidget(self.frames_box)
        bottom.addWidget(QLabel("fps", self))
        bottom.addWidget(self.fps_box)
        bottom.addSpacing(16)
        bottom.addWidget(self.film_button)
        bottom.addWidget(self.film_stop)
        bottom.addWidget(self.film_progress)
        bottom.addWidget(self.film_status, 1)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 2, 6, 2)
        layout.addLayout(top)
        layout.addLayout(bottom)

        self.play_timer = QTimer(self)
        self.play_timer.timeout.connect(self._play_tick)
        self.film_timer = QTimer(self)
        self.film_timer.setInterval(100)
        self.film_timer.timeout.connect(self._film_tick)
        window.installEventFilter(self)

        self.doc.changed.connect(self._scene_changed)
        self.doc.reset.connect(self._scene_reset)
        self.doc.undo_stack.indexChanged.connect(self._stack_moved)
        self._update_controls()

    # ------------------------------------------------------------------ frames

    @property
    def frame_count(self) -> int:
        """Frames of the animation; a still scene offers :data:`NEW_FRAMES` to key."""
        anim = self.doc.scene.animation
        return anim.frames if anim is not None else NEW_FRAMES

    def still(self, scene: Scene) -> Scene:
        """The plain still of ``scene`` (the document's scene, posed at this frame) that the
        picture shows and Render renders: ``scene.at_frame(frame)`` with the edits not keyed
        yet. The same object for the same scene and frame (the picking cache compares)."""
        cache = self._still_cache
        if cache is not None and cache[0] is scene and cache[1] == self.frame:
            return cache[2]
        frame = min(self.frame, scene.frame_count - 1) if scene.animation is not None else 0
        try:
            still = frame_still(scene, frame)
        except WhittedError as exc:
            self._status(str(exc))
            still = scene
        self._still_cache = (scene, self.frame, still)
        return still

    def set_frame(self, frame: int) -> None:
        """Show ``frame``: pose the scene there and preview it."""
        frame = max(0, min(int(frame), self.frame_count - 1))
        if frame == self.frame:
            return
        lost = self._unkeyed()
        if lost:
            self._status(f"The edit of {', '.join(lost)} was not keyed: frame {frame} shows "
                         "the track's value (I keys an edit at its frame)", 10_000)
        self.frame = frame
        self._sync_frame_widgets()
        self._pose()
        self.frame_changed.emit(frame)

    def _sync_frame_widgets(self) -> None:
        for widget in (self.slider, self.frame_box):
            if widget.value() != self.frame:
                widget.blockSignals(True)
                widget.setValue(self.frame)
                widget.blockSignals(False)

    def _unkeyed(self) -> list[str]:
        scene = self.doc.scene
        if scene.animation is None or self.playing:
            return []
        try:
            return unkeyed_edits(scene, min(self.frame, scene.frame_count - 1))
        except (ValueError, WhittedError):
            return []

    def _pose(self) -> None:
        """Set the values the tracks drive to this frame's (no undo step), and show it."""
        scene = self.doc.scene
        if scene.animation is None:
            return
        try:
            new = posed(scene, min(self.frame, scene.frame_count - 1))
        except (ValueError, WhittedError) as exc:
            self._status(f"Cannot show frame {self.frame}: {exc}")
            return
        self.doc.show_pose(new)  # also when unchanged: the picture shows the new frame

    # ------------------------------------------------------------------ document

    def _scene_changed(self, *_: object) -> None:
        self._update_controls()
        if self.doc.scene.animation is not None:
            self.show_panel()

    def _scene_reset(self) -> None:
        self.stop()
        self.frame = 0
        self._stack_index = self.doc.undo_stack.index()
        self._update_controls()
        dock = self.parentWidget()
        if isinstance(dock, QDockWidget):
            dock.setVisible(self.doc.scene.animation is not None)
        self._pose()

    def _stack_moved(self, index: int) -> None:
        """Undo and redo put back a scene posed at the frame of its edit: pose it at this
        frame (an edit just made is left as it is: it may be a value not keyed yet)."""
        stack = self.doc.undo_stack
        previous, self._stack_index = self._stack_index, index
        try:
            if stack.count() == 0:  # cleared: a new scene, which the reset poses
                return
            command = stack.command(index - 1) if index > 0 else None
        except RuntimeError:  # the window is going away
            return
        fresh = command is not None and not getattr(command, "_seen", False)
        if fresh:
            command._seen = True  # a new edit (a push; at the undo limit the index stays)
        if index == previous or (index > previous and fresh):
            return
        self._pose()

    def _update_controls(self, *, boxes: bool = False) -> None:
        scene = self.doc.scene
        anim = scene.animation
        n = self.frame_count
        for widget in (self.slider, self.frame_box):
            widget.blockSignals(True)
            widget.setRange(0, n - 1)
            widget.blockSignals(False)
        if self.frame > n - 1:
            self.frame = n - 1
        self._sync_frame_widgets()
        self.slider.set_keys(key_frames(scene))
        for box, value in ((self.frames_box, n),
                           (self.fps_box, anim.fps if anim is not None else NEW_FPS)):
            if boxes or not box.hasFocus():
                box.blockSignals(True)
                box.setValue(value)
                box.blockSignals(False)
        self.play_button.setEnabled(anim is not None and n > 1)
        if self.film is None:
            self.film_button.setEnabled(anim is not None)

    def show_panel(self) -> None:
        dock = self.parentWidget()
        if isinstance(dock, QDockWidget) and not dock.isVisible():
            dock.show()

    def _status(self, text: str, ms: int = 5000) -> None:
        self.window_.statusBar().showMessage(text, ms)

    # ------------------------------------------------------------------ keys

    def insert_key(self) -> bool:
        """Key the selection's placement at the current frame (one undo step)."""
        self.window_.commit_pending_edit()
        scene = self.doc.scene
        selection = self.doc.selection
        targets = key_targets(scene, selection)
        if not targets:
            self._status("Insert key: select an object, a light or the camera first")
            return False
        try:
            new = insert_keys(scene, targets, self.frame, self.interpolation.currentText())
        except ValidationError as exc:
            self._status(f"Cannot key: {friendly_message(exc)}")
            return False
        except (ValueError, WhittedError) as exc:
            self._status(f"Cannot key: {exc}")
            return False
        name = label_of(self.doc.item(selection))
        if not self.doc.apply(new, f"Insert key: {name} at frame {self.frame}"):
            self._status(f"{name} is already keyed at frame {self.frame}")
            return False
        self.show_panel()
        paths = ", ".join(path.rsplit(".", 1)[-1] for path, _ in targets)
        self._status(f"Keyed {name} ({paths}) at frame {self.frame}")
        return True

    def delete_key(self) -> bool:
        """Remove the selection's keys at the current frame (one undo step)."""
        scene = self.doc.scene
        targets = key_targets(scene, self.doc.selection)
        try:
            new = delete_keys(scene, targets, self.frame)
        except (ValidationError, ValueError, WhittedError) as exc:
            self._status(f"Cannot delete the key: {exc}")
            return False
        name = label_of(self.doc.item()) if targets else "the selection"
        if new is scene or not self.doc.apply(new, f"Delete key: {name} at frame "
                                                   f"{self.frame}"):
            self._status(f"{name} has no key at frame {self.frame}")
            return False
        self._status(f"Deleted the key of {name} at frame {self.frame}")
        return True

    def _edit_animation(self, text: str, merge: str, **update) -> None:
        scene = self.doc.scene
        anim = scene.animation or Animation(frames=NEW_FRAMES, fps=NEW_FPS)
        data = {"frames": anim.frames, "fps": anim.fps, "tracks": anim.tracks, **update}
        try:
            new = rebuild_scene(scene, animation=Animation(**data))
        except (EditRefused, ValidationError, ValueError) as exc:
            message = friendly_message(exc) if isinstance(exc, ValidationError) else str(exc)
            self._status(f"{text}: {message}")
            self._update_controls(boxes=True)  # the box shows the scene's value again
            return
        self.doc.apply(new, text, merge_key=("timeline", merge))

    def _frames_edited(self) -> None:
        if self.frames_box.value() != self.frame_count or self.doc.scene.animation is None:
            self._edit_animation(f"Frames {self.frames_box.value()}", "frames",
                                 frames=self.frames_box.value())
        _forget_typing(self.frames_box)

    def _fps_edited(self) -> None:
        anim = self.doc.scene.animation
        if anim is not None and self.fps_box.value() != anim.fps:
            self._edit_animation(f"{self.fps_box.value():g} fps", "fps",
                                 fps=self.fps_box.value())
            if self.playing:
                self.play()
        _forget_typing(self.fps_box)

    # ------------------------------------------------------------------ playing

    @property
    def playing(self) -> bool:
        return self.play_timer.isActive()

    def play(self) -> None:
        anim = self.doc.scene.animation
        if anim is None or anim.frames < 2:
            return
        self.play_timer.start(max(1, round(1000 / anim.fps)))
        self.play_button.setText("■ Stop")
        self._interacting(True)  # coarse, fast previews while playing

    def stop(self) -> None:
        was_playing = self.playing
        self.play_timer.stop()
        self.play_button.setText("▶ Play")
        if was_playing:
            self._interacting(False)  # the frame stopped at refines to full size

    def _interacting(self, on: bool) -> None:
        set_interacting = getattr(self.window_.controller, "set_interacting", None)
        if set_interacting is not None:
            set_interacting(on)

    def toggle_play(self) -> None:
        if self.playing:
            self.stop()
        else:
            self.play()

    def _play_tick(self) -> None:
        n = self.frame_count
        if self.doc.scene.animation is None or n < 2:
            self.stop()
            return
        self.set_frame((self.frame + 1) % n)

    # ------------------------------------------------------------------ the film

    def ask_film_path(self) -> Path | None:
        stem = self.doc.path.with_suffix(".mp4") if self.doc.path else Path("film.mp4")
        name, chosen = QFileDialog.getSaveFileName(self, "Render animation to", str(stem),
                                                   FILM_FILTER)
        if not name:
            return None
        path = Path(name)
        if path.suffix.lower() not in (".mp4", ".gif"):
            path = path.with_suffix(".gif" if "gif" in chosen.lower() else ".mp4")
        return path

    def render_animation(self, output: Path | None = None) -> bool:
        """Save the scene once the user agrees (asking where, if it has no file), then render
        its film on a
        background thread (:class:`~whitted.gui.film_job.FilmJob`: the frames and the film
        ``whitted animate`` makes); False when cancelled or already running."""
        if self.film is not None:
            return False
        window = self.window_
        window.commit_pending_edit()
        if self.doc.scene.animation is None:
            window.show_error("Nothing to animate", "Key something first (I), or open an "
                              "animated scene.")
            return False
        # the film is made from the file, as ``whitted animate`` makes it: ask, then save
        unsaved = self.doc.path is None or self.doc.dirty
        if unsaved and (not window.ask_save_for_film() or not window.save()):
            return False
        output = output if output is not None else self.ask_film_path()
        if output is None:
            return False
        output = Path(output)
        try:
            scene = load_scene(self.doc.path)  # what the file holds, as the command reads it
            if output.resolve() == Path(self.doc.path).resolve():
                raise ValueError("the film would write over the scene file")
            job = FilmJob(scene, output)
            job.start()
        except (WhittedError, ValueError, OSError) as exc:
            window.show_error("Cannot render the animation", str(exc))
            return False
        self.film = job
        self.film_progress.setRange(0, 1000)
        self.film_progress.setValue(0)
        self.film_status.setText(f"Rendering {output.name}…")
        self.film_button.setEnabled(False)
        self.film_stop.setEnabled(True)
        self.film_timer.start()
        return True

    @property
    def film_running(self) -> bool:
        return self.film is not None

    def stop_film(self) -> None:
        """Stop the film render after the tiles in flight: finished frames stay on disk, and
        the next run (or ``whitted animate``) continues from them."""
        if self.film is not None:
            self.film.stop()
            self.film_status.setText("Stopping…")
            self.film_stop.setEnabled(False)

    def _film_tick(self) -> None:
        job = self.film
        if job is None:
            self.film_timer.stop()
            return
        self.film_progress.setValue(round(job.fraction * 1000))
        if not job.finished:
            if job.encoding:
                self.film_status.setText(f"Encoding {job.output.name}…")
            elif job.frame is not None and not job.cancel.cancelled:
                eta = job.eta
                left = "" if eta is None else f", {_duration(eta)} left"
                self.film_status.setText(f"frame {job.frame + 1}/{job.total}{left}")
            return
        self.film_timer.stop()
        self.film = None
        self.film_stop.setEnabled(False)
        self._update_controls()
        kept = f", {job.kept} already done" if job.kept else ""
        if job.error is not None:
            self.film_status.setText("Failed")
            self.window_.show_error("The animation did not finish", job.error)
        elif job.stopped:
            self.film_status.setText(f"Stopped: {job.done} of {job.total} frames kept in "
                                     f"{job.frames_dir}")
        else:
            self.film_progress.setValue(1000)
            self.film_status.setText(f"Wrote {job.output} ({job.total} frames{kept}, "
                                     f"{_duration(job.seconds)})")
            self._status(f"Rendered the animation to {job.output}", 8000)
        self.film_done.emit(job)

    def _window_closing(self) -> None:
        if self.film is not None and not self.window_.isVisible():
            self.film.stop()  # the window is gone: finish nothing more

    def eventFilter(self, watched, event) -> bool:  # noqa: N802 - Qt's name
        if watched is self.window_ and event.type() == QEvent.Type.Close:
            QTimer.singleShot(0, self._window_closing)  # after the close was accepted
        return False


def _duration(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.0f} s"
    return f"{int(seconds // 60)} min {int(seconds % 60):02d} s"


def _forget_typing(box: QSpinBox | QDoubleSpinBox) -> None:
    """After a value is committed, Ctrl+Z in the box is the scene's undo, as in the editor's
    other fields (see :func:`_scene_keys_event`)."""
    box.lineEdit().setModified(False)


def attach_timeline(window: MainWindow) -> TimelinePanel:
    """Put the timeline under ``window``'s picture (shown while the scene is animated), its
    actions in an Animation menu, and ``I`` (Insert key) on the whole window."""
    panel = TimelinePanel(window)
    dock = QDockWidget("Timeline", window)
    dock.setObjectName("Timeline")
    dock.setWidget(panel)
    dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                     | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                     | QDockWidget.DockWidgetFeature.DockWidgetClosable)
    window.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, dock)
    dock.setVisible(window.doc.scene.animation is not None)

    def action(text: str, slot, shortcut: str | None = None, tip: str = "") -> QAction:
        act = QAction(text, window)
        if shortcut:
            act.setShortcut(QKeySequence(shortcut))
        act.setToolTip(tip)
        act.setStatusTip(tip)
        act.triggered.connect(lambda checked=False: slot())
        window.addAction(act)  # works wherever the focus is in the window
        return act

    # Insert key (I) and Delete key (Alt+I) are rows of the window's actions table
    panel.act_key = window.acts["insert_key"]
    panel.act_delete_key = window.acts["delete_key"]
    panel.act_play = action("&Play / Stop", panel.toggle_play, None,
                            "play the preview of the animation")
    panel.act_film = action("&Render animation…", lambda: panel.render_animation(), None,
                            "save, then render every frame and encode the film")
    menu = window.menuBar().addMenu("A&nimation")
    help_menu = next((a for a in window.menuBar().actions() if a.text() == "&Help"), None)
    if help_menu is not None:  # before Help, where menus usually end
        window.menuBar().removeAction(menu.menuAction())
        window.menuBar().insertMenu(help_menu, menu)
    menu.addActions([panel.act_key, panel.act_delete_key, panel.act_play])
    menu.addSeparator()
    menu.addAction(panel.act_film)
    menu.addSeparator()
    toggle = dock.toggleViewAction()
    toggle.setText("Show &timeline")
    menu.addAction(toggle)
    window.timeline = panel
    panel._pose()  # an animated scene opens posed at frame 0
    return panel


__all__ = ["KeySlider", "TimelinePanel", "attach_timeline"]
