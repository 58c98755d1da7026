"""``whitted gui`` ended by SIGTERM or Ctrl-C while its window is open: the one line says what
happened to the editor (not "stopped before the command began"), and unsaved edits are
written to the autosave first, where the editor offers them back."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("PySide6.QtWidgets")

# the whitted program, with a signal sent to itself from the editor's event loop (once the
# window is open: the first turn of the loop), after an edit when asked
SCRIPT = """
import os, signal, sys
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication
app = QApplication(sys.argv[:1])
scene, what, signame = sys.argv[1:4]

def stop():
    from whitted.cli import interrupt
    from whitted.gui.main_window import MainWindow
    windows = [w for w in app.topLevelWidgets() if isinstance(w, MainWindow)]
    if not windows or not interrupt._running:  # the loop turned before the window was up
        QTimer.singleShot(20, stop)
        return
    window = windows[0]
    if what == "edit":
        from whitted.gui.document import RENDER
        window.doc.set_field(RENDER, ("samples",), 3, "Samples")
    os.kill(os.getpid(), getattr(signal, signame))

QTimer.singleShot(0, stop)
sys.argv = ["whitted", "gui", scene]
from whitted.program import main
main()
"""

SCENE = """\
[render]
width = 16
height = 12
samples = 1

[camera]
position = [0, 1, 6]
look_at = [0, 0.5, 0]

[[objects]]
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
"""


def _editor(tmp_path: Path, what: str, signame: str) -> subprocess.CompletedProcess:
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_DATA_HOME": str(tmp_path),
           "XDG_CONFIG_HOME": str(tmp_path)}
    return subprocess.run([sys.executable, "-c", SCRIPT, str(scene), what, signame],
                          capture_output=True, text=True, env=env, timeout=60, cwd=tmp_path)


def _last_line(done: subprocess.CompletedProcess) -> str:
    lines = [ln for ln in done.stderr.splitlines() if ln.strip()
             and "propagateSizeHints" not in ln]  # the offscreen platform's own note
    assert len(lines) == 1, done.stderr
    return lines[0]


def test_sigterm_to_an_open_editor_without_edits(tmp_path):
    done = _editor(tmp_path, "look", "SIGTERM")
    assert done.returncode == 143, done.stderr
    assert _last_line(done) == "terminated: the editor was closed; it had no unsaved edits"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml"]


def test_ctrl_c_to_an_editor_with_unsaved_edits_keeps_them_in_the_autosave(tmp_path):
    scene_text = SCENE
    done = _editor(tmp_path, "edit", "SIGINT")
    assert done.returncode == 130, done.stderr
    autosave = tmp_path / ".scene.autosave.toml"
    assert _last_line(done) == (
        f"interrupted: the editor was closed; its unsaved edits are kept in {autosave} "
        "(offered when the scene is opened again)")
    assert "samples = 3" in autosave.read_text()
    assert (tmp_path / "scene.toml").read_text() == scene_text  # the scene file untouched
