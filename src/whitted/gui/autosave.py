"""Periodic autosave beside the scene file (``.NAME.autosave.toml`` next to ``NAME.toml``;
untitled scenes in the editor's data folder), offered back for recovery after a crash. A clean
save or a deliberate discard removes it. The name is whitted's choice, not the user's: a file
there that whitted did not write is neither written over nor removed; the status bar says the
autosave is off for it. An autosave proves itself whitted's by its first line
(:data:`AUTOSAVE_MARK`, a TOML comment: the autosave is TOML whatever the scene file's
format), so the proof survives a cleared cache or a home folder where nothing else can be
recorded."""

from __future__ import annotations

import os
from pathlib import Path

from PySide6.QtCore import QObject, QStandardPaths, QTimer, Signal

from ..errors import WhittedError
from ..output.ownership import exists, recorded_by_whitted
from ..scene import load_scene
from ..scene.writing import for_folder, scene_text, write_scene_text
from .document import SceneDocument

INTERVAL_MS = 60_000
UNTITLED = "untitled.autosave.toml"
#: the first line of every autosave whitted writes: the file is whitted's to replace or remove
AUTOSAVE_MARK = "# whitted autosave: the editor's copy of unsaved edits (removed on save)\n"


def default_folder() -> Path:
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".local" / "share" / "whitted")


def autosave_path(scene_path: Path | None, untitled_folder: Path) -> Path:
    """Where the autosave of ``scene_path`` goes (the untitled one when None)."""
    if scene_path is None:
        return untitled_folder / UNTITLED
    return scene_path.with_name(f".{scene_path.stem}.autosave.toml")


def is_autosave(path: Path) -> bool:
    """Whether ``path`` is an autosave whitted wrote: its first line is the mark (or an
    earlier whitted recorded it)."""
    try:
        with open(path, "rb") as f:
            head = f.read(len(AUTOSAVE_MARK.encode()))
    except OSError:
        return False
    return head == AUTOSAVE_MARK.encode() or recorded_by_whitted(path)


def recovery_for(scene_path: Path | None, untitled_folder: Path) -> Path | None:
    """An autosave worth offering: there, and newer than the scene file."""
    auto = autosave_path(scene_path, untitled_folder)
    if not auto.is_file():
        return None
    if scene_path is not None and scene_path.is_file() and \
            auto.stat().st_mtime < scene_path.stat().st_mtime:
        return None
    return auto


class Autosave(QObject):
    saved = Signal(str)

    def __init__(self, doc: SceneDocument, *, interval_ms: int = INTERVAL_MS,
                 folder: Path | None = None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.folder = Path(folder) if folder is not None else default_folder()
        self._saved_revision = -1
        self.timer = QTimer(self)
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self.save_now)
        self.timer.start()

    @property
    def path(self) -> Path:
        return autosave_path(self.doc.path, self.folder)

    @property
    def current(self) -> bool:
        """Whether the autosave holds the document's present edits."""
        return self.doc.revision == self._saved_revision

    def save_now(self) -> Path | None:
        """Write the autosave if there are unsaved edits not autosaved yet."""
        if not self.doc.dirty or self.doc.revision == self._saved_revision:
            return None
        target = self.path
        if exists(target) and not is_autosave(target):
            self.saved.emit(f"Autosave off: {target.name} is there and whitted did not write "
                            "it (it is kept)")
            return None
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            moved = for_folder(self.doc.scene, target)
            write_scene_text(target, AUTOSAVE_MARK + scene_text(moved, target))
        except OSError as exc:  # a read-only folder: nothing to do but say so
            self.saved.emit(f"Autosave failed: {exc.strerror or exc}")
            return None
        except WhittedError as exc:
            self.saved.emit(f"Autosave failed: {exc}")
            return None
        self._saved_revision = self.doc.revision
        self.saved.emit(f"Autosaved to {target.name}")
        return target

    def discard(self, scene_path: Path | None = None) -> None:
        """Remove the autosave (after a save, or when the user throws the changes away)."""
        target = autosave_path(scene_path if scene_path is not None else self.doc.path,
                               self.folder)
        self._saved_revision = -1
        if not is_autosave(target):  # not whitted's (or gone): kept
            return
        try:
            os.remove(target)
        except FileNotFoundError:
            pass
        except OSError:
            pass

    def recover(self, autosave: Path, scene_path: Path | None):
        """The autosaved scene, with file names relative to the scene's own folder."""
        scene = load_scene(autosave)
        folder = scene_path.parent if scene_path is not None else autosave.parent
        return scene.with_base_dir(folder)
