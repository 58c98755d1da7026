"""A render's time left comes from what its tiles cost (measured by the
preview of the same picture), not from how many there are."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.gui.render_eta import CostClock, CostMap


def test_the_time_left_weighs_the_tiles_by_their_cost():
    """A 4x4 preview: the top half cost 8 rays (1 a pixel), the bottom half 24 (3 a
    pixel). A render of 8x8 that finished its top half in 2 s has done a quarter of the
    work: 6 s are left (counting tiles would say 2 s)."""
    cost = CostMap(4, 4)
    cost.learn(np.array([[0, 0, 4, 2]]), 8)
    assert not cost.complete
    cost.learn(np.array([[0, 2, 2, 4], [2, 2, 4, 4]]), 32)  # two tiles in one batch
    assert cost.complete
    assert cost.density[0, 0] == 1.0 and cost.density[3, 3] == 3.0
    shares = cost.scaled(8, 8)
    assert shares.sum() == pytest.approx(1.0)
    assert shares[:4].sum() == pytest.approx(0.25) and shares[4:].sum() == pytest.approx(0.75)
    clock = CostClock(shares)
    assert clock.eta(1.0) is None  # nothing done yet: no estimate
    clock.done(np.array([[0, 0, 8, 2], [0, 2, 8, 4]]))  # the top half, in two tiles
    assert clock.fraction == pytest.approx(0.25)
    assert clock.eta(2.0) == pytest.approx(6.0)
    clock.done(np.array([[0, 4, 8, 8]]))
    assert clock.fraction == pytest.approx(1.0) and clock.eta(8.0) == pytest.approx(0.0)


def test_a_batch_shares_only_the_rays_traced_since_the_last_one():
    cost = CostMap(2, 1)
    cost.learn(np.array([[0, 0, 1, 1]]), 10)
    cost.learn(np.array([[1, 0, 2, 1]]), 10)  # no new rays: that pixel cost nothing
    assert cost.density.tolist() == [[10.0, 0.0]]
    cost.learn(np.zeros((0, 4), np.int64), 50)  # an empty batch changes nothing
    assert cost.density.tolist() == [[10.0, 0.0]]


def test_each_tile_keeps_its_own_rays_whatever_the_batch():
    """A batch of two tiles with their own counts (what the render reports): the sky tile
    is not charged for the glass tile beside it, however the lanes batched them."""
    cost = CostMap(4, 2)
    cost.learn(np.array([[0, 0, 2, 2], [2, 0, 4, 2]]), 40, np.array([4, 36]))
    assert cost.complete
    assert cost.density[:, :2].tolist() == [[1.0, 1.0], [1.0, 1.0]]
    assert cost.density[:, 2:].tolist() == [[9.0, 9.0], [9.0, 9.0]]


def test_a_render_reports_each_tiles_rays():
    """RenderJob's progress carries each finished tile's rays; they add up to the rays."""
    from whitted import RenderJob
    from whitted.gui.main_window import starter_scene

    scene = starter_scene().with_settings(width=32, height=24, samples=1, threads=1)
    reports = []
    job = RenderJob(scene)
    job.progress = reports.append
    job.run()
    assert sum(len(p.tile_rays) for p in reports) == sum(len(p.new_tiles) for p in reports)
    assert sum(int(p.tile_rays.sum()) for p in reports) == reports[-1].rays > 0


def test_the_editor_says_the_time_left_from_the_previews_costs(qtbot, tmp_path):
    """In the editor: the preview of a picture that is sky above and glass below learns that
    the glass costs more rays a pixel; Ctrl+R then measures its progress in that cost."""
    pytest.importorskip("PySide6.QtWidgets")
    import os

    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtCore import QSettings, Qt

    from whitted import scene as S
    from whitted.gui.main_window import MainWindow, starter_scene

    scene = starter_scene().with_settings(width=96, height=72)
    glass = S.Sphere(name="glass", center=(0.0, 0.8, 2.5), radius=1.2, material="glass")
    scene = scene.model_copy(update={"objects": [scene.objects[0], glass]})
    window = MainWindow(scene, None, autosave_folder=tmp_path / "auto", warm_up=False,
                        settings=QSettings(str(tmp_path / "s.ini"), QSettings.Format.IniFormat))
    window.ask_unsaved = lambda: "discard"
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    controller = window.controller
    qtbot.waitUntil(lambda: controller.cost_map is not None
                    and controller.cost_map[1].width == 96 and controller.preview is None,
                    timeout=120_000)
    learnt, cost = controller.cost_map
    assert learnt == window.shown_scene()
    density = cost.density
    assert density[48:, 30:66].mean() > 2 * density[:8].mean()  # glass below, sky above
    texts = []
    controller.progress.connect(lambda fraction, eta, text: texts.append((fraction, text)))
    qtbot.keyClick(window.viewport, Qt.Key.Key_R, Qt.KeyboardModifier.ControlModifier)
    active = controller.full
    assert active is not None and active.clock is not None
    qtbot.waitUntil(lambda: not controller.rendering, timeout=120_000)
    assert active.clock.fraction == pytest.approx(1.0)
    assert texts and texts[-1][0] == pytest.approx(1.0)
    window.close()
