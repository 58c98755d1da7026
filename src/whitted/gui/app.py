"""``whitted gui [SCENE]``: start Qt, open the editor window, run the event loop."""

from __future__ import annotations

import sys
from pathlib import Path

from ..scene import Scene


def run_editor(scene: Scene | None = None, path: Path | None = None) -> int:
    """Open the editor on ``scene`` (loaded from ``path``; None: the default scene, or a new
    scene to be saved at ``path``) and return the exit status when the window closes.
    Returns 2 with one line on stderr when Qt could not open a window here (missing system
    libraries), before Qt starts."""
    from .system_check import display_problem

    problem = display_problem()
    if problem is not None:
        print(f"whitted gui: {problem}", file=sys.stderr)
        return 2
    from PySide6.QtWidgets import QApplication

    from .main_window import MainWindow, starter_scene

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("whitted")
    app.setOrganizationName("whitted")
    if scene is None and path is not None:  # a new file: start from the starter scene
        scene = starter_scene()
    window = MainWindow(scene, path)
    window.show()
    if path is not None and path.exists():
        window.offer_recovery()
    elif path is None:
        window.offer_recovery()  # the untitled autosave left by a crashed editor
    return app.exec()
