"""The viewport as a 3-D view, driven by real clicks and keys: picking
through the object-id image, the outline, Esc, moving with G, turntable orbit, framing and
the numpad views."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, QPointF, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import SLOW, drag, make_window, mouse  # noqa: E402, F401
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


def test_g_moves_the_selection_on_the_ground_and_typed_values_along_an_axis(window, qtbot):
    vp = window.viewport
    start = pixel_of(window, 1)
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=start)
    assert window.doc.selection == ("objects", 1)
    steps = window.doc.undo_stack.count()
    mouse(vp, "move", QPointF(start), Qt.MouseButton.NoButton)
    qtbot.keyClick(vp, Qt.Key.Key_G)
    assert vp.tool is not None and "Move on the ground" in window.statusBar().currentMessage()
    for dx in (10, 20, 30):  # the pointer moves right: the ball follows on the ground
        mouse(vp, "move", QPointF(start) + QPointF(dx, 0), Qt.MouseButton.NoButton)
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(30, 0))
    assert vp.tool is None
    c = window.doc.item(("objects", 1)).center  # a sphere: G moves its centre
    assert c[0] > 0.05 and c[1] == 0.8  # right, and not off the ground
    assert window.doc.item(("objects", 1)).transform is None
    assert window.doc.undo_stack.count() == steps + 1  # the whole move is one step
    # G, Z, a typed value, Enter: exactly that far along z
    before = c
    qtbot.keyClick(vp, Qt.Key.Key_G)
    qtbot.keyClick(vp, Qt.Key.Key_Z)
    qtbot.keyClicks(vp, "-1.5")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    after = window.doc.item(("objects", 1)).center
    assert after == pytest.approx((before[0], before[1], before[2] - 1.5))
    # R with a typed angle turns it about y; Esc during S cancels, leaving nothing to redo
    qtbot.keyClicks(vp, "r90")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert window.doc.item(("objects", 1)).transform.rotate == pytest.approx((0, 90, 0))
    scene = window.doc.scene
    qtbot.keyClicks(vp, "s3")
    assert window.doc.scene != scene
    qtbot.keyClick(vp, Qt.Key.Key_Escape)
    assert window.doc.scene == scene and not window.doc.undo_stack.canRedo()
    assert window.doc.selection == ("objects", 1)  # Esc cancelled the move, not deselected


def test_turntable_orbit_keeps_the_horizon_level(window, qtbot):
    vp = window.viewport
    c = QPointF(vp.rect().center())
    camera = window.doc.scene.camera
    up = window.navigation.camera().up
    drag(vp, c, [c + QPointF(20 * i, 7 * i) for i in range(1, 8)])
    cam = window.navigation.camera()
    assert cam.up == up
    right, _, forward = cam.basis()
    assert abs(float(np.dot(right, up))) < 1e-9  # no roll: the horizon stays level
    assert forward[1] != 0
    # the view moved, not the scene's camera: nothing to save, nothing to undo
    assert window.doc.scene.camera == camera and not window.doc.dirty
    assert not window.navigation.camera_view


def test_frame_selection_home_and_the_numpad_views(window, qtbot):
    vp = window.viewport
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=pixel_of(window, 1))
    qtbot.keyClick(vp, Qt.Key.Key_F)
    cam = window.navigation.camera()
    assert cam.look_at == pytest.approx((0.0, 0.8, 0.0))  # the ball's centre
    qtbot.keyClick(vp, Qt.Key.Key_7, Qt.KeyboardModifier.KeypadModifier)  # top
    cam = window.navigation.camera()
    assert cam.position[0] == pytest.approx(cam.look_at[0])
    assert cam.position[2] == pytest.approx(cam.look_at[2], abs=0.01)  # a hair to the front
    assert cam.position[1] > cam.look_at[1] and cam.up == (0.0, 1.0, 0.0)
    qtbot.keyClick(vp, Qt.Key.Key_3, Qt.KeyboardModifier.KeypadModifier)  # right side
    cam = window.navigation.camera()
    assert cam.position[0] > cam.look_at[0] and cam.position[1] == pytest.approx(cam.look_at[1])
    qtbot.keyClick(vp, Qt.Key.Key_1, Qt.KeyboardModifier.KeypadModifier)  # front
    cam = window.navigation.camera()
    assert cam.position[2] > cam.look_at[2] and cam.position[0] == pytest.approx(cam.look_at[0])
    qtbot.keyClick(vp, Qt.Key.Key_Home)  # everything bounded (the ball; the floor is endless)
    assert window.navigation.camera().look_at == pytest.approx((0.0, 0.8, 0.0))
    assert window.doc.selection == ("objects", 1)  # moving the view keeps the selection
    assert not window.doc.dirty  # and the scene's camera stays where it is


def test_a_light_is_drawn_picked_and_moved_with_g(make_window, qtbot):  # noqa: F811
    scene = whitted.gui.main_window.starter_scene().with_settings(width=160, height=120)
    lights = [*scene.lights, whitted.PointLight(name="bulb", position=(1.0, 2.0, 0.0))]
    scene = scene.model_copy(update={"lights": lights})
    window = make_window(scene, preview=False, warm_up=False)
    vp = window.viewport
    marks = dict(window._light_marks())
    uv = marks[("lights", 2)]
    at = vp.to_widget(*uv)
    picture = vp.grab().toImage()
    colour = picture.pixelColor(round(at.x()), round(at.y()))
    assert colour.red() > 200 and colour.green() > 180 and colour.blue() < 150  # the mark
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=QPoint(round(at.x()) + 3,
                                                                round(at.y()) + 2))
    assert window.doc.selection == ("lights", 2)
    assert "bulb" in window.properties.title.text()
    qtbot.keyClicks(vp, "gy1")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert window.doc.item(("lights", 2)).position == pytest.approx((1.0, 3.0, 0.0))


def test_new_objects_rest_on_the_floor_clear_of_the_others(window, tmp_path):
    from whitted.gui.transform_tool import object_bounds

    for kind in ("sphere", "box", "cylinder", "cone", "sphere"):
        window.object_actions[kind].trigger()
    scene = window.doc.scene
    boxes = [object_bounds(scene, i) for i in range(1, len(scene.objects))]
    for i, (lo, hi) in enumerate(boxes):
        if i > 0:  # the new ones (the ball is the first)
            assert lo[1] == pytest.approx(0.0, abs=1e-6)  # on the floor
        for j, (lo2, hi2) in enumerate(boxes[:i]):
            assert not (np.all(lo < hi2 - 1e-6) and np.all(lo2 < hi - 1e-6)), (i, j)
    # a huge model is scaled to a sensible size, and says so
    obj = tmp_path / "huge.obj"
    obj.write_text("v 0 0 0\nv 900 0 0\nv 0 900 0\nv 0 0 900\nf 1 3 2\nf 1 2 4\nf 1 4 3\n"
                   "f 2 3 4\n")
    key = window.add_model(obj)
    lo, hi = object_bounds(window.doc.scene, key[1])
    assert np.max(hi - lo) == pytest.approx(1.5, rel=1e-2) and lo[1] == pytest.approx(0.0)
    assert "scaled by" in window.statusBar().currentMessage()
    # lights are named by type and number
    window.light_actions["point"].trigger()
    assert window.doc.item().name == "point 2"  # the starter scene's lamp is the first
    window.light_actions["disk"].trigger()
    assert window.doc.item().name == "disk 1"
