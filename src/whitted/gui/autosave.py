"""Periodic autosave beside the scene file (``.NAME.autosave.toml`` next to ``NAME.toml``;
untitled scenes in the editor's data folder), offered back for recovery after a crash. A clean
save or a deliberate discard removes it. The name is whitted's choice, not the user's: a file
there that whitted did not write (its record, :mod:`whitted.output.ownership`) is neither
written over nor removed; the status bar says the autosave is off for it."""

from __future__ import annotations

import os
from pathlib import Path

from PySide6.QtCore import QObject, QStandardPaths, QTimer, Signal

from ..output.ownership import exists, record_written, recorded_by_whitted
from ..scene import load_scene, save_scene
from .document import SceneDocument

INTERVAL_MS = 60_000
UNTITLED = "untitled.autosave.toml"


def default_folder() -> Path:
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".local" / "share" / "whitted")


def autosave_path(scene_path: Path | None, untitled_folder: Path) -> Path:
    """Where the autosave of ``scene_path`` goes (the untitled one when None)."""
    if scene_path is None:
        return untitled_folder / UNTITLED
    suffix = scene_path.suffix if scene_path.suffix in (".toml", ".json") else ".toml"
    return scene_path.with_name(f".{scene_path.stem}.autosave{suffix}")


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
        if exists(target) and not recorded_by_whitted(target):
            self.saved.emit(f"Autosave off: {target.name} is there and whitted did not write "
                            "it (it is kept)")
            return None
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            save_scene(self.doc.scene, target)
        except OSError as exc:  # a read-only folder: nothing to do but say so
            self.saved.emit(f"Autosave failed: {exc.strerror or exc}")
            return None
        record_written(target)
        self._saved_revision = self.doc.revision
        self.saved.emit(f"Autosaved to {target.name}")
        return target

    def discard(self, scene_path: Path | None = None) -> None:
        """Remove the autosave (after a save, or when the user throws the changes away)."""
        target = autosave_path(scene_path if scene_path is not None else self.doc.path,
                               self.folder)
        self._saved_revision = -1
        if not recorded_by_whitted(target):  # not whitted's (or gone): kept
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
