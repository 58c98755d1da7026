"""The viewport as a 3-D view (issue 14, section 2), driven by real clicks and keys: picking
through the object-id image, the outline, Esc, moving with G, turntable orbit, framing and
the numpad views."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import SLOW, make_window  # noqa: E402, F401
from whitted.gui.picking import object_ids  # noqa: E402


@pytest.fixture
def window(make_window):  # noqa: F811 - the fixture of gui_input
    return make_window(whitted.gui.main_window.starter_scene().with_settings(
        width=160, height=120), preview=False, warm_up=False)


def pixel_of(window, index: int) -> QPoint:
    """A widget position where object ``index`` is seen (the middle of its pixels)."""
    ids = object_ids(window.doc.scene, 160, 120)
    ys, xs = np.nonzero(ids == index)
    assert len(xs), index
    k = len(xs) // 2
    order = np.lexsort((xs, ys))
    y, x = ys[order[k]], xs[order[k]]
    p = window.viewport.to_widget((x + 0.5) / 160, (y + 0.5) / 120)
    return QPoint(round(p.x()), round(p.y()))


def test_click_picks_the_object_under_the_pointer_and_esc_deselects(window, qtbot):
    vp = window.viewport
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=pixel_of(window, 1))
    assert window.doc.selection == ("objects", 1)
    assert "ball" in window.properties.title.text()
    assert window.tree.currentItem() is window.tree.item_for(("objects", 1))
    qtbot.waitUntil(lambda: vp.outline is not None, timeout=SLOW)
    # the outline is drawn where the ball's edge is
    outline = vp.outline
    assert outline.width() == window.ids.ids.shape[1]
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=pixel_of(window, 0))
    assert window.doc.selection == ("objects", 0)
    # the sky: nothing
    top = vp.to_widget(0.5, 0.02)
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=QPoint(round(top.x()), round(top.y())))
    assert window.doc.selection is None
    assert window.properties.title.text() == "Nothing selected"
    assert vp.outline is None
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=pixel_of(window, 1))
    qtbot.keyClick(vp, Qt.Key.Key_Escape)
    assert window.doc.selection is None and not window.tree.selectedItems()
