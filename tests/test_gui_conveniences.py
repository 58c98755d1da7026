"""The editor's small things, with real keys and mouse: Save As where the file cannot be
written says so in one line; long names never widen the panels and the panels come back
after the window was at its smallest; Ctrl+R from the user's own view dims the camera's
picture; Shift+D / Ctrl+D duplicate as "X.001" and grab; A selects all, Shift+A opens the Add
menu; R turns several objects about their median point; the Properties header counts the
selection; the kernels' loading says when it waits on another process."""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPointF, Qt  # noqa: E402
from PySide6.QtWidgets import QApplication, QMenu  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, SHIFT, click_tree, drag, make_window, mouse, small_scene  # noqa: E402, F401
from whitted import scene as S  # noqa: E402

SLOW = 120_000


def test_save_as_where_the_file_cannot_be_written_says_so_in_one_line(make_window):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    for path, reason in (("/sys/t.toml", "permission denied"),
                         ("/nonexistent-folder/t.toml", "no such file or directory")):
        window.errors.clear()
        assert not window.files.save_as(__import__("pathlib").Path(path))
        assert window.errors == [("Cannot save the scene", f"cannot write {path}: {reason}")]
    # the API says the same (an OutputError, exit 2 from the CLI)
    with pytest.raises(whitted.WhittedError, match=r"^cannot write /sys/t.toml: permission"):
        whitted.save_scene(window.doc.scene, "/sys/t.toml")


def test_long_names_are_cut_and_the_panels_come_back(make_window, qtbot):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    tree_dock, props_dock = (d for d, _ in window._dock_widths)
    qtbot.waitUntil(lambda: tree_dock.width() > 0)
    widths = (tree_dock.width(), props_dock.width())
    click_tree(qtbot, window.tree, ("objects", 1))
    long = "ball" + " copy" * 40
    window.doc.rename(("objects", 1), long)
    QApplication.processEvents()
    assert (tree_dock.width(), props_dock.width()) == widths
    title = window.properties.title
    assert title.full_text.endswith(f"{long} (sphere)") and "…" in title.shown_text()
    assert window.tree.item_for(("objects", 1)).text(0).startswith(long)
    # the window at its smallest, then back: the panels get their widths again
    size = window.size()
    window.resize(window.minimumSizeHint())
    qtbot.waitUntil(lambda: tree_dock.width() < widths[0])
    window.resize(size)
    qtbot.waitUntil(lambda: abs(tree_dock.width() - widths[0]) <= 4
                    and abs(props_dock.width() - widths[1]) <= 4, timeout=5000)


def test_shift_d_duplicates_as_x_001_and_grabs(make_window, qtbot):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    ball = ("objects", 1)
    click_tree(qtbot, window.tree, ball)
    vp = window.viewport
    mouse(vp, "move", vp.picture_rect().center(), Qt.MouseButton.NoButton)
    count = len(window.doc.scene.objects)
    qtbot.keyClick(window.tree, Qt.Key.Key_D, SHIFT)
    assert vp.tool is not None  # grabbed: the copy follows the mouse
    copy_key = window.doc.selection
    assert window.doc.item(copy_key).name == "ball.001"
    assert len(window.doc.scene.objects) == count + 1
    qtbot.keyClicks(vp, "x")
    qtbot.keyClicks(vp, "1")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert vp.tool is None
    assert window.doc.item(copy_key).center == pytest.approx((1.0, 0.8, 0.0))
    assert window.doc.item(ball).center == (0.0, 0.8, 0.0)  # the original stays
    # Ctrl+D does the same; Esc leaves the copy on the original; the next name is .002
    qtbot.keyClick(window.tree, Qt.Key.Key_D, CTRL)
    assert vp.tool is not None
    qtbot.keyClick(vp, Qt.Key.Key_Escape)
    assert vp.tool is None
    assert window.doc.item(window.doc.selection).name == "ball.002"
    assert window.doc.item(window.doc.selection).center == pytest.approx((1.0, 0.8, 0.0))


def test_a_selects_all_and_the_header_counts_them(make_window, qtbot):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    click_tree(qtbot, window.tree, ("objects", 1))
    qtbot.keyClick(window.tree, Qt.Key.Key_A)
    scene = window.doc.scene
    assert set(window.doc.selected_keys()) == {
        *(("lights", i) for i in range(len(scene.lights))),
        *(("objects", i) for i in range(len(scene.objects)))}
    assert window.doc.selection == ("objects", 1)  # the active one stays
    panel = window.properties
    assert panel.title.full_text == "Object: ball (sphere)"  # what the panel edits
    assert panel.selection_note.isVisible()
    assert panel.selection_note.full_text == \
        "2 objects and 2 lights selected (this panel edits the one above)"
    window.select([("objects", 0), ("objects", 1)])
    assert panel.selection_note.full_text.startswith("2 objects selected")
    click_tree(qtbot, window.tree, ("objects", 0))
    assert not panel.selection_note.isVisible()


