"""The editor driven as a person drives it: real clicks, key presses and
wheel turns on the real widgets, offscreen. Each test failed on the editor before its fix."""

from __future__ import annotations

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QColor  # noqa: E402

import whitted  # noqa: E402
import whitted.gui.widgets  # noqa: E402
from gui_input import (  # noqa: E402, F401
    CTRL,
    SHIFT,
    SLOW,
    click_tree,
    drag,
    make_window,
    type_into,
    wheel,
)
from whitted.gui.document import CAMERA  # noqa: E402


@pytest.fixture
def new_window(make_window):  # noqa: F811 - the fixture of gui_input
    return make_window


@pytest.fixture
def window(new_window):
    return new_window(preview=False, warm_up=False)


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


def test_shortcuts_work_after_typing_in_a_field(window, qtbot, tmp_path):
    window.object_actions["sphere"].trigger()
    key = window.doc.selection
    line = window.properties.row("radius").editor.line
    type_into(qtbot, line, "0.9")
    assert window.doc.item(key).radius == 0.9 and line.hasFocus()
    # Ctrl+Z in the field, the edit committed: the scene's undo, not the field's
    qtbot.keyClick(line, Qt.Key.Key_Z, CTRL)
    assert window.doc.item(key).radius == 0.5
    qtbot.keyClick(window.properties.row("radius").editor.line, Qt.Key.Key_Z, CTRL | SHIFT)
    assert window.doc.item(key).radius == 0.9
    # while a value is being typed, Ctrl+Z is the field's own undo (the scene keeps 0.9)
    line = window.properties.row("radius").editor.line
    type_into(qtbot, line, "0.3", finish=False)
    qtbot.keyClick(line, Qt.Key.Key_Z, CTRL)
    assert window.doc.item(key).radius == 0.9 and line.text() != "0.3"
    # Ctrl+S while typing saves what is typed (the field's value is committed first)
    path = tmp_path / "typed.toml"
    window.ask_save_path = lambda: path
    type_into(qtbot, line, "0.7", finish=False)
    qtbot.keyClick(line, Qt.Key.Key_S, CTRL)
    assert path.exists() and whitted.load_scene(path).objects[key[1]].radius == 0.7
    # a render from the keyboard with the focus in a field
    qtbot.keyClick(window.properties.row("radius").editor.line, Qt.Key.Key_R, CTRL)
    assert window.controller.rendering
    window.controller.shutdown()
    # Delete with the focus on the picture deletes the selected object
    n = len(window.doc.scene.objects)
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton, CTRL,
                     window.viewport.rect().topLeft() + QPoint(2, 2))
    window.select(key)
    qtbot.keyClick(window.viewport, Qt.Key.Key_Delete)
    assert len(window.doc.scene.objects) == n - 1


def test_a_shaky_click_does_not_stop_a_render_and_the_render_shows_at_1_to_1(new_window, qtbot):
    scene = whitted.default_scene().with_settings(width=320, height=240, samples=64)
    window = new_window(scene=scene, preview=False)
    vp = window.viewport
    window.act_render.trigger()
    qtbot.waitUntil(lambda: window.controller.full is None
                    or window.controller.full.latest is not None, timeout=SLOW)
    camera = window.doc.scene.camera
    c = QPointF(vp.rect().center())
    drag(vp, c, [c + QPointF(1, 1), c + QPointF(2, 1)])  # a two-pixel slip of the hand
    assert window.doc.scene.camera == camera
    assert window.controller.rendering
    # Esc stops it, and says so at once
    qtbot.keyClick(vp, Qt.Key.Key_Escape)
    assert window.statusBar().currentMessage() == "Stopping…"
    assert vp.caption == "Stopping…"
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    assert vp.caption != "Stopping…"
    # the picture at 1:1, zoomed in about the pointer, and fitted again
    qtbot.keyClick(vp, Qt.Key.Key_1, CTRL)
    assert vp.picture_rect().width() == pytest.approx(320)
    assert vp.picture_rect().height() == pytest.approx(240)
    wheel(vp, 2, modifiers=CTRL)
    assert vp.picture_rect().width() == pytest.approx(320 * 1.25 ** 2)
    assert window.doc.scene.camera == camera  # the picture zoomed, not the camera
    qtbot.keyClick(vp, Qt.Key.Key_0, CTRL)
    assert vp.picture_scale is None


