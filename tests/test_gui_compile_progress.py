"""The editor's first compile of the kernels shows real progress: how far along it is and the
time left at its pace, in the picture's caption and the status bar's progress bar, until the
kernels are ready."""

from __future__ import annotations

import os
import time

import pytest


def test_the_editor_shows_how_far_the_first_compile_is(qtbot, tmp_path, monkeypatch):
    pytest.importorskip("PySide6.QtWidgets")
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtCore import QSettings

    from whitted.gui.main_window import MainWindow, starter_scene
    from whitted.render import warm_up

    window = MainWindow(starter_scene().with_settings(width=32, height=24), None,
                        autosave_folder=tmp_path / "auto", warm_up=False,
                        settings=QSettings(str(tmp_path / "s.ini"), QSettings.Format.IniFormat))
    window.ask_unsaved = lambda: "discard"
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    controller = window.controller
    controller._warm.clear()  # as while the warm-up thread compiles
    monkeypatch.setattr(warm_up, "compile_progress", lambda: 0.25)
    seen = []
    controller.kernels_progress.connect(lambda fraction, left: seen.append((fraction, left)))
    controller._warm_started = time.perf_counter() - 10.0  # ten seconds into it
    controller._tick()
    assert seen and seen[-1][0] == 0.25
    assert seen[-1][1] == pytest.approx(30.0, rel=0.05)  # 10 s for a quarter: 30 s left
    window.render_control.show_warm_up()  # the picture's caption, as MainWindow starts it
    caption = window.viewport.caption
    assert caption.startswith("Compiling the kernels (the first run only): 25%")
    assert caption.endswith("s left")
    bar = window.render_control.progress
    assert bar.isVisible() and bar.value() == 250
    assert "s left" in window.render_control.eta.text()
    controller._warm_seconds = 12.0
    controller._warm.set()  # compiled: the caption and the bar go
    controller._tick()
    window.render_control._kernels_ready(12.0)
    assert window.viewport.caption == ""
    assert not bar.isVisible()