def test_shift_a_opens_the_add_menu_at_the_pointer(make_window, qtbot):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    vp = window.viewport
    mouse(vp, "move", vp.picture_rect().center(), Qt.MouseButton.NoButton)
    vp.setFocus()
    count = len(window.doc.scene.objects)
    qtbot.keyClick(vp, Qt.Key.Key_A, SHIFT)
    menu = window.add_menu
    qtbot.waitUntil(menu.isVisible)
    assert [a.text() for a in menu.actions()][:2] == ["&Object", "&Light"]
    # the keyboard picks from it: Object, then its first entry
    qtbot.keyClick(menu, Qt.Key.Key_Down)
    qtbot.keyClick(menu, Qt.Key.Key_Right)
    sub = window.add_object_menu
    qtbot.waitUntil(sub.isVisible)
    qtbot.keyClick(sub, Qt.Key.Key_Return)
    qtbot.waitUntil(lambda: len(window.doc.scene.objects) == count + 1)
    assert window.doc.item().type == "sphere"
    assert not any(isinstance(w, QMenu) and w.isVisible() for w in QApplication.topLevelWidgets())


def test_r_turns_several_objects_about_their_median_point(make_window, qtbot):  # noqa: F811
    from whitted.gui.transform_tool import object_centre

    scene = small_scene().model_copy(update={"objects": [
        S.Plane(name="floor"), S.Sphere(name="left", center=(-1.0, 0.5, 0.0), radius=0.4),
        S.Sphere(name="right", center=(2.0, 0.5, 0.0), radius=0.4)]})
    window = make_window(scene, preview=False, warm_up=False)
    click_tree(qtbot, window.tree, ("objects", 1))
    qtbot.mouseClick(window.tree.viewport(), Qt.MouseButton.LeftButton, SHIFT,
                     window.tree.visualItemRect(window.tree.item_for(("objects", 2))).center())
    assert set(window.doc.selected_keys()) == {("objects", 1), ("objects", 2)}
    qtbot.keyClick(window.tree, Qt.Key.Key_R)
    qtbot.keyClicks(window.viewport, "180")
    qtbot.keyClick(window.viewport, Qt.Key.Key_Return)
    new = window.doc.scene
    # about x = 0.5 (the median of -1 and 2): the two swap places
    assert object_centre(new, 1) == pytest.approx((2.0, 0.5, 0.0), abs=1e-6)
    assert object_centre(new, 2) == pytest.approx((-1.0, 0.5, 0.0), abs=1e-6)
    assert window.doc.undo_stack.count() == 1


def test_render_from_the_users_view_dims_the_cameras_picture(make_window, qtbot):  # noqa: F811
    from whitted.gui.render_controller import BACKDROP_DIM
    from whitted.output.colour import encode_ldr

    window = make_window(small_scene(64, 48), warm_up=False)
    controller, vp = window.controller, window.viewport

    def settled():
        return controller.preview is None and controller._pending is None and \
            controller.last_preview is not None

    qtbot.waitUntil(settled, timeout=SLOW)
    camera_picture = controller.last_preview.pixels.copy()
    c = vp.picture_rect().center()
    drag(vp, c, [c + QPointF(25 * i, 6 * i) for i in range(1, 6)])  # orbit: the user's view
    assert window.navigation.label() == "User Perspective"
    qtbot.waitUntil(lambda: settled() and controller._shown.scene.camera !=
                    window.doc.scene.camera, timeout=SLOW)
    user_picture = controller.last_preview.pixels.copy()
    qtbot.keyClick(vp, Qt.Key.Key_R, CTRL)
    backdrop = controller.full.backdrop
    assert backdrop is not None

    def dimmed(pixels):
        s = window.doc.scene.render
        small = encode_ldr(pixels, transfer=s.transfer, tonemap=s.tonemap)
        ys = np.arange(s.height) * small.shape[0] // s.height
        xs = np.arange(s.width) * small.shape[1] // s.width
        return (small[ys][:, xs] * BACKDROP_DIM).astype(np.float64)

    to_camera = np.abs(backdrop - dimmed(camera_picture)).mean()
    to_user = np.abs(backdrop - dimmed(user_picture)).mean()
    assert to_camera < 0.5 * to_user, (to_camera, to_user)
    qtbot.waitUntil(lambda: not controller.rendering, timeout=SLOW)


def test_the_kernels_wait_says_another_process_compiles_them(make_window, tmp_path):  # noqa: F811
    from whitted.jit.cache import KernelCache

    folder = tmp_path / "kernels"
    folder.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys; from whitted.jit.cache import KernelCache; "
         f"c = KernelCache({str(folder)!r}, True, False); c.compiling(); print('held', "
         "flush=True); sys.stdin.read()"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        window = make_window(preview=False, warm_up=False)
        controller = window.controller
        controller._warm_started = time.perf_counter() - 3.0
        controller._kernel_cache = KernelCache(str(folder), True, False)
        text = controller.warm_up_text()
        assert text.startswith("Waiting for another whitted process, which is compiling "
                               "the render kernels (3 s)")
        # the picture shows it while the kernels are not loaded, and drops it once they are
        window.render_control.show_warm_up()
        assert window.viewport.caption.startswith("Waiting for another whitted process")
    finally:
        holder.stdin.close()
        holder.wait(30)
    assert controller.warm_up_text().startswith("Loading the render kernels")
    window.render_control._kernels_ready(0.0)
    assert window.viewport.caption == ""
