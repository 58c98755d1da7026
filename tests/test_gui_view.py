"""The viewport has its own view. Looking around never
changes the scene's camera; numpad 0 looks through the camera; Ctrl+Alt+numpad 0 moves the
camera to the view as one undoable edit. The preview's size follows the picture's size on
screen once the window is laid out and whenever it is resized."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPointF, Qt  # noqa: E402

from gui_input import SLOW, drag, make_window, small_scene, wheel  # noqa: E402, F401
from whitted.gui.main_window import starter_scene  # noqa: E402

KEYPAD = Qt.KeyboardModifier.KeypadModifier
CTRL_ALT_KEYPAD = (Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier
                   | KEYPAD)


@pytest.fixture
def window(make_window):  # noqa: F811 - the fixture of gui_input
    return make_window(starter_scene().with_settings(width=160, height=120), preview=False,
                       warm_up=False)


def test_looking_around_moves_the_view_not_the_camera(window, qtbot):
    vp, nav = window.viewport, window.navigation
    camera = window.doc.scene.camera
    assert nav.camera_view and nav.label() == "Camera Perspective"
    c = QPointF(vp.picture_rect().center())
    drag(vp, c, [c + QPointF(15 * i, 4 * i) for i in range(1, 6)])  # orbit
    wheel(vp, -2)  # zoom
    drag(vp, c, [c + QPointF(0, 6 * i) for i in range(1, 4)], Qt.MouseButton.RightButton)
    assert window.doc.scene.camera == camera
    assert not window.doc.dirty and window.doc.undo_stack.count() == 0
    assert not nav.camera_view and nav.label() == "User Perspective"
    view = nav.view
    assert view.position != camera.position
    # the picture is seen through the view: previews and picking use it
    assert window.shown_scene().camera == view
    assert window.shown_scene() is window.shown_scene()  # (matched by identity)
    # numpad 0: through the scene's camera; again: back to the view
    qtbot.keyClick(vp, Qt.Key.Key_0, KEYPAD)
    assert nav.camera_view and window.shown_scene().camera == camera
    assert window.acts["camera_view"].isChecked()
    qtbot.keyClick(vp, Qt.Key.Key_0, KEYPAD)
    assert not nav.camera_view and nav.view == view
    # Ctrl+Alt+numpad 0: the camera moves to the view, one undo step; its lens stays
    qtbot.keyClick(vp, Qt.Key.Key_0, CTRL_ALT_KEYPAD)
    moved = window.doc.scene.camera
    assert moved.position == view.position and moved.look_at == view.look_at
    assert moved.fov == camera.fov
    assert nav.camera_view and window.doc.dirty and window.doc.undo_stack.count() == 1
    assert window.doc.undo_stack.undoText() == "Set camera to view"
    qtbot.keyClick(vp, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.doc.scene.camera == camera and not window.doc.dirty


def test_the_numpad_views_and_frame_look_around_from_any_focus(window, qtbot):
    nav, tree = window.navigation, window.tree
    tree.setFocus()
    qtbot.keyClick(tree, Qt.Key.Key_7, KEYPAD)  # the top view, with the focus in the tree
    view = nav.camera()
    assert view.position[1] > view.look_at[1]
    assert np.hypot(view.position[0] - view.look_at[0],
                    view.position[2] - view.look_at[2]) < 0.01
    assert window.doc.undo_stack.count() == 0 and not window.doc.dirty


def test_a_render_looks_through_the_scene_camera(window, qtbot):
    vp, nav = window.viewport, window.navigation
    c = QPointF(vp.picture_rect().center())
    drag(vp, c, [c + QPointF(20 * i, 0) for i in range(1, 4)])
    assert not nav.camera_view
    window.controller.preview_enabled = True
    qtbot.keyClick(vp, Qt.Key.Key_R, Qt.KeyboardModifier.ControlModifier)
    assert nav.camera_view  # the render is the camera's picture: camera view
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    assert window.controller.last_image is not None
    assert "Rendered" in window.statusBar().currentMessage()
    # File > New: nothing said about the last scene's render stays
    qtbot.keyClick(vp, Qt.Key.Key_N, Qt.KeyboardModifier.ControlModifier)
    assert window.statusBar().currentMessage() == "" and window.eta.text() == ""
    assert window.navigation.camera_view


def test_the_preview_size_follows_the_picture_on_screen(make_window, qtbot):  # noqa: F811
    window = make_window(small_scene(), preview=False, warm_up=False)
    vp = window.viewport

    def expected():
        r = vp.fit_rect()
        ratio = vp.devicePixelRatioF()
        return max(1, int(r.width() * r.height() * ratio * ratio))

    assert window.controller.target_pixels == expected()  # once laid out, not before
    size = window.size()
    window.resize(size.width() + 200, size.height() + 100)
    qtbot.waitUntil(lambda: window.controller.target_pixels == expected(), timeout=5000)
    assert window.controller.target_pixels > 0
    window.resize(size)
    qtbot.waitUntil(lambda: window.controller.target_pixels == expected(), timeout=5000)


def test_new_objects_land_in_view_on_the_floor_and_are_seen(window, qtbot):
    from pathlib import Path

    from whitted.gui import camera_ops
    from whitted.gui.transform_tool import item_bounds

    def seen_whole(key) -> bool:
        scene = window.doc.scene
        lo, hi = item_bounds(scene.objects[key[1]], scene)
        s = scene.render
        for corner in ((x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                       for z in (lo[2], hi[2])):
            uv = camera_ops.project(window.navigation.camera(), s.width, s.height, corner)
            if uv is None or not all(0.0 <= c <= 1.0 for c in uv):
                return False
        return True

    # a plane with a floor there already: a wall behind the scene, facing the view, seen
    window.object_actions["plane"].trigger()
    plane = window.doc.selection
    ids = window.ids.ids_for(window.shown_scene())
    assert (ids == plane[1]).mean() > 0.05
    assert window.doc.scene.objects[plane[1]].normal != (0.0, 1.0, 0.0)
    # after looking around, new things land where the view looks, whole in the picture
    vp = window.viewport
    c = QPointF(vp.picture_rect().center())
    drag(vp, c, [c + QPointF(-25 * i, 0) for i in range(1, 5)])
    assert not window.navigation.camera_view
    for kind in ("sphere", "box", "cone"):
        window.object_actions[kind].trigger()
        key = window.doc.selection
        assert seen_whole(key), kind
        lo, _ = item_bounds(window.doc.item(key), window.doc.scene)
        assert lo[1] == pytest.approx(0.0, abs=1e-6), kind  # resting on the floor
    model = Path(__file__).parents[1] / "examples" / "models" / "teapot.obj"
    key = window.add_model(model)
    assert key is not None and seen_whole(key)
