"""``whitted gui [SCENE]``: start Qt, open the editor window, run the event loop."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from ..scene import Scene

#: Milliseconds between the moments the event loop lets Python run its signal handlers (a
#: SIGTERM to a waiting editor is handled within this time, not at the next user event).
SIGNAL_CHECK_MS = 200


def run_editor(scene: Scene | None = None, path: Path | None = None,
               on_running: Callable[[Callable[[], str]], None] | None = None) -> int:
    """Open the editor on ``scene`` (loaded from ``path``; None: the default scene, or a new
    scene to be saved at ``path``) and return the exit status when the window closes.
    Returns 2 with one line on stderr when Qt could not open a window here (missing system
    libraries), before Qt starts. ``on_running`` is given, once the window is open, what a
    process ended by a signal says (:func:`last_words`, which autosaves unsaved edits)."""
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
    if on_running is not None:
        from PySide6.QtCore import QTimer

        on_running(lambda: last_words(window))
        ticks = QTimer(window)  # Python's signal handlers run only while Python code runs
        ticks.timeout.connect(lambda: None)
        ticks.start(SIGNAL_CHECK_MS)
    if path is not None and path.exists():
        window.offer_recovery()
    elif path is None:
        window.offer_recovery()  # the untitled autosave left by a crashed editor
    return app.exec()


def last_words(window) -> str:
    """What the editor says when a signal ends the process: unsaved edits are written to the
    autosave first (offered back when the scene is opened again), and the sentence says
    where they are, or that there were none, or that they were lost."""
    autosave = window.autosave
    if not window.doc.dirty:
        return "the editor was closed; it had no unsaved edits"
    autosave.save_now()
    if not autosave.current:
        return "the editor was closed; its unsaved edits were lost (the autosave failed)"
    return (f"the editor was closed; its unsaved edits are kept in {autosave.path} "
            "(offered when the scene is opened again)")
