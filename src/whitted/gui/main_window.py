"""The editor's window: scene tree (left), picture (centre), properties (right), menus and a
toolbar with Render / Stop, a progress bar with the time left. It puts its collaborators
together and owns every dialog (each behind one method, so the tests can answer them):

- :mod:`.actions`: the actions table (menus, shortcuts, Help > Controls)
- :mod:`.files`: New, Open, Save, Save image, the unsaved prompt, autosave recovery
- :mod:`.navigation`: the viewport's own view, camera view, set camera to view
- :mod:`.editing`: G/R/S, Delete, Duplicate, the Add menus, picking
- :mod:`.overlays`: what is drawn over the picture
- :mod:`.render_control`: Render / Stop, progress, the preview's size"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QCloseEvent, QCursor
from PySide6.QtWidgets import (
    QApplication,
    QDialog,
    QDialogButtonBox,
    QDockWidget,
    QFileDialog,
    QMainWindow,
    QMessageBox,
    QTextBrowser,
    QToolButton,
    QVBoxLayout,
)

from ..scene import Scene
from ..scene.default import default_scene
from . import catalog
from .actions import MENU_TEXT, ShortcutGuard, controls_html, fill_menus, make_actions
from .autosave import Autosave
from .document import (
    RENDER,
    SceneDocument,
    get_path,
    label_of,
    rebuild_scene,
    set_path,
)
from .editing import Editing
from .files import FileControl, starter_scene
from .icons import icon_for
from .navigation import Navigation
from .overlays import Overlays
from .picking import IdBuffer
from .properties import PropertyPanel
from .recent import RecentFiles
from .render_control import RenderControl
from .render_controller import RenderController
from .timeline import attach_timeline
from .tree import SceneTree
from .viewport import Viewport

SCENE_FILTER = "Scene files (*.toml *.json);;TOML scene (*.toml);;JSON scene (*.json)"
IMAGE_FILTER = "PNG image (*.png);;OpenEXR HDR image (*.exr);;All images (*.png *.exr *.jpg *.pfm)"
#: fits a 1366×768 screen with its panel and the title bar
WINDOW_SIZE = (1280, 680)


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
        self.properties.interacting.connect(self.interacting)
        self._dock(self.tree, "Scene", Qt.DockWidgetArea.LeftDockWidgetArea, 240)
        self._dock(self.properties, "Properties", Qt.DockWidgetArea.RightDockWidgetArea, 390)

        self.files = FileControl(self, scene, path)
        self.navigation = Navigation(self)
        self.editing = Editing(self)
        self.overlays = Overlays(self)
        self.ids = IdBuffer(self)
        self.child_ids = IdBuffer(self)  # a CSG child's own outline
        self.acts = make_actions(self)
        self.render_control = RenderControl(self)
        self._make_menus()
        self._make_toolbar()
        self.timeline = attach_timeline(self)  # frames of an animated scene, keys, films
        self._shown_cache: tuple = ()
        self._guard = ShortcutGuard(self)
        QApplication.instance().installEventFilter(self._guard)

        self.doc.changed.connect(self._scene_changed)
        self.doc.reset.connect(self._scene_reset)
        self.doc.path_changed.connect(self._update_title)
        self.doc.undo_stack.cleanChanged.connect(self._update_title)
        self.autosave.saved.connect(self._status)
        self.ids.ready.connect(self.overlays.update_outline)
        self.child_ids.ready.connect(self.overlays.update_outline)
        self.doc.selection_changed.connect(self._selection_changed)
        self.navigation.changed.connect(self._view_changed)
        self.viewport.clicked.connect(self.editing.pick)
        self.viewport.overlay = self.overlays.draw
        self.viewport.drag_started.connect(lambda: self.interacting(True))
        self.viewport.drag_finished.connect(lambda: self.interacting(False))
        self.viewport.orbit.connect(self.navigation.orbit)
        self.viewport.pan.connect(self.navigation.pan)
        self.viewport.zoom.connect(self.navigation.zoom)

        self._fit_window()
        self.files.update_title()
        self.render_control.update_actions()
        self.viewport.set_aspect(scene.render.width, scene.render.height)
        self.render_control.update_preview_target()
        if warm_up:
            self.controller.warm_up()
            self.render_control.show_warm_up()
            self.ids.warm_up(self.doc.scene)
        self.navigation.reset()
        self.controller.request_preview(self.shown_scene())

    # ------------------------------------------------------------------ layout

    def _dock(self, widget, title: str, area, width: int) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        self.addDockWidget(area, dock)
        self.resizeDocks([dock], [width], Qt.Orientation.Horizontal)
        if not hasattr(self, "_dock_widths"):
            self._dock_widths: list[tuple[QDockWidget, int]] = []
        self._dock_widths.append((dock, width))
        return dock

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        QTimer.singleShot(0, self.restore_docks)

    def restore_docks(self) -> None:
        """The panels' widths at the window's largest size are remembered; when the window
        comes back to that size (after it was made small and the panels squeezed), the
        panels get those widths back (Qt would give all the new room to the picture)."""
        docks = [d for d, _ in getattr(self, "_dock_widths", [])]
        if not docks:
            return
        width = self.width()
        memory = getattr(self, "_dock_memory", None)
        widths = [d.width() for d in docks]
        if memory is None or width > memory[0]:
            self._dock_memory = (width, widths)
        elif width >= memory[0] - 2:
            if widths != memory[1] and all(d.isVisible() and not d.isFloating()
                                           for d in docks):
                self.resizeDocks(docks, memory[1], Qt.Orientation.Horizontal)
            self._dock_memory = (width, [d.width() for d in docks])

    def _fit_window(self) -> None:
        w, h = WINDOW_SIZE
        screen = self.screen()
        if screen is not None:
            avail = screen.availableGeometry()
            w, h = min(w, avail.width() - 20), min(h, avail.height() - 40)
        self.resize(max(w, 800), max(h, 500))

    def _make_menus(self) -> None:
        bar = self.menuBar()
        menus = {name: bar.addMenu(text) for name, text in MENU_TEXT.items()
                 if name != "Animation"}  # the timeline adds its menu, before Help
        fill_menus(self, self.acts, menus)
        file = menus["File"]
        self.recent_menu = file.addMenu("Open &Recent")
        file.insertMenu(self.acts["save"], self.recent_menu)
        self.recent_menu.aboutToShow.connect(self.files.fill_recent)
        add = bar.addMenu("&Add")
        self.add_menu = add
        bar.insertMenu(menus["Object"].menuAction(), add)
        self.add_object_menu = add.addMenu("&Object")
        self.object_actions: dict[str, QAction] = {}
        for kind, text in catalog.OBJECT_KINDS.items():
            action = self.add_object_menu.addAction(icon_for(kind), text)
            action.triggered.connect(lambda checked=False, k=kind: self.add_object(k))
            self.object_actions[kind] = action
        self.add_object_menu.addSeparator()
        self.act_model = self.add_object_menu.addAction(icon_for("mesh"), "Model from file…")
        self.act_model.setToolTip("OBJ, PLY, STL, OFF, glTF")
        self.act_model.triggered.connect(lambda checked=False: self.add_model())
        self.act_model.setEnabled(catalog.HAS_MESH)
        self.add_light_menu = add.addMenu("&Light")
        self.light_actions: dict[str, QAction] = {}
        for kind, text in catalog.LIGHT_KINDS.items():
            action = self.add_light_menu.addAction(icon_for(f"light:{kind}"), text)
            action.triggered.connect(lambda checked=False, k=kind: self.add_light(k))
            self.light_actions[kind] = action
        self.view_menu = menus["View"]
        preview = self.acts["preview"]
        preview.blockSignals(True)  # on from the start: nothing to do yet
        preview.setChecked(self.controller.preview_enabled)
        preview.blockSignals(False)

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
        tools.addActions([self.acts["render"], self.acts["stop"]])

    def __getattr__(self, name: str):
        """``act_<name>``: the action of the table's row ``name``."""
        if name.startswith("act_"):
            acts = self.__dict__.get("acts")
            if acts is not None and name[4:] in acts:
                return acts[name[4:]]
        raise AttributeError(name)

    # ------------------------------------------------------------------ dialogs (tests answer)

    def ask_unsaved(self) -> str:
        """'save', 'discard' or 'cancel' for unsaved changes."""
        buttons = (QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                   | QMessageBox.StandardButton.Cancel)
        answer = QMessageBox.question(
            self, "Unsaved changes", f"Save the changes to {self.files.scene_name()}?", buttons,
            QMessageBox.StandardButton.Save)
        return {QMessageBox.StandardButton.Save: "save",
                QMessageBox.StandardButton.Discard: "discard"}.get(answer, "cancel")

    def ask_rewrite(self, path: Path) -> str:
        """The edits cannot be written into the file as it is written: 'rewrite' the whole
        file (its comments and layout go), or 'cancel' (the file stays as it is)."""
        box = QMessageBox(QMessageBox.Icon.Warning, "Rewrite the whole file?",
                          f"The changes cannot be written into {path.name} as it is laid out. "
                          "Saving would write the whole file afresh: its comments and layout "
                          "would be lost. (Save As… keeps this file as it is.)", parent=self)
        rewrite = box.addButton("Rewrite the file", QMessageBox.ButtonRole.DestructiveRole)
        box.addButton(QMessageBox.StandardButton.Cancel)
        box.exec()
        return "rewrite" if box.clickedButton() is rewrite else "cancel"

    def ask_save_for_film(self) -> bool:
        """The film is rendered from the scene's file: save the changes first? (True:
        save; False: no film)."""
        answer = QMessageBox.question(
            self, "Save before the film?",
            f"The film is rendered from the scene's file. Save the changes to "
            f"{self.files.scene_name()} first?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Cancel,
            QMessageBox.StandardButton.Save)
        return answer == QMessageBox.StandardButton.Save

    def ask_recover(self, autosave: Path) -> bool:
        answer = QMessageBox.question(
            self, "Recover unsaved changes?",
            f"{autosave.name} holds changes to {self.files.scene_name()} that were never saved "
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

    def show_add_menu(self) -> None:
        """Shift+A: the Add menu (objects, lights) under the pointer, as Blender's; at the
        picture's centre when the pointer is not over the window."""
        pos = QCursor.pos()
        if not self.rect().contains(self.mapFromGlobal(pos)):
            pos = self.viewport.mapToGlobal(self.viewport.rect().center())
        self.add_menu.popup(pos)

    def show_controls(self) -> None:
        """Help > Controls: made from the actions table, so it lists every shortcut."""
        dialog = QDialog(self)
        dialog.setWindowTitle("Controls")
        text = QTextBrowser(dialog)
        text.setHtml(controls_html())
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, dialog)
        buttons.rejected.connect(dialog.reject)
        layout = QVBoxLayout(dialog)
        layout.addWidget(text)
        layout.addWidget(buttons)
        dialog.resize(620, min(620, self.height()))  # scrolls on a small screen
        dialog.exec()

    # ------------------------------------------------------------------ what is shown

    def shown_scene(self) -> Scene:
        """The still the picture shows: the current frame's, through the view (or the
        camera in camera view). The same object while nothing changed (the id image and
        the previews are matched to it by identity)."""
        still = self.timeline.still(self.doc.scene)
        nav = self.navigation
        key = (still, nav.view, nav.camera_view)
        if self._shown_cache and all(a is b for a, b in zip(self._shown_cache[0], key,
                                                             strict=True)):
            return self._shown_cache[1]
        shown = nav.shown(still)
        self._shown_cache = (key, shown)
        return shown

    def interacting(self, on: bool) -> None:
        """A drag (mouse, slider, G/R/S) started or ended: coarse previews and no outline
        updates during it (the CPU goes to the picture), refinement and the outline after."""
        self.controller.set_interacting(on)
        if on and self.viewport.tool is not None:  # the object moves: its old outline goes
            self.viewport.outline = None          # (the bounding box follows it live)
        if not on:
            self.overlays.update_outline()

    def _selection_changed(self, *_: object) -> None:
        self.overlays.update_outline()
        self.viewport.update()

    def _view_changed(self) -> None:
        scene = self.shown_scene()
        if any(k[0] == "objects" for k in self.doc.selected_keys()) \
                and not self.controller.interacting:
            self.ids.request(scene)
        self.viewport.outline = None if self.ids.scene is not scene else self.viewport.outline
        self.viewport.update()
        if self.controller.rendering:
            self.controller.stop()
        self.controller.request_preview(scene)

    def _scene_changed(self, key=None) -> None:
        self.render_control.update_preview_target()
        scene = self.shown_scene()
        if any(k[0] == "objects" for k in self.doc.selected_keys()) \
                and not self.controller.interacting:  # (during a drag: when it ends)
            self.ids.request(scene)  # the outline follows
        self.viewport.set_aspect(scene.render.width, scene.render.height)
        self.files.update_title()
        if self.controller.rendering:
            self.controller.stop()
            self.statusBar().showMessage("Render stopped: the scene changed", 3000)
        self.controller.request_preview(scene)

    def _scene_reset(self) -> None:
        """New or Open: look through the new scene's camera; nothing of the last one's
        render is said."""
        self.render_control.forget()
        self.navigation.reset()

    def _update_title(self, *_: object) -> None:
        self.files.update_title()

    def _status(self, text: str) -> None:
        self.statusBar().showMessage(text, 3000)

    def select_render_settings(self) -> None:
        self.select(RENDER)

    def escape(self) -> None:
        """Esc: cancel a G/R/S move; else stop a running render; else deselect."""
        if self.viewport.tool is not None:
            self.viewport.tool.cancel()
        elif self.controller.rendering:
            self.stop_render()
        else:
            self.select(None)

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802
        self.files.commit_pending_edit()
        if not self.files.maybe_save():
            event.ignore()
            return
        if not self.doc.dirty:
            self.autosave.discard()
        self.autosave.timer.stop()
        self.controller.shutdown()
        QApplication.instance().removeEventFilter(self._guard)
        event.accept()

    # ------------------------------------------------------------------ the collaborators'
    # entry points, as the window's (scripts and tests call these)

    def select(self, key) -> None:
        """Select ``key`` (None: nothing; a list: all of them): the tree, the properties
        panel and the picture's outline all follow the document's one selection."""
        self.doc.select(key)

    def maybe_save(self) -> bool:
        return self.files.maybe_save()

    def new_scene(self) -> bool:
        return self.files.new_scene()

    def open_path(self, path: Path, *, ask: bool = True) -> bool:
        return self.files.open_path(path, ask=ask)

    def offer_recovery(self) -> bool:
        return self.files.offer_recovery()

    def commit_pending_edit(self) -> None:
        self.files.commit_pending_edit()

    def save(self) -> bool:
        return self.files.save()

    def save_as(self, path: Path | None = None) -> bool:
        return self.files.save_as(path)

    def save_to(self, path: Path) -> bool:
        return self.files.save_to(path)

    def save_image(self, path: Path | None = None) -> bool:
        return self.files.save_image(path)

    def _fill_recent(self) -> None:
        self.files.fill_recent()

    def add_object(self, kind: str) -> tuple:
        return self.editing.add_object(kind)

    def add_light(self, kind: str) -> tuple:
        return self.editing.add_light(kind)

    def add_model(self, path: Path | None = None) -> tuple | None:
        return self.editing.add_model(path)

    def delete_selected(self) -> bool:
        return self.editing.delete_selected()

    def duplicate_selected(self):
        return self.editing.duplicate_selected()

    def start_tool(self, mode: str) -> bool:
        return self.editing.start_tool(mode)

    def pick(self, u: float, v: float, modifiers=None) -> tuple | None:
        return self.editing.pick(u, v, modifiers)

    def _light_marks(self):
        return self.overlays.light_marks()

    def frame_all(self) -> bool:
        return self.navigation.frame_all()

    def start_render(self) -> None:
        self.render_control.start_render()

    def stop_render(self) -> None:
        self.render_control.stop_render()

    @property
    def progress(self):
        return self.render_control.progress

    @property
    def eta(self):
        return self.render_control.eta


__all__ = ["MainWindow", "get_path", "label_of", "rebuild_scene", "set_path", "starter_scene"]
