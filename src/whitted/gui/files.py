"""The editor's files: New, Open, Open Recent, Save, Save As, Save Image, the unsaved-changes
prompt and autosave recovery. Saving a TOML file writes only the edits into the text as it
was read (comments and layout stay); when the file's own style cannot carry an edit, the user
is asked before the whole file is written afresh: a save never silently rewrites a file."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QApplication

from .. import scene as S
from ..errors import WhittedError
from ..scene import Scene, load_scene
from ..scene.toml_document import edited_toml
from ..scene.writing import for_folder, scene_text, write_scene_text
from .autosave import recovery_for
from .keyframes import unposed


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


class FileControl(QObject):
    """Every dialog goes through the window (``window.ask_...``), so tests can answer."""

    def __init__(self, window, scene: Scene, path: Path | None) -> None:
        super().__init__(window)
        self.window_ = window
        self.doc = window.doc
        self.remember_source(scene, path)

    @property
    def status(self):
        return self.window_.statusBar()

    def scene_name(self) -> str:
        return self.doc.path.name if self.doc.path else "the untitled scene"

    def update_title(self, *_: object) -> None:
        name = self.doc.path.name if self.doc.path else "untitled"
        self.window_.setWindowTitle(f"{name}[*] — whitted")
        self.window_.setWindowModified(self.doc.dirty)

    def maybe_save(self) -> bool:
        """Before the scene goes away: True when it may go (saved or discarded)."""
        if not self.doc.dirty:
            return True
        answer = self.window_.ask_unsaved()
        if answer == "save":
            return self.save()
        if answer == "discard":
            self.window_.autosave.discard()
            return True
        return False

    def new_scene(self) -> bool:
        if not self.maybe_save():
            return False
        self.window_.controller.stop()
        self.doc.set_scene(starter_scene(), None)
        self.source_path = None
        self.remember_source(None, None)
        return True

    def open_dialog(self) -> bool:
        if not self.maybe_save():
            return False
        path = self.window_.ask_open_path()
        return self.open_path(path, ask=False) if path else False

    def open_path(self, path: Path, *, ask: bool = True) -> bool:
        """Open a scene file; offers a newer autosave of it for recovery."""
        if ask and not self.maybe_save():
            return False
        path = Path(path)
        try:
            scene = load_scene(path)
        except WhittedError as exc:
            self.window_.show_error("Cannot open the scene", str(exc))
            if not path.exists():
                self.window_.recent.remove(path)
            return False
        self.window_.controller.stop()
        self.doc.set_scene(scene, path)
        self.source_path = None  # read afresh: what earlier saves wrote is forgotten
        self.remember_source(scene, path)
        self.window_.recent.add(path)
        self.offer_recovery()
        return True

    def remember_source(self, scene: Scene | None, path: Path | None,
                        text: str | None = None) -> None:
        """Keep the TOML file's text as read (or written) and the scene it holds: saving
        writes only the edits into it (comments and layout stay). The versions written
        before, while the same file stays open, lend their spellings: a value or an object
        set back is written as the file first had it, comments included."""
        same_file = path is not None and getattr(self, "source_path", None) == path
        history = list(getattr(self, "history", [])) if same_file else []
        if same_file and self.source_text is not None and self.source_scene is not None:
            history.append((self.source_text, self.source_scene))
        # the file as first read, and the last few saves (each is parsed at every save)
        self.history: list[tuple[str, Scene]] = history[:1] + history[1:][-3:]
        self.source_path = path
        self.source_text: str | None = text
        self.source_scene: Scene | None = scene
        if text is None and path is not None and Path(path).suffix.lower() == ".toml":
            try:
                self.source_text = Path(path).read_text(encoding="utf-8")
            except OSError:
                self.source_text = None

    def offer_recovery(self) -> bool:
        """If an autosave of the current scene is newer than the file, offer it back."""
        autosave = self.window_.autosave
        auto = recovery_for(self.doc.path, autosave.folder)
        if auto is None:
            return False
        if not self.window_.ask_recover(auto):
            autosave.discard()
            return False
        try:
            scene = autosave.recover(auto, self.doc.path)
        except WhittedError as exc:
            self.window_.show_error("Cannot recover", str(exc))
            return False
        self.doc.set_scene(scene, self.doc.path, dirty=True)
        self.status.showMessage(f"Recovered the unsaved changes from {auto.name}", 5000)
        return True

    def commit_pending_edit(self) -> None:
        """A value typed in a field but not yet committed (no Enter, no focus change) is
        committed before the scene is saved or rendered."""
        focus = QApplication.focusWidget()
        finish = getattr(focus, "finish", None)
        if focus is not None and self.window_.isAncestorOf(focus) and callable(finish):
            finish()

    def save(self) -> bool:
        self.commit_pending_edit()
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def save_as(self, path: Path | None = None) -> bool:
        self.commit_pending_edit()
        path = path if path is not None else self.window_.ask_save_path()
        return self.save_to(Path(path)) if path is not None else False

    def _toml_text(self, scene: Scene, path: Path) -> str | None:
        """What to write into the TOML file ``path``: the file as read with only the edits
        in it; if that cannot be made, the whole scene afresh once the user agrees (None:
        the user said no)."""
        old_path = self.doc.path
        same_folder = old_path is not None and \
            Path(old_path).parent.resolve() == path.parent.resolve()  # the same file names
        if self.source_text is not None and self.source_scene is not None and same_folder:
            edited = edited_toml(scene, self.source_text, self.source_scene,
                                 history=self.history)
            if edited is not None:
                return edited
            if self.window_.ask_rewrite(path) != "rewrite":
                return None
        return scene_text(scene, path)

    def save_to(self, path: Path) -> bool:
        old_path = self.doc.path
        scene = self.doc.scene
        text = None
        try:
            # the values the tracks drive are shown posed at the current frame; the file
            # keeps its still values there
            written = for_folder(unposed(scene, self.source_scene), path)
            if path.suffix.lower() == ".toml":
                text = self._toml_text(written, path)
                if text is None:
                    self.status.showMessage("Not saved: the file was left as it was", 5000)
                    return False
            else:
                text = scene_text(written, path)
            write_scene_text(path, text)
        except (WhittedError, OSError, ValueError) as exc:
            self.window_.show_error("Cannot save the scene", str(exc))
            return False
        if path.suffix.lower() == ".toml":
            from ..scene.toml_document import read_toml

            self.remember_source(read_toml(text, written), path, text)
        else:
            self.remember_source(None, path)
        autosave = self.window_.autosave
        if old_path is not None and old_path != path:
            autosave.discard(old_path)
        self.doc.mark_saved(path, for_folder(scene, path).with_base_dir(path.parent))
        autosave.discard()
        self.window_.recent.add(path)
        self.status.showMessage(f"Saved {path}", 4000)
        return True

    def save_image(self, path: Path | None = None) -> bool:
        controller = self.window_.controller
        image = controller.last_image
        note = ""
        if image is None:
            image = controller.last_preview
            note = " (the preview: render for the full picture)"
        if image is None:
            self.window_.show_error("No picture yet", "Render the scene first (Ctrl+R).")
            return False
        path = path if path is not None else self.window_.ask_image_path()
        if path is None:
            return False
        try:
            image.save(path)
        except (ValueError, OSError) as exc:
            self.window_.show_error("Cannot save the image", str(exc))
            return False
        self.status.showMessage(f"Saved {path}{note}", 5000)
        return True

    def fill_recent(self) -> None:
        menu = self.window_.recent_menu
        menu.clear()
        paths = self.window_.recent.paths()
        for p in paths:
            action = menu.addAction(str(p))
            action.triggered.connect(lambda checked=False, p=p: self.open_path(p))
        if not paths:
            menu.addAction("(none)").setEnabled(False)


__all__ = ["FileControl"]
