"""``whitted gui MODEL``: the editor opens the quick-look scene of a model file (the same
scene ``whitted render MODEL`` renders) as an untitled scene, and saves it as a scene file
that finds the model again."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest  # noqa: E402

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QSettings  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

import whitted  # noqa: E402
from whitted.gui.main_window import MainWindow  # noqa: E402
from whitted.program import app as cli_app  # noqa: E402

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def test_gui_opens_the_models_scene_untitled(tmp_path, monkeypatch):
    model = tmp_path / "tetra.obj"
    model.write_text(TETRA)
    seen = []
    import whitted.gui.app as gui_app

    monkeypatch.setattr(gui_app, "run_editor",
                        lambda scene, path, **options: seen.append((scene, path)) or 0)
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli_app, ["gui", "tetra.obj"])
    assert result.exit_code == 0, result.output
    scene, path = seen[0]
    assert path is None  # untitled: Save asks where; the model file is never written
    assert scene == whitted.model_scene("tetra.obj")
    seen.clear()
    result = CliRunner().invoke(cli_app, ["gui", "glass_cube"])  # an example, untitled too
    assert result.exit_code == 0 and seen[0][1] is None and seen[0][0].objects
    (tmp_path / "empty.stl").write_text("")
    result = CliRunner().invoke(cli_app, ["gui", "empty.stl"])
    assert result.exit_code == 2 and "empty.stl" in result.output


def test_the_editor_saves_the_models_scene(qtbot, tmp_path):
    model = tmp_path / "models" / "tetra.obj"
    model.parent.mkdir()
    model.write_text(TETRA)
    scene = whitted.model_scene(model, width=48, height=36)
    window = MainWindow(scene, None, settings=QSettings(str(tmp_path / "s.ini"),
                                                        QSettings.Format.IniFormat),
                        autosave_folder=tmp_path / "auto", warm_up=False)
    window.ask_unsaved = lambda: "discard"
    qtbot.addWidget(window)
    assert window.doc.scene == scene
    saved = tmp_path / "elsewhere" / "tetra_scene.toml"
    saved.parent.mkdir()
    assert window.save_as(saved)
    loaded = whitted.load_scene(saved)
    assert loaded.camera == scene.camera and len(loaded.lights) == len(scene.lights)
    assert loaded.resolve_path(loaded.objects[0].file).resolve() == model.resolve()
