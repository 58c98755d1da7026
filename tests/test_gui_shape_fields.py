"""The Shape section edits every parameter of a shape: a triangle's texture coordinates and a
solid mesh's outside medium, typed into their fields, undone and saved."""

from __future__ import annotations

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, click_tree, make_window, small_scene, type_into  # noqa: E402, F401
from whitted import scene as S  # noqa: E402
from whitted.gui.properties import INLINE  # noqa: E402


def test_a_triangles_uvs_are_typed_refused_undone_and_saved(make_window, qtbot, tmp_path):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    window.object_actions["triangle"].trigger()
    key = window.doc.selection
    panel = window.properties
    lines = panel.row("uvs", 1).editor.lines
    assert [line.text() for line in lines] == ["1", "0"]
    type_into(qtbot, lines[1], "0.25")
    assert window.doc.item(key).uvs == ((0.0, 0.0), (1.0, 0.25), (0.0, 1.0))
    type_into(qtbot, lines[0], "nan")
    assert window.doc.item(key).uvs[1] == (1.0, 0.25)  # refused: the scene keeps its value
    assert panel.row("uvs", 1).message.text()
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    assert window.doc.item(key).uvs[1] == (1.0, 0.0)
    type_into(qtbot, panel.row("uvs", 2).editor.lines[0], "0.5")
    window.files.save_as(tmp_path / "tri.toml")
    assert whitted.load_scene(tmp_path / "tri.toml").objects[-1].uvs[2] == (0.5, 1.0)


def _with_mesh(outside):
    tetra = S.Mesh(vertices=[(-0.5, 0, -0.5), (0.5, 0, -0.5), (0, 0, 0.5), (0, 0.8, 0)],
                   faces=[(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)], material="glass",
                   outside=outside, name="cavity")
    scene = small_scene()
    return scene.model_copy(update={"objects": [*scene.objects, tetra]})


def test_a_meshs_outside_medium_is_named_cleared_and_saved(make_window, qtbot, tmp_path):  # noqa: F811
    scene = _with_mesh(None)
    window = make_window(scene, preview=False, warm_up=False)
    key = ("objects", len(scene.objects) - 1)
    click_tree(qtbot, window.tree, key)
    line = window.properties.row("outside").editor.line
    assert line.text() == ""
    type_into(qtbot, line, "ice")
    assert window.doc.item(key).outside == "ice"
    window.files.save_as(tmp_path / "m.toml")
    assert not window.errors, window.errors
    assert whitted.load_scene(tmp_path / "m.toml").objects[-1].outside == "ice"
    type_into(qtbot, line, "", finish=False)  # emptied: the medium the ray arrives through
    qtbot.keyClick(line, Qt.Key.Key_Backspace)
    qtbot.keyClick(line, Qt.Key.Key_Return)
    assert window.doc.item(key).outside is None


def test_an_inline_outside_medium_is_shown_and_kept(make_window, qtbot):  # noqa: F811
    scene = _with_mesh(S.Material(ior=1.31, kt=0.9))
    window = make_window(scene, preview=False, warm_up=False)
    key = ("objects", len(scene.objects) - 1)
    click_tree(qtbot, window.tree, key)
    assert window.properties.row("outside").editor.line.text() == INLINE
    type_into(qtbot, window.properties.row("outside").editor.line, INLINE)  # left as shown
    type_into(qtbot, window.properties.row("crease_angle").editor.line, "30")
    assert window.doc.item(key).crease_angle == 30
    assert window.doc.item(key).outside == S.Material(ior=1.31, kt=0.9)
