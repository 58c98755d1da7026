"""The recent files list (Open Recent), kept in QSettings."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSettings

KEY = "recent_files"
LIMIT = 8


class RecentFiles:
    def __init__(self, settings: QSettings) -> None:
        self.settings = settings

    def paths(self) -> list[Path]:
        value = self.settings.value(KEY, [])
        if isinstance(value, str):  # QSettings gives a lone string for one entry
            value = [value]
        return [Path(p) for p in (value or []) if p]

    def add(self, path: Path) -> None:
        text = str(Path(path).resolve())
        items = [text] + [str(p) for p in self.paths() if str(p) != text]
        self.settings.setValue(KEY, items[:LIMIT])
        self.settings.sync()

    def remove(self, path: Path) -> None:
        text = str(path)
        self.settings.setValue(KEY, [str(p) for p in self.paths() if str(p) != text])
        self.settings.sync()

    def clear(self) -> None:
        self.settings.setValue(KEY, [])
