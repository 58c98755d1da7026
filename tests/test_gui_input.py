"""The editor driven as a person drives it (issue 14, section 1): real clicks, key presses and
wheel turns on the real widgets, offscreen. Each test failed on the editor before its fix."""

from __future__ import annotations

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import Qt  # noqa: E402

from gui_input import click_tree, make_window, type_into, wheel  # noqa: E402, F401
from whitted.gui.document import CAMERA  # noqa: E402


@pytest.fixture
def window(make_window):  # noqa: F811 - the fixture of gui_input
    return make_window(preview=False, warm_up=False)


def test_tree_panel_and_edit_target_are_one_selection(window, qtbot):
    window.object_actions["sphere"].trigger()  # "sphere 1", selected, its panel shown
    sphere_key = window.doc.selection
    sphere_before = window.doc.scene.material_of(sphere_key[1])
    # a click on "ball" in the tree: the panel shows the ball...
    click_tree(qtbot, window.tree, ("objects", 1))
    assert window.doc.selection == ("objects", 1)
    assert "ball" in window.properties.title.text()
    # ...and a colour typed in the panel turns the ball green, not the sphere
    type_into(qtbot, window.properties.row("material", "color").editor.line, "#00ff00")
    assert window.doc.scene.material_of(1).color == (0.0, 1.0, 0.0)
    assert window.doc.scene.material_of(sphere_key[1]) == sphere_before
    # the arrow keys move the one selection too
    window.tree.setFocus()
    qtbot.keyClick(window.tree, Qt.Key.Key_Up)
    assert window.doc.selection == ("objects", 0)
    assert "floor" in window.properties.title.text()
    # selecting the camera shows the camera's panel, and edits go to the camera
    click_tree(qtbot, window.tree, CAMERA)
    assert window.properties.title.text() == "Camera"
    assert ("material", "color") not in window.properties.rows
    type_into(qtbot, window.properties.row("fov").editor.line, "35")
    assert window.doc.scene.camera.fov == 35.0
    # undo goes back to the item the edit was made to, and the panel follows
    window.act_undo.trigger()
    assert window.doc.scene.camera.fov == 40.0
    window.act_undo.trigger()
    assert window.doc.selection == ("objects", 1)
    assert "ball" in window.properties.title.text()
    assert window.tree.currentItem() is window.tree.item_for(("objects", 1))


def test_the_wheel_scrolls_the_panel_and_changes_only_a_focused_field(window, qtbot):
    window.object_actions["sphere"].trigger()
    key = window.doc.selection
    panel = window.properties
    asked = []
    panel.choose_file = lambda title, filters: asked.append(title)
    before = window.doc.scene
    bar = panel.scroll.verticalScrollBar()
    assert bar.maximum() > 0  # the sphere's panel is taller than the window
    texture = panel.row("material", "texture", "type").editor.combo
    slider = panel.row("material", "kd").editor.slider
    for widget in (texture, slider, panel.material_combo):
        for notches in (-1, 1, -1):  # down, up, down: scrolling past it
            start = bar.value()
            wheel(widget, notches)
            if notches < 0 and start < bar.maximum():
                assert bar.value() > start  # the panel scrolled instead
    assert window.doc.scene == before and not asked
    assert texture.currentText() == "none"
    assert panel.material_combo.currentData() == "preset:plastic"
    # a field with the focus does take the wheel
    slider.setFocus()
    qtbot.waitUntil(slider.hasFocus)
    wheel(slider, 1)
    assert window.doc.scene.material_of(key[1]).kd != before.material_of(key[1]).kd
