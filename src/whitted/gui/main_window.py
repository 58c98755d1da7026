"""The editor's window: scene tree (left), picture (centre), properties (right), menus and a
toolbar with Render / Stop, a progress bar with the time left. It wires the document, the
render controller and autosave together and owns every dialog (each behind one method, so the
tests can answer them)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PySide6.QtCore import QPointF, QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QCloseEvent, QColor, QKeySequence, QPainter, QPen
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QFileDialog,
    QLabel,
    QMainWindow,
    QMessageBox,
    QProgressBar,
    QToolButton,
)

from .. import scene as S
from ..errors import WhittedError
from ..scene import Scene, load_scene, save_scene
from ..scene.default import default_scene
from ..scene.toml_document import save_scene_toml
from ..scene.writing import rebase_files
from . import camera_ops, catalog
from .autosave import Autosave, recovery_for
from .document import (
    CAMERA,
    RENDER,
    EditRefused,
    SceneDocument,
    get_path,
    label_of,
    rebuild_scene,
    set_path,
)
from .icons import icon_for
from .picking import IdBuffer, id_at, outline_image
from .properties import PropertyPanel
from .recent import RecentFiles
from .render_controller import RenderController
from .timeline import attach_timeline
from .transform_tool import TransformTool, light_position, object_bounds, object_centre
from .tree import SceneTree
from .viewport import Viewport

SCENE_FILTER = "Scene files (*.toml *.json);;TOML scene (*.toml);;JSON scene (*.json)"
IMAGE_FILTER = "PNG image (*.png);;OpenEXR HDR image (*.exr);;All images (*.png *.exr *.jpg *.pfm)"
#: fits a 1366×768 screen with its panel and the title bar
WINDOW_SIZE = (1280, 680)


def starter_scene() -> Scene:
    """What File > New gives: a floor, a sphere, an ambient and a point light."""
    return Scene(
        render=S.RenderSettings(width=640, height=480),
        camera=S.Camera(position=(0.0, 1.5, 6.0), look_at=(0.0, 0.6, 0.0), fov=40.0),
        background=S.Background(gradient=S.Gradient(top=(0.3, 0.45, 0.75),
                                                     bottom=(0.85, 0.88, 0.95))),
        lights=[S.AmbientLight(name="ambient", intensity=0.2),
                S.PointLight(name="lamp", position=(-4.0, 6.0, 5.0), intensity=0.9)],
        objects=[S.Plane(name="floor", material="matte"),
                 S.Sphere(name="ball", center=(0.0, 0.8, 0.0), radius=0.8, material="plastic")],
    )


class MainWindow(QMainWindow):
    def __init__(self, scene: Scene | None = None, path: Path | None = None, *,
                 settings: QSettings | None = None, autosave_folder: Path | None = None,
                 autosave_interval_ms: int = 60_000, preview: bool = True,
                 warm_up: bool = True) -> None:
        super().__init__()
        self.settings = settings if settings is not None else QSettings("whitted", "editor")
        self.recent = RecentFiles(self.settings)
        if scene is None:
            scene = default_scene()
        if path is not None:
            scene = scene.with_base_dir(Path(path).parent)
        self.doc = SceneDocument(scene, Path(path) if path is not None else None, self)
        self._remember_source(scene, path)
        self.controller = RenderController(self)
        self.controller.preview_enabled = preview
        self.autosave = Autosave(self.doc, interval_ms=autosave_interval_ms,
                                 folder=autosave_folder, parent=self)

        self.viewport = Viewport(self)
        self.setCentralWidget(self.viewport)
        self.tree = SceneTree(self.doc)
        self.properties = PropertyPanel(self.doc)
        self.properties.choose_file = self.choose_file
        self.properties.ask_keep_colour = self.ask_keep_colour
        self.properties.interacting.connect(self._interacting)
        self._dock(self.tree, "Scene", Qt.DockWidgetArea.LeftDockWidgetArea, 240)
        self._dock(self.properties, "Properties", Qt.DockWidgetArea.RightDockWidgetArea, 390)

        self.progress = QProgressBar(self)
        self.progress.setRange(0, 1000)
        self.progress.setMaximumWidth(220)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p%")
        self.eta = QLabel("", self)
        self.statusBar().addPermanentWidget(self.eta)
        self.statusBar().addPermanentWidget(self.progress)
        self.progress.hide()  # only while a render runs

        self._make_actions()
        self._make_menus()
        self._make_toolbar()
        self.timeline = attach_timeline(self)  # frames of an animated scene, keys, films

        self.doc.changed.connect(self._scene_changed)
        self.doc.path_changed.connect(self._update_title)
        self.doc.undo_stack.cleanChanged.connect(self._update_title)
        self.controller.frame.connect(self.viewport.show_image)
        self.controller.frame.connect(self._frame_shown)
        self.controller.progress.connect(self._progress)
        self.controller.finished.connect(self._render_finished)
        self.controller.failed.connect(self._render_failed)
        self.controller.kernels_ready.connect(self._kernels_ready)
        self.autosave.saved.connect(self._status)
        self.ids = IdBuffer(self)
        self.ids.ready.connect(self._update_outline)
        self.doc.selection_changed.connect(lambda *_: self._update_outline())
        self.viewport.clicked.connect(self.pick)
        self.viewport.key_handler = self._viewport_key
        self.viewport.overlay = self._draw_overlay
        self.viewport.drag_started.connect(lambda: self._interacting(True))
        self.viewport.drag_finished.connect(lambda: self._interacting(False))
        self.viewport.orbit.connect(self._orbit)
        self.viewport.pan.connect(self._pan)
        self.viewport.zoom.connect(self._zoom)

        self._fit_window()
        self._update_title()
        self._update_render_actions()
        self.viewport.set_aspect(scene.render.width, scene.render.height)
        self._update_preview_target()
        if warm_up:
            self.viewport.caption = "Loading the render kernels (the first run compiles them)…"
            self.controller.warm_up()
            self.ids.warm_up(self.doc.scene)
        self.controller.request_preview(self.timeline.still(self.doc.scene))

    # ------------------------------------------------------------------ layout

    def _dock(self, widget, title: str, area, width: int) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        self.addDockWidget(area, dock)
        self.resizeDocks([dock], [width], Qt.Orientation.Horizontal)
        return dock

    def _fit_window(self) -> None:
        w, h = WINDOW_SIZE
        screen = self.screen()
        if screen is not None:
            avail = screen.availableGeometry()
            w, h = min(w, avail.width() - 20), min(h, avail.height() - 40)
        self.resize(max(w, 800), max(h, 500))

    def _action(self, text: str, slot, shortcut=None, tip: str = "") -> QAction:
        action = QAction(text, self)
        if shortcut is not None:
            if isinstance(shortcut, list):
                action.setShortcuts(shortcut)
            else:
                action.setShortcut(shortcut)
        if tip:
            action.setStatusTip(tip)
            action.setToolTip(tip)
        action.triggered.connect(lambda checked=False: slot())
        return action

    def _make_actions(self) -> None:
        K = QKeySequence
        self.act_new = self._action("&New", self.new_scene, K.StandardKey.New)
        self.act_open = self._action("&Open…", self.open_dialog, K.StandardKey.Open)
        self.act_save = self._action("&Save", self.save, K.StandardKey.Save)
        self.act_save_as = self._action("Save &As…", self.save_as, K("Ctrl+Shift+S"))
        self.act_save_image = self._action("Save &Image…", self.save_image, K("Ctrl+E"),
                                           "save the picture as PNG or EXR")
        self.act_quit = self._action("&Quit", self.close, K.StandardKey.Quit)
        stack = self.doc.undo_stack
        self.act_undo = stack.createUndoAction(self, "&Undo")
        self.act_undo.setShortcuts([K("Ctrl+Z")])
        self.act_redo = stack.createRedoAction(self, "&Redo")
        self.act_redo.setShortcuts([K("Ctrl+Shift+Z"), K("Ctrl+Y")])
        self.act_duplicate = self._action("D&uplicate", self.duplicate_selected, K("Ctrl+D"))
        self.act_rename = self._action("Re&name", self.rename_selected, K("F2"))
        self.act_delete = self._action("&Delete", self.delete_selected, K.StandardKey.Delete)
        self.act_delete.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
        self.act_rename.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
        for a in (self.act_duplicate, self.act_rename, self.act_delete):
            self.tree.addAction(a)
            self.viewport.addAction(a)  # also with the focus on the picture
        self.act_render = self._action("&Render", self.start_render, K("Ctrl+R"),
                                       "render the full picture, tile by tile")
        self.act_stop = self._action("&Stop", self.stop_render, None,
                                     "stop the render and keep the picture so far (Esc)")
        self.act_escape = self._action("Stop the render, or &deselect", self.escape, K("Esc"),
                                       "Esc: stops a running render, else deselects")
        self.act_fit = self._action("&Fit the picture", lambda: self.viewport.set_picture_scale(
            None), K("Ctrl+0"), "show the whole picture, as large as fits")
        self.act_one_to_one = self._action(
            "&Actual pixels (1:1)", lambda: self.viewport.set_picture_scale(1.0), K("Ctrl+1"),
            "one render pixel per screen pixel")
        self.act_zoom_in = self._action(
            "Zoom the picture &in", lambda: self.viewport.zoom_picture(1.25),
            [K("Ctrl+="), K("Ctrl++")], "also Ctrl+wheel; Ctrl+drag moves the zoomed picture")
        self.act_zoom_out = self._action(
            "Zoom the picture &out", lambda: self.viewport.zoom_picture(0.8), K("Ctrl+-"))
        self.act_preview = QAction("Interactive &preview", self, checkable=True, checked=True)
        self.act_preview.toggled.connect(self._toggle_preview)
        self.act_settings = self._action("Render &settings…",
                                         lambda: self.select(RENDER))
        self.object_actions: dict[str, QAction] = {}
        for kind, text in catalog.OBJECT_KINDS.items():
            self.object_actions[kind] = self._action(text, lambda k=kind: self.add_object(k))
            self.object_actions[kind].setIcon(icon_for(kind))
        self.act_model = self._action("Model from file…", self.add_model,
                                      tip="OBJ, PLY, STL, OFF, glTF")
        self.act_model.setEnabled(catalog.HAS_MESH)
        self.act_model.setIcon(icon_for("mesh"))
        self.light_actions: dict[str, QAction] = {}
        for kind, text in catalog.LIGHT_KINDS.items():
            self.light_actions[kind] = self._action(text, lambda k=kind: self.add_light(k))
            self.light_actions[kind].setIcon(icon_for(f"light:{kind}"))

    def _make_menus(self) -> None:
        bar = self.menuBar()
        file = bar.addMenu("&File")
        file.addActions([self.act_new, self.act_open])
        self.recent_menu = file.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent)
        file.addActions([self.act_save, self.act_save_as])
        file.addSeparator()
        file.addAction(self.act_save_image)
        file.addSeparator()
        file.addAction(self.act_quit)
        edit = bar.addMenu("&Edit")
        edit.addActions([self.act_undo, self.act_redo])
        edit.addSeparator()
        edit.addActions([self.act_duplicate, self.act_rename, self.act_delete])
        edit.addSeparator()
        edit.addAction(self.act_escape)
        add = bar.addMenu("&Add")
        self.add_object_menu = add.addMenu("&Object")
        self.add_object_menu.addActions(list(self.object_actions.values()))
        self.add_object_menu.addSeparator()
        self.add_object_menu.addAction(self.act_model)
        self.add_light_menu = add.addMenu("&Light")
        self.add_light_menu.addActions(list(self.light_actions.values()))
        view = bar.addMenu("&View")
        self.view_menu = view
        view.addActions([self.act_fit, self.act_one_to_one, self.act_zoom_in, self.act_zoom_out])
        render = bar.addMenu("&Render")
        render.addActions([self.act_render, self.act_stop])
        render.addSeparator()
        render.addActions([self.act_preview, self.act_settings])
        help_ = bar.addMenu("&Help")
        help_.addAction(self._action("&Controls", self._show_controls))

    def _make_toolbar(self) -> None:
        tools = self.addToolBar("Main")
        tools.setObjectName("main toolbar")
        tools.setMovable(False)
        tools.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        for menu, text, icon in ((self.add_object_menu, "Add object", "sphere"),
                                 (self.add_light_menu, "Add light", "light:point")):
            button = QToolButton(self)
            button.setText(text)
            button.setIcon(icon_for(icon))
            button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
            button.setMenu(menu)
            button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
            tools.addWidget(button)
        tools.addSeparator()
        stack = self.doc.undo_stack
        for text, slot, signal, tip in (
                ("Undo", stack.undo, stack.canUndoChanged, "undo the last edit (Ctrl+Z)"),
                ("Redo", stack.redo, stack.canRedoChanged, "redo (Ctrl+Shift+Z)")):
            action = tools.addAction(text)  # short texts here; the Edit menu names the edit
            action.setToolTip(tip)
            action.triggered.connect(slot)
            action.setEnabled(False)
            signal.connect(action.setEnabled)
        tools.addSeparator()
        tools.addActions([self.act_render, self.act_stop])

    # ------------------------------------------------------------------ dialogs (tests answer)

    def ask_unsaved(self) -> str:
        """'save', 'discard' or 'cancel' for unsaved changes."""
        buttons = (QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                   | QMessageBox.StandardButton.Cancel)
        answer = QMessageBox.question(
            self, "Unsaved changes", f"Save the changes to {self.scene_name()}?", buttons,
            QMessageBox.StandardButton.Save)
        return {QMessageBox.StandardButton.Save: "save",
                QMessageBox.StandardButton.Discard: "discard"}.get(answer, "cancel")

    def ask_recover(self, autosave: Path) -> bool:
        answer = QMessageBox.question(
            self, "Recover unsaved changes?",
            f"{autosave.name} holds changes to {self.scene_name()} that were never saved "
            "(the editor closed unexpectedly). Recover them?")
        return answer == QMessageBox.StandardButton.Yes

    def ask_keep_colour(self, preset: str) -> str:
        """A preset chosen over the object's own colour: keep the colour, or take the
        preset's? ('keep', 'replace' or 'cancel')."""
        box = QMessageBox(QMessageBox.Icon.Question, "Keep your colour?",
                          f"The {preset} preset has a colour of its own. Keep this object's "
                          "colour with the preset's other values?", parent=self)
        keep = box.addButton("Keep my colour", QMessageBox.ButtonRole.AcceptRole)
        replace = box.addButton(f"Use the {preset} colour", QMessageBox.ButtonRole.DestructiveRole)
        box.addButton(QMessageBox.StandardButton.Cancel)
        box.exec()
        return {keep: "keep", replace: "replace"}.get(box.clickedButton(), "cancel")

    def ask_open_path(self) -> Path | None:
        name, _ = QFileDialog.getOpenFileName(self, "Open scene", self._start_dir(), SCENE_FILTER)
        return Path(name) if name else None

    def ask_save_path(self) -> Path | None:
        start = str(self.doc.path) if self.doc.path else str(Path(self._start_dir(),
                                                                  "scene.toml"))
        name, chosen = QFileDialog.getSaveFileName(self, "Save scene as", start, SCENE_FILTER)
        if not name:
            return None
        path = Path(name)
        if path.suffix.lower() not in (".toml", ".json"):
            path = path.with_suffix(".json" if "json" in chosen.lower() else ".toml")
        return path

    def ask_image_path(self) -> Path | None:
        stem = self.doc.path.stem if self.doc.path else "render"
        name, chosen = QFileDialog.getSaveFileName(
            self, "Save image", str(Path(self._start_dir(), f"{stem}.png")), IMAGE_FILTER)
        if not name:
            return None
        path = Path(name)
        if not path.suffix:
            path = path.with_suffix(".exr" if "exr" in chosen.lower() else ".png")
        return path

    def choose_file(self, title: str, filters: str) -> str | None:
        name, _ = QFileDialog.getOpenFileName(self, title, self._start_dir(), filters)
        return name or None

    def show_error(self, title: str, message: str) -> None:
        QMessageBox.warning(self, title, message)

    def _start_dir(self) -> str:
        return str(self.doc.path.parent if self.doc.path else Path.cwd())

    def _show_controls(self) -> None:
        QMessageBox.information(self, "Controls", (
            "Picture: drag to orbit the camera, right-drag or Shift-drag to pan, wheel to zoom.\n"
            "Scene tree: Delete removes, Ctrl+D duplicates, F2 or double-click renames.\n"
            "Ctrl+Z / Ctrl+Shift+Z undo and redo every edit. Ctrl+R renders, Esc stops."))

    # ------------------------------------------------------------------ files

    def scene_name(self) -> str:
        return self.doc.path.name if self.doc.path else "the untitled scene"

    def _update_title(self, *_: object) -> None:
        name = self.doc.path.name if self.doc.path else "untitled"
        self.setWindowTitle(f"{name}[*] — whitted")
        self.setWindowModified(self.doc.dirty)

    def maybe_save(self) -> bool:
        """Before the scene goes away: True when it may go (saved or discarded)."""
        if not self.doc.dirty:
            return True
        answer = self.ask_unsaved()
        if answer == "save":
            return self.save()
        if answer == "discard":
            self.autosave.discard()
            return True
        return False

    def new_scene(self) -> bool:
        if not self.maybe_save():
            return False
        self.controller.stop()
        self.doc.set_scene(starter_scene(), None)
        self._remember_source(None, None)
        return True

    def open_dialog(self) -> bool:
        if not self.maybe_save():
            return False
        path = self.ask_open_path()
        return self.open_path(path, ask=False) if path else False

    def open_path(self, path: Path, *, ask: bool = True) -> bool:
        """Open a scene file; offers a newer autosave of it for recovery."""
        if ask and not self.maybe_save():
            return False
        path = Path(path)
        try:
            scene = load_scene(path)
        except WhittedError as exc:
            self.show_error("Cannot open the scene", str(exc))
            if not path.exists():
                self.recent.remove(path)
            return False
        self.controller.stop()
        self.doc.set_scene(scene, path)
        self._remember_source(scene, path)
        self.recent.add(path)
        self.offer_recovery()
        return True

    def _remember_source(self, scene: Scene | None, path: Path | None,
                         text: str | None = None) -> None:
        """Keep the TOML file's text as read (or written) and the scene it holds: saving
        writes only the edits into it (comments and layout stay)."""
        self.source_text: str | None = text
        self.source_scene: Scene | None = scene
        if text is None and path is not None and Path(path).suffix.lower() == ".toml":
            try:
                self.source_text = Path(path).read_text(encoding="utf-8")
            except OSError:
                self.source_text = None

    def offer_recovery(self) -> bool:
        """If an autosave of the current scene is newer than the file, offer it back."""
        auto = recovery_for(self.doc.path, self.autosave.folder)
        if auto is None:
            return False
        if not self.ask_recover(auto):
            self.autosave.discard()
            return False
        try:
            scene = self.autosave.recover(auto, self.doc.path)
        except WhittedError as exc:
            self.show_error("Cannot recover", str(exc))
            return False
        self.doc.set_scene(scene, self.doc.path, dirty=True)
        self.statusBar().showMessage(f"Recovered the unsaved changes from {auto.name}", 5000)
        return True

    def commit_pending_edit(self) -> None:
        """A value typed in a field but not yet committed (no Enter, no focus change) is
        committed before the scene is saved or rendered."""
        focus = QApplication.focusWidget()
        finish = getattr(focus, "finish", None)
        if focus is not None and self.isAncestorOf(focus) and callable(finish):
            finish()

    def save(self) -> bool:
        self.commit_pending_edit()
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def save_as(self, path: Path | None = None) -> bool:
        self.commit_pending_edit()
        path = path if path is not None else self.ask_save_path()
        return self.save_to(Path(path)) if path is not None else False

    def save_to(self, path: Path) -> bool:
        old_path = self.doc.path
        scene = self.doc.scene
        text = None
        try:
            if path.parent.resolve() != scene.base_dir.resolve():
                scene = rebase_files(scene, path.parent)
            if path.suffix.lower() == ".toml":
                same_folder = old_path is not None and old_path.parent.resolve() == \
                    path.parent.resolve()
                text = save_scene_toml(
                    scene, path, text=self.source_text if same_folder else None,
                    loaded=self.source_scene if same_folder else None)
            else:
                save_scene(scene, path)
        except (WhittedError, OSError, ValueError) as exc:
            self.show_error("Cannot save the scene", str(exc))
            return False
        self._remember_source(scene, path, text)
        if old_path is not None and old_path != path:
            self.autosave.discard(old_path)
        self.doc.mark_saved(path, scene.with_base_dir(path.parent))
        self.autosave.discard()
        self.recent.add(path)
        self.statusBar().showMessage(f"Saved {path}", 4000)
        return True

    def save_image(self, path: Path | None = None) -> bool:
        image = self.controller.last_image
        note = ""
        if image is None:
            image = self.controller.last_preview
            note = " (the preview: render for the full picture)"
        if image is None:
            self.show_error("No picture yet", "Render the scene first (Ctrl+R).")
            return False
        path = path if path is not None else self.ask_image_path()
        if path is None:
            return False
        try:
            image.save(path)
        except (ValueError, OSError) as exc:
            self.show_error("Cannot save the image", str(exc))
            return False
        self.statusBar().showMessage(f"Saved {path}{note}", 5000)
        return True

    def _fill_recent(self) -> None:
        self.recent_menu.clear()
        paths = self.recent.paths()
        for p in paths:
            action = self.recent_menu.addAction(str(p))
            action.triggered.connect(lambda checked=False, p=p: self.open_path(p))
        if not paths:
            self.recent_menu.addAction("(none)").setEnabled(False)

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802
        self.commit_pending_edit()
        if not self.maybe_save():
            event.ignore()
            return
        if not self.doc.dirty:
            self.autosave.discard()
        self.autosave.timer.stop()
        self.controller.shutdown()
        event.accept()

    # ------------------------------------------------------------------ edits

    def select(self, key) -> None:
        """Select ``key`` (None: nothing): the tree, the properties panel and the picture's
        outline all follow the document's one selection."""
        self.doc.select(key)

    def add_object(self, kind: str) -> tuple:
        obj = catalog.new_object(self.doc.scene, kind)
        return self.doc.add("objects", obj, f"Add {kind}")

    def add_light(self, kind: str) -> tuple:
        light = catalog.new_light(self.doc.scene, kind)
        return self.doc.add("lights", light, f"Add {kind} light")

    def add_model(self, path: Path | None = None) -> tuple | None:
        if path is None:
            name = self.choose_file("Add a model", catalog_model_filter())
            if not name:
                return None
            path = Path(name)
        try:
            obj = catalog.new_model(self.doc.scene, Path(path))
        except (ValueError, EditRefused) as exc:
            self.show_error("Cannot add the model", str(exc))
            return None
        scale = obj.transform.scale if obj.transform is not None else 1.0
        if scale != 1.0:
            self.statusBar().showMessage(
                f"{Path(path).name} was scaled by {scale:g} to a sensible size "
                "(Placement > Scale)", 8000)
        return self.doc.add("objects", obj, f"Add model {Path(path).name}")

    def delete_selected(self) -> bool:
        return self.doc.delete(self.doc.selection)

    def duplicate_selected(self):
        return self.doc.duplicate(self.doc.selection)

    def rename_selected(self) -> None:
        key = self.doc.selection
        item = self.tree.item_for(key) if key is not None else None
        if item is not None and len(key) == 2:
            self.tree.editItem(item, 0)

    # ------------------------------------------------------------------ pointing

    def pick(self, u: float, v: float, modifiers=None) -> tuple | None:
        """A click on the picture at (u, v): select the object seen there (through the
        renderer's object-id image); a click on the background deselects."""
        if not (0 <= u <= 1 and 0 <= v <= 1):
            return None
        try:
            ids = self.ids.ids_for(self.timeline.still(self.doc.scene))
        except WhittedError as exc:
            self.statusBar().showMessage(f"Cannot pick: {exc}", 4000)
            return None
        light = self.light_at(u, v)
        index = id_at(ids, u, v)
        key = light if light is not None else ("objects", index) if index >= 0 else None
        self.select(key)
        return key

    LIGHT_PICK_PX = 12

    def _light_marks(self):
        """(key, picture point (u, v)) of every light with a place in the scene."""
        scene = self.doc.scene
        s = scene.render
        for i, light in enumerate(scene.lights):
            p = light_position(light)
            uv = camera_ops.project(scene.camera, s.width, s.height, p) if p else None
            if uv is not None:
                yield ("lights", i), uv

    def light_at(self, u: float, v: float):
        """The light whose mark is within a few pixels of (u, v), if any."""
        here = self.viewport.to_widget(u, v)
        best, best_d = None, float(self.LIGHT_PICK_PX)
        for key, (lu, lv) in self._light_marks():
            p = self.viewport.to_widget(lu, lv)
            d = math.hypot(p.x() - here.x(), p.y() - here.y())
            if d <= best_d:
                best, best_d = key, d
        return best

    def _draw_overlay(self, p: QPainter, to_widget) -> None:
        """Over the picture: lights (a sun mark, named), the camera's target (a cross), and
        the selected object's bounding box."""
        scene = self.doc.scene
        s = scene.render
        cam = scene.camera
        selected = self.doc.selection
        if selected is not None and selected[0] == "objects":
            bounds = object_bounds(scene, selected[1])
            if bounds is not None:
                lo, hi = bounds
                corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                           for z in (lo[2], hi[2])]
                uvs = [camera_ops.project(cam, s.width, s.height, c) for c in corners]
                pen = QPen(QColor(255, 150, 20, 170), 1, Qt.PenStyle.DashLine)
                p.setPen(pen)
                for a in range(8):
                    for b in range(a + 1, 8):
                        if bin(a ^ b).count("1") == 1 and uvs[a] and uvs[b]:
                            p.drawLine(to_widget(*uvs[a]), to_widget(*uvs[b]))
        target = camera_ops.project(cam, s.width, s.height, camera_ops.target_of(cam))
        if target is not None:
            c = to_widget(*target)
            p.setPen(QPen(QColor(255, 255, 255, 150), 1))
            p.drawLine(c + QPointF(-7, 0), c + QPointF(7, 0))
            p.drawLine(c + QPointF(0, -7), c + QPointF(0, 7))
        for key, uv in self._light_marks():
            c = to_widget(*uv)
            light = scene.lights[key[1]]
            colour = QColor(255, 150, 20) if key == selected else QColor(255, 230, 90)
            p.setPen(QPen(QColor(0, 0, 0, 160), 3))
            p.drawEllipse(c, 5, 5)
            p.setPen(QPen(colour, 1.5))
            p.setBrush(colour)
            p.drawEllipse(c, 4, 4)
            p.setBrush(Qt.BrushStyle.NoBrush)
            for k in range(8):
                a = k * math.pi / 4
                d = QPointF(math.cos(a), math.sin(a))
                p.drawLine(c + d * 6.5, c + d * 10)
            p.setPen(QColor(0, 0, 0))
            p.drawText(c + QPointF(13, 5), label_of(light))
            p.setPen(colour)
            p.drawText(c + QPointF(12, 4), label_of(light))

    def _update_outline(self) -> None:
        """The selected object's outline over the picture (from the current id image)."""
        key = self.doc.selection
        ids = self.ids.ids if self.ids.scene is self.timeline.still(self.doc.scene) else None
        if key is None or key[0] != "objects":
            outline = None
        elif ids is None:
            self.ids.request(self.timeline.still(self.doc.scene))
            return
        else:
            outline = outline_image(ids, key[1])
        if outline is not self.viewport.outline:
            self.viewport.outline = outline
            self.viewport.update()

    def _viewport_key(self, event) -> bool:
        """The picture's keys: G/R/S move, rotate, scale the selection; F frames it, Home
        frames everything; numpad 1/3/7 (or 1/3/7) look from the front, the right, the top
        (with Ctrl: the back, the left, the bottom)."""
        key = event.key()
        mods = event.modifiers()
        ctrl = bool(mods & Qt.KeyboardModifier.ControlModifier)
        tools = {Qt.Key.Key_G: "move", Qt.Key.Key_R: "rotate", Qt.Key.Key_S: "scale"}
        if key in tools and not ctrl:
            return self.start_tool(tools[key])
        if key == Qt.Key.Key_F and not ctrl:
            return self.frame_selection()
        if key == Qt.Key.Key_Home:
            return self.frame_all()
        views = {Qt.Key.Key_1: (0.0, 0.0, 1.0), Qt.Key.Key_3: (1.0, 0.0, 0.0),
                 Qt.Key.Key_7: (0.0, 1.0, 0.0)}
        if key in views and (not ctrl or mods & Qt.KeyboardModifier.KeypadModifier):
            d = np.asarray(views[key]) * (-1.0 if ctrl else 1.0)
            return self.view_from(d, {Qt.Key.Key_1: "front", Qt.Key.Key_3: "side",
                                      Qt.Key.Key_7: "top"}[key])
        return False

    def start_tool(self, mode: str) -> bool:
        key = self.doc.selection
        if key is None or len(key) != 2 or self.viewport.tool is not None:
            return False
        if key[0] == "lights" and (mode != "move" or light_position(
                self.doc.item(key)) is None):
            return False
        start = self.viewport.hover
        if self.viewport.to_picture(start) is None:
            start = self.viewport.picture_rect().center()
        tool = TransformTool(mode, self.doc.scene, key[1], start,
                             (self.viewport.width(), self.viewport.height()),
                             apply=lambda t, merge: self._tool_edit(key, t, merge, mode),
                             finish=self._tool_finished,
                             status=lambda text: self.statusBar().showMessage(text),
                             kind=key[0])
        tool.start_uv = tool.uv = self.viewport.to_picture(start)
        self.viewport.tool = tool
        self._tool_edits = 0
        self._interacting(True)
        return True

    def _tool_edit(self, key, transform, merge, mode: str) -> None:
        item = self.doc.item(key)
        data = item.model_dump()
        if key[0] == "lights":  # a light moves by the vector: from where it was at the start
            tool = self.viewport.tool
            field = "position" if "position" in data else "center"
            start = tool.centre if tool is not None else np.asarray(data[field])
            data[field] = tuple(round(float(v), 6) + 0.0 for v in start + transform)
        else:
            data["transform"] = transform.model_dump()
        try:
            before = self.doc.undo_stack.index()
            self.doc.edit_item(key, data, f"{TransformTool.NAMES[mode]} {label_of(item)}",
                               merge_key=merge)
            self._tool_edits += self.doc.undo_stack.index() != before or self._tool_edits > 0
        except EditRefused as exc:
            self.statusBar().showMessage(str(exc), 3000)

    def _tool_finished(self, confirmed: bool, tool) -> None:
        self.viewport.tool = None
        self._interacting(False)
        if not confirmed and self._tool_edits:
            stack = self.doc.undo_stack
            command = stack.command(stack.index() - 1)
            if command is not None and getattr(command, "merge_key", None) == tool.merge_key:
                command.forget_on_undo = True  # no redo of a cancelled move
                stack.undo()
        self.statusBar().showMessage("" if confirmed else "Cancelled", 2000)
        self.viewport.update()

    def frame_selection(self) -> bool:
        key = self.doc.selection
        if key is None or key[0] != "objects":
            return self.frame_all()
        bounds = object_bounds(self.doc.scene, key[1])
        if bounds is None:
            c = object_centre(self.doc.scene, key[1])
            bounds = (c - 1.0, c + 1.0)
        self._frame(*bounds, "Frame selection")
        return True

    def frame_all(self) -> bool:
        scene = self.doc.scene
        boxes = [b for i in range(len(scene.objects))
                 if (b := object_bounds(scene, i)) is not None]
        if not boxes:
            return False
        lo = np.min([b[0] for b in boxes], axis=0)
        hi = np.max([b[1] for b in boxes], axis=0)
        self._frame(lo, hi, "Frame all")
        return True

    def _frame(self, lo, hi, text: str) -> None:
        s = self.doc.scene.render
        try:
            camera = camera_ops.frame_bounds(self.doc.scene.camera, s.width, s.height, lo, hi)
        except ValueError:
            return
        self._camera_edit(camera, text, None)

    def view_from(self, direction, name: str) -> bool:
        camera = self.doc.scene.camera
        target = camera_ops.target_of(camera)
        distance = float(np.linalg.norm(np.subtract(camera.position, target)))
        try:
            camera = camera_ops.look_from(camera, direction, target, distance)
        except ValueError:
            return False
        self._camera_edit(camera, f"View from the {name}", None)
        return True

    def _camera_edit(self, camera, text: str, merge) -> None:
        try:
            # the view moves; the selection stays (the camera's panel, if shown, follows)
            self.doc.edit_item(CAMERA, camera.model_dump(), text, merge_key=merge,
                               select=False)
        except EditRefused as exc:
            self.statusBar().showMessage(str(exc), 3000)

    def _orbit(self, yaw: float, pitch: float, drag: int) -> None:
        try:
            camera = camera_ops.orbit(self.doc.scene.camera, yaw, pitch)
        except ValueError:
            return
        self._camera_edit(camera, "Orbit camera", ("orbit", drag))

    def _pan(self, dx: float, dy: float, drag: int) -> None:
        try:
            camera = camera_ops.pan(self.doc.scene.camera, dx, dy)
        except ValueError:
            return
        self._camera_edit(camera, "Pan camera", ("pan", drag))

    def _zoom(self, factor: float, u: float = -1.0, v: float = -1.0) -> None:
        s = self.doc.scene.render
        try:
            camera = camera_ops.zoom_to(self.doc.scene.camera, factor, s.width, s.height, u, v)
        except ValueError:
            return
        # wheel notches in a row zoom as one step
        self._zoom_serial = getattr(self, "_zoom_serial", 0)
        if not getattr(self, "_zoom_timer", None):
            self._zoom_timer = QTimer(self)
            self._zoom_timer.setSingleShot(True)
            self._zoom_timer.setInterval(600)
            self._zoom_timer.timeout.connect(self._end_zoom)
        self._zoom_timer.start()
        self._camera_edit(camera, "Zoom camera", ("zoom", self._zoom_serial))

    def _end_zoom(self) -> None:
        self._zoom_serial += 1

    # ------------------------------------------------------------------ rendering

    def _interacting(self, on: bool) -> None:
        """A drag (mouse, slider, G/R/S) started or ended: coarse previews and no outline
        updates during it (the CPU goes to the picture), refinement and the outline after."""
        self.controller.set_interacting(on)
        if on and self.viewport.tool is not None:  # the object moves: its old outline goes
            self.viewport.outline = None          # (the bounding box follows it live)
        if not on:
            self._update_outline()

    def _update_preview_target(self) -> None:
        """Previews refine, when the input stops, up to the picture's size on screen."""
        r = self.viewport.fit_rect()
        ratio = self.viewport.devicePixelRatioF()
        self.controller.target_pixels = max(1, int(r.width() * r.height() * ratio * ratio))

    def _scene_changed(self, key=None) -> None:
        self._update_preview_target()
        scene = self.timeline.still(self.doc.scene)
        if self.doc.selection is not None and self.doc.selection[0] == "objects" \
                and not self.controller.interacting:  # (during a drag: when it ends)
            self.ids.request(scene)  # the outline follows
        self.viewport.set_aspect(scene.render.width, scene.render.height)
        self._update_title()
        if self.controller.rendering:
            self.controller.stop()
            self.statusBar().showMessage("Render stopped: the scene changed", 3000)
        self.controller.request_preview(scene)

    def start_render(self) -> None:
        self.commit_pending_edit()
        self.controller.render(self.timeline.still(self.doc.scene))
        self.progress.setValue(0)
        self.progress.show()
        self.eta.setText("starting…")
        self._update_render_actions()

    def escape(self) -> None:
        """Esc: cancel a G/R/S move; else stop a running render; else deselect."""
        if self.viewport.tool is not None:
            self.viewport.tool.cancel()
        elif self.controller.rendering:
            self.stop_render()
        else:
            self.select(None)

    def stop_render(self) -> None:
        if self.controller.rendering:
            self.controller.stop()
            self.eta.setText("stopping…")
            self.statusBar().showMessage("Stopping…")
            self.viewport.caption = "Stopping…"
            self.viewport.update()
            self.act_stop.setEnabled(False)  # until it has stopped

    def _update_render_actions(self) -> None:
        running = self.controller.rendering
        self.act_render.setEnabled(not running)
        self.act_stop.setEnabled(running)

    def _progress(self, fraction: float, eta, text: str) -> None:
        self.progress.setValue(round(fraction * 1000))
        self.eta.setText(text)

    def _frame_shown(self, image, kind: str) -> None:
        self.viewport.caption = "preview" if kind == "preview" else ""

    def _render_finished(self, kind: str, text: str) -> None:
        if self.viewport.caption == "Stopping…":
            self.viewport.caption = ""
            self.viewport.update()
        self.statusBar().showMessage(text, 8000)
        self.progress.hide()
        self._update_render_actions()

    def _render_failed(self, kind: str, message: str) -> None:
        self.viewport.caption = f"cannot render: {message}"
        self.viewport.update()
        self.statusBar().showMessage(f"Cannot {kind}: {message}", 8000)
        if not self.controller.rendering:
            self.progress.hide()
        self._update_render_actions()

    def _kernels_ready(self, seconds: float) -> None:
        if self.viewport.caption.startswith("Loading"):
            self.viewport.caption = ""
            self.viewport.update()
        if seconds > 1:
            self.statusBar().showMessage(f"Render kernels ready ({seconds:.0f} s)", 4000)

    def _status(self, text: str) -> None:
        self.statusBar().showMessage(text, 3000)

    def _toggle_preview(self, on: bool) -> None:
        self.controller.preview_enabled = on
        if on:
            self.controller.request_preview(self.timeline.still(self.doc.scene))


def catalog_model_filter() -> str:
    from .fields import MODEL_FILTER

    return MODEL_FILTER


__all__ = ["MainWindow", "get_path", "label_of", "rebuild_scene", "set_path", "starter_scene"]
