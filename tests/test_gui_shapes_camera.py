"""Every kind of object the scene format accepts is in Add > Object and has a Shape section
(the torus's radii edited by typing); the camera's focal blur is set in its panel (aperture,
focus on a distance or a point; each an undo step, saved); a CSG child is outlined itself
and its material panel says which material it inherits."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, click_tree, make_window, small_scene, type_into  # noqa: E402, F401
from whitted import scene as S  # noqa: E402
from whitted.gui import catalog  # noqa: E402
from whitted.gui import fields as F  # noqa: E402
from whitted.gui.document import CAMERA  # noqa: E402

SLOW = 120_000


def test_every_shape_of_the_scene_format_is_added_and_has_a_shape_section(make_window):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    kinds = catalog.shape_kinds()
    assert "torus" in kinds and "csg" in kinds
    for kind in kinds:
        if kind in catalog.ADDED_OTHERWISE:  # a model: Add > Object > Model from file
            continue
        action = window.object_actions[kind]
        assert action in window.add_object_menu.actions()
        action.trigger()
        obj = window.doc.item()
        assert obj.type == kind and not window.errors
        shape = [s for s in window.properties.specs.values() if s.group == F.GEOMETRY]
        own = set(type(obj).model_fields) - set(F.NOT_SHAPE_FIELDS)
        assert shape and {s.path[0] for s in shape} <= own, kind
        # the new object is in the view, resting on the floor (y = 0) or above it
        from whitted.gui.transform_tool import item_bounds

        lo, _hi = item_bounds(obj, window.doc.scene) if kind != "plane" else (np.zeros(3), 0)
        assert lo[1] >= -1e-6, kind


def test_the_torus_radii_are_typed_undone_and_saved(make_window, qtbot, tmp_path):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    window.object_actions["torus"].trigger()
    key = window.doc.selection
    panel = window.properties
    assert panel.title.text().endswith("(torus)")
    assert panel.row("major_radius").editor.line.text() == "0.5"
    type_into(qtbot, panel.row("major_radius").editor.line, "0.8")
    type_into(qtbot, panel.row("minor_radius").editor.line, "0.25")
    torus = window.doc.item(key)
    assert (torus.major_radius, torus.minor_radius) == (0.8, 0.25)
    # a tube wider than zero only: refused at the field, the scene keeps its value
    type_into(qtbot, panel.row("minor_radius").editor.line, "-1")
    assert "greater than 0" in panel.row("minor_radius").message.text()
    assert window.doc.item(key).minor_radius == 0.25
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    assert window.doc.item(key).minor_radius == 0.15
    window.files.save_as(tmp_path / "ring.toml")
    saved = whitted.load_scene(tmp_path / "ring.toml")
    assert saved.objects[-1].type == "torus" and saved.objects[-1].major_radius == 0.8


def test_focal_blur_is_set_in_the_camera_panel(make_window, qtbot, tmp_path):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    click_tree(qtbot, window.tree, CAMERA)
    panel = window.properties
    camera = window.doc.scene.camera
    assert camera.aperture == 0.0 and panel.row("focus_mode").editor.combo.currentText() == \
        "look-at point"
    type_into(qtbot, panel.row("aperture").editor.line, "0.2")
    assert window.doc.scene.camera.aperture == 0.2
    # focus on a distance: the field appears with the distance it focuses at now
    combo = panel.row("focus_mode").editor.combo
    qtbot.mouseClick(combo, Qt.MouseButton.LeftButton)
    qtbot.keyClick(combo, Qt.Key.Key_Escape)  # (the popup closed, the focus stays)
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    cam = window.doc.scene.camera
    assert cam.focal_distance == pytest.approx(camera.focus(), abs=1e-4)
    type_into(qtbot, panel.row("focal_distance").editor.line, "3")
    assert window.doc.scene.camera.focal_distance == 3.0
    # a point: on the view's axis, 3 units ahead
    combo = panel.row("focus_mode").editor.combo
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    cam = window.doc.scene.camera
    assert cam.focal_distance is None and cam.focus() == pytest.approx(3.0, abs=1e-3)
    type_into(qtbot, panel.row("focal_point").editor.lines[1], "0.5")
    assert window.doc.scene.camera.focal_point[1] == 0.5
    # refused: a point behind the camera
    type_into(qtbot, panel.row("focal_point").editor.lines[2], "50")
    assert "front of the camera" in panel.row("focal_point").message.text()
    # every change an undo step
    for _ in range(3):
        qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    cam = window.doc.scene.camera
    assert cam.focal_distance == pytest.approx(camera.focus(), abs=1e-4) and cam.aperture == 0.2
    qtbot.keyClick(window.viewport, Qt.Key.Key_Y, CTRL)
    window.files.save_as(tmp_path / "blur.toml")
    text = (tmp_path / "blur.toml").read_text()
    assert "aperture = 0.2" in text and "focal_distance = 3" in text


def _die_scene():
    scene = small_scene(160, 120)
    die = S.CSG(name="die", operation="difference", material="glass",
                transform=S.Transform(translate=(0.0, 0.8, 0.0)), objects=[
                    S.Box(name="body", min=(-0.6, -0.6, -0.6), max=(0.6, 0.6, 0.6)),
                    S.Sphere(name="pip", center=(0.35, 0.35, 0.6), radius=0.3)])
    return scene.model_copy(update={"objects": [scene.objects[0], die]})


def test_a_csg_child_is_outlined_itself_and_says_what_it_inherits(make_window, qtbot):  # noqa: F811
    window = make_window(_die_scene(), preview=False, warm_up=False)
    vp = window.viewport

    def outline_pixels():
        image = vp.outline
        if image is None:
            return None
        h, w = image.height(), image.width()
        rows = np.frombuffer(image.constBits(), np.uint8).reshape(h, image.bytesPerLine())
        return np.argwhere(rows[:, : 4 * w].reshape(h, w, 4)[..., 3] > 0)

    # the pip, before any edit: an outline of its own
    click_tree(qtbot, window.tree, ("objects", 1, 1))
    qtbot.waitUntil(lambda: outline_pixels() is not None, timeout=SLOW)
    pip = outline_pixels()
    click_tree(qtbot, window.tree, ("objects", 1))
    qtbot.waitUntil(lambda: outline_pixels() is not None and len(outline_pixels()) != len(pip),
                    timeout=SLOW)
    whole = outline_pixels()
    click_tree(qtbot, window.tree, ("objects", 1, 1))
    qtbot.waitUntil(lambda: outline_pixels() is not None and len(outline_pixels()) == len(pip),
                    timeout=SLOW)
    # the pip's outline lies within the die's box on screen, and is smaller than it
    (y0, x0), (y1, x1) = whole.min(axis=0), whole.max(axis=0)
    assert np.all((pip[:, 0] >= y0 - 2) & (pip[:, 0] <= y1 + 2) & (pip[:, 1] >= x0 - 2)
                  & (pip[:, 1] <= x1 + 2))
    assert np.ptp(pip[:, 1]) < 0.8 * np.ptp(whole[:, 1])
    # its material: the die's glass, said so
    panel = window.properties
    assert panel.material_combo.currentText() == "Inherited from die (glass)"
    glass = whitted.Material(preset="glass")
    shown = panel.row("material", "kt").editor.line.text()
    assert float(shown) == pytest.approx(glass.kt)
    # choosing the default makes it grey of its own; "inherited" gives it back
    combo = panel.material_combo
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    qtbot.waitUntil(lambda: window.doc.item(("objects", 1, 1)).material is not None)
    assert window.doc.item(("objects", 1, 1)).material == whitted.Material()
    assert panel.material_combo.currentText() == "Default (grey)"
    combo = panel.material_combo
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Up)
    qtbot.waitUntil(lambda: window.doc.item(("objects", 1, 1)).material is None)
