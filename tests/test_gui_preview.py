"""The preview keeps up: coarse while the user drags, refining to the
picture's full size on screen once the input stops, with no new edit. The times are written
to the test log (``-s`` or the captured output), not asserted: this machine is shared."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPointF, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import SLOW, make_window, mouse, type_into  # noqa: E402, F401
from whitted.gui.document import CAMERA  # noqa: E402


@pytest.mark.timing  # counts updates in a 2 s drag: depends on the machine's speed
def test_preview_is_coarse_while_dragging_and_refines_when_idle(make_window, qtbot):  # noqa: F811
    window = make_window(whitted.default_scene().with_settings(width=480, height=360))
    vp = window.viewport
    c = window.controller
    qtbot.waitUntil(lambda: c.previews_done > 0, timeout=SLOW)
    goal = min(c.target_pixels, 480 * 360)  # the picture's size on screen, at most 1:1

    def full() -> bool:
        return vp.image is not None and vp.image.width() * vp.image.height() >= 0.98 * goal

    # idle: the picture refines to full size by itself
    qtbot.waitUntil(full, timeout=30_000)
    # an edit: first a coarse preview, then refinement up to full size, with no new edit
    c.edit_to_frame.clear()
    c.edit_to_full.clear()
    window.select(CAMERA)
    type_into(qtbot, window.properties.row("fov").editor.line, "35")
    qtbot.waitUntil(lambda: bool(c.edit_to_frame), timeout=SLOW)
    first_width = vp.image.width()
    qtbot.waitUntil(lambda: bool(c.edit_to_full) and full(), timeout=30_000)
    assert first_width < vp.image.width()  # the first look was coarse
    # a drag: previews keep coming while the mouse moves
    done = c.previews_done
    centre = QPointF(vp.rect().center())
    mouse(vp, "press", centre)
    t0 = time.perf_counter()
    moves = 0
    while time.perf_counter() - t0 < 2.0:
        moves += 1
        mouse(vp, "move", centre + QPointF(8 * moves % 300, 0), Qt.MouseButton.LeftButton)
        qtbot.wait(16)
    seconds = time.perf_counter() - t0
    during = c.previews_done - done
    widths = vp.image.width()
    mouse(vp, "release", centre + QPointF(8 * moves % 300, 0))
    released = time.perf_counter()
    qtbot.waitUntil(lambda: full() and c.preview is None, timeout=30_000)
    refine = time.perf_counter() - released
    assert during >= 3  # updates keep coming during the drag
    assert widths <= vp.image.width()
    print(f"\n[preview] edit -> first update {1000 * c.edit_to_frame[0]:.0f} ms "
          f"(width {first_width}); edit -> full size {1000 * c.edit_to_full[0]:.0f} ms; "
          f"drag: {during / seconds:.1f} updates/s at width {widths}; "
          f"release -> full size ({vp.image.width()}x{vp.image.height()}) {1000 * refine:.0f} ms")


@pytest.mark.timing  # counts updates in a 2 s drag: depends on the machine's speed
def test_g_move_drag_rate_is_logged(make_window, qtbot):  # noqa: F811
    """A G move changes the geometry, so every preview compiles the scene again: its rate
    (written to the log) is the slowest kind of drag."""
    window = make_window(whitted.default_scene().with_settings(width=480, height=360))
    vp = window.viewport
    c = window.controller
    qtbot.waitUntil(lambda: c.previews_done > 0, timeout=SLOW)
    window.select(("objects", 1))
    before = window.doc.item(("objects", 1)).center
    centre = QPointF(vp.rect().center())
    mouse(vp, "move", centre, Qt.MouseButton.NoButton)
    qtbot.keyClick(vp, Qt.Key.Key_G)
    done = c.previews_done
    t0 = time.perf_counter()
    moves = 0
    while time.perf_counter() - t0 < 2.0:
        moves += 1
        mouse(vp, "move", centre + QPointF(3 * (moves % 60), 0), Qt.MouseButton.NoButton)
        qtbot.wait(16)
    rate = (c.previews_done - done) / (time.perf_counter() - t0)
    width = vp.image.width()
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert window.doc.item(("objects", 1)).center != before  # G moves a sphere's centre
    assert c.previews_done - done >= 3
    print(f"\n[preview] G-move drag (geometry rebuilt each time): {rate:.1f} updates/s "
          f"at width {width}")