def test_a_refused_value_does_not_move_the_form_and_speaks_plainly(window, qtbot):
    window.object_actions["sphere"].trigger()
    key = window.doc.selection
    panel = window.properties

    def layout():
        return {path: row.mapTo(panel.form, QPoint(0, 0)) for path, row in panel.rows.items()}

    before = layout()
    line = panel.row("radius").editor.line
    type_into(qtbot, line, "-1")
    row = panel.row("radius")
    assert row.error == "radius must be greater than 0"
    assert not row.message.isHidden()
    assert layout() == before  # nothing moved: the next click lands where it was aimed
    # the message floats just under the field
    assert row.message.mapTo(panel.form, QPoint(0, 0)).y() == row.mapTo(
        panel.form, QPoint(0, row.height())).y()
    # typing the scene's value back clears it, as does a new valid value
    type_into(qtbot, line, "0.5")
    assert row.message.isHidden() and row.error == ""
    type_into(qtbot, line, "0")
    assert row.error == "radius must be greater than 0"
    type_into(qtbot, line, "0.25")
    assert row.message.isHidden() and window.doc.item(key).radius == 0.25
    # other fields name themselves the way their labels do
    type_into(qtbot, panel.row("material", "kr").editor.line, "1.5")
    assert panel.row("material", "kr").error == "reflection kr must be at most 1"


def test_a_model_shows_the_material_of_its_file_and_can_override_it(window, qtbot, tmp_path):
    (tmp_path / "red.mtl").write_text("newmtl red\nKd 1 0 0\nKa 0 0 0\n")
    obj = tmp_path / "tetra.obj"
    obj.write_text("mtllib red.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl red\n"
                   "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    key = window.add_model(obj)
    click_tree(qtbot, window.tree, ("objects", 0))
    click_tree(qtbot, window.tree, key)
    panel = window.properties
    assert panel.material_combo.currentText() == "From the model file (tetra.obj)"
    assert panel.row("material", "color").editor.line.text() == "#ff0000"
    assert window.doc.item(key).material is None
    # an edit overrides the file's material with this one, starting from what it showed
    type_into(qtbot, panel.row("material", "kr").editor.line, "0.5")
    material = window.doc.scene.material_of(key[1])
    assert material.kr == 0.5 and material.color == (1.0, 0.0, 0.0)
    assert panel.material_combo.currentText() == "Custom"
    # back to the file's materials from the drop-down, with the keyboard
    combo = panel.material_combo
    panel.ask_keep_colour = lambda preset: "replace"  # (passing the presets on the way)
    combo.setFocus()
    for _ in range(combo.count()):
        qtbot.keyClick(combo, Qt.Key.Key_Up)
    qtbot.waitUntil(lambda: window.doc.item(key).material is None)
    assert panel.material_combo.currentText() == "From the model file (tetra.obj)"


def test_small_things_icons_swatches_live_colour_and_the_idle_progress_bar(window, qtbot):
    # icons in the tree and the Add menus
    item = window.tree.item_for(("objects", 1))
    assert not item.icon(0).isNull()
    assert not window.tree.item_for(("lights", 1)).icon(0).isNull()
    assert not window.object_actions["cone"].icon().isNull()
    assert window.progress.isHidden()  # no render: no progress bar
    # the preset list has swatches; a preset over a custom colour asks first
    click_tree(qtbot, window.tree, ("objects", 1))
    panel = window.properties
    combo = panel.material_combo
    glass = combo.findData("preset:glass")
    assert not combo.itemIcon(glass).isNull()
    type_into(qtbot, panel.row("material", "color").editor.line, "#ff8800")
    asked = []
    panel.ask_keep_colour = lambda preset: asked.append(preset) or "keep"
    combo.showPopup()  # open the list and click "glass"
    view = combo.view()
    qtbot.waitUntil(view.isVisible)
    rect = view.visualRect(view.model().index(glass, 0))
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    qtbot.waitUntil(lambda: bool(asked))
    assert asked == ["glass"]
    material = window.doc.scene.material_of(1)
    assert material.preset == "glass" and material.kt == whitted.Material(preset="glass").kt
    assert whitted.gui.widgets.hex_of(material.color) == "#ff8800"  # the colour was kept
    # the colour picker changes the picture while it is open; Cancel leaves no trace
    steps = window.doc.undo_stack.count()
    before = window.doc.scene
    editor = panel.row("material", "color").editor
    qtbot.mouseClick(editor.button, Qt.MouseButton.LeftButton)
    dialog = editor.dialog
    assert dialog is not None and dialog.isVisible()
    dialog.setCurrentColor(QColor("#00ff00"))
    assert window.doc.scene.material_of(1).color == (0.0, 1.0, 0.0)  # live
    dialog.setCurrentColor(QColor("#0000ff"))
    assert window.doc.scene.material_of(1).color == (0.0, 0.0, 1.0)
    dialog.reject()
    assert window.doc.scene == before and window.doc.undo_stack.count() == steps
    # a render shows the bar; when it ends the bar goes away
    window.act_render.trigger()
    assert not window.progress.isHidden()
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    assert window.progress.isHidden()
