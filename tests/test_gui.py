"""The scene editor (``whitted gui``) through its UI actions, offscreen: adding every kind of
object and light, editing properties (and refusing invalid values at the field), undo/redo,
files (round trip, recent, autosave recovery, the close prompt), the camera controls, the
preview after an edit, render/stop keeping the partial picture, and the editor's render equal
to ``whitted render``'s."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image as PILImage  # noqa: E402

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPointF, QSettings, Qt  # noqa: E402
from PySide6.QtGui import QMouseEvent  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

import whitted  # noqa: E402
from whitted.gui import camera_ops  # noqa: E402
from whitted.gui.autosave import autosave_path  # noqa: E402
from whitted.gui.catalog import HAS_MESH, LIGHT_KINDS, OBJECT_KINDS  # noqa: E402
from whitted.gui.document import CAMERA, RENDER  # noqa: E402
from whitted.gui.main_window import WINDOW_SIZE, MainWindow, starter_scene  # noqa: E402
from whitted.program import app as cli_app  # noqa: E402

SLOW = 120_000  # ms: the first render in a fresh process compiles or loads the kernels


def small_scene(width: int = 64, height: int = 48) -> whitted.Scene:
    return starter_scene().with_settings(width=width, height=height)


@pytest.fixture
def make_window(qtbot, tmp_path):
    """A factory of editor windows with their own settings file and autosave folder; the
    close prompt answers "discard" unless a test says otherwise."""

    def make(scene=None, path=None, **options) -> MainWindow:
        settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
        options.setdefault("autosave_folder", tmp_path / "autosave")
        window = MainWindow(scene if scene is not None or path is not None else small_scene(),
                            path, settings=settings, **options)
        window.ask_unsaved = lambda: "discard"
        window.properties.ask_keep_colour = lambda preset: "replace"
        window.show_error = lambda title, message: errors.append((title, message))
        window.errors = errors = []
        qtbot.addWidget(window)
        window.show()
        return window

    return make


@pytest.fixture
def window(make_window) -> MainWindow:
    return make_window()


def set_text(window: MainWindow, path: tuple, text: str) -> str:
    """Type ``text`` into the field of ``path`` (the first box of a vector) and finish it;
    returns the field's error message ('' when accepted)."""
    row = window.properties.row(*path)
    editor = row.editor
    line = getattr(editor, "line", None) or editor.lines[0]
    line.setText(text)
    line.editingFinished.emit()
    return row.error


def wait_preview(qtbot, window: MainWindow, after: int) -> None:
    qtbot.waitUntil(lambda: window.controller.previews_done > after, timeout=SLOW)


def test_window_fits_a_small_screen_and_keeps_the_aspect_ratio(window):
    assert WINDOW_SIZE[0] <= 1366 and WINDOW_SIZE[1] <= 768 - 60
    assert window.width() <= 1366 and window.height() <= 768
    rect = window.viewport.picture_rect()
    assert rect.width() / rect.height() == pytest.approx(64 / 48, rel=1e-6)
    assert window.doc.selection == CAMERA  # the camera is selected first
    assert ("position",) in window.properties.rows


def test_add_every_kind_of_object_and_light(window, tmp_path):
    before = len(window.doc.scene.objects)
    for kind, action in window.object_actions.items():
        action.trigger()
        assert window.doc.selection == ("objects", len(window.doc.scene.objects) - 1)
        assert window.doc.item().type == kind
        assert kind in window.properties.title.text()
    assert [o.type for o in window.doc.scene.objects[before:]] == list(OBJECT_KINDS)
    lights = len(window.doc.scene.lights)
    for kind, action in window.light_actions.items():
        action.trigger()
        assert window.doc.item().type == kind
    assert [li.type for li in window.doc.scene.lights[lights:]] == list(LIGHT_KINDS)
    # every new item is in the tree, selected
    assert window.tree.currentItem().data(0, Qt.ItemDataRole.UserRole) == window.doc.selection


@pytest.mark.skipif(not HAS_MESH, reason="no mesh shape in the scene model")
def test_add_a_model_from_a_file(window, tmp_path):
    obj = tmp_path / "tetra.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    key = window.add_model(obj)
    assert key is not None and window.doc.item(key).type == "mesh"
    assert window.doc.scene.resolve_path(window.doc.item(key).file).resolve() == obj.resolve()
    # saved elsewhere, the scene still finds its model
    (tmp_path / "elsewhere").mkdir()
    assert window.save_as(tmp_path / "elsewhere" / "with_model.toml")
    loaded = whitted.load_scene(tmp_path / "elsewhere" / "with_model.toml")
    assert loaded.resolve_path(loaded.objects[key[1]].file).resolve() == obj.resolve()
    bad = tmp_path / "broken.obj"
    bad.write_text("this is not a model\n")
    n = len(window.doc.scene.objects)
    assert window.add_model(bad) is None
    assert len(window.doc.scene.objects) == n and window.errors


def test_edit_properties_with_every_kind_of_field(window):
    window.object_actions["sphere"].trigger()
    key = window.doc.selection
    assert set_text(window, ("radius",), "0.75") == ""
    assert window.doc.item(key).radius == 0.75
    row = window.properties.row("center")
    for line, text in zip(row.editor.lines, ("1", "2", "-3"), strict=True):
        line.setText(text)
    row.editor.lines[2].editingFinished.emit()
    assert window.doc.item(key).center == (1.0, 2.0, -3.0)
    # colour (what the picker gives), a coefficient slider, a preset, a check box
    window.properties.row("material", "color").editor.choose("#ff0000")
    assert window.doc.scene.material_of(key[1]).color == (1.0, 0.0, 0.0)
    window.properties.row("material", "kr").editor.slider.setValue(500)
    assert window.doc.scene.material_of(key[1]).kr == pytest.approx(0.5)
    assert set_text(window, ("material", "ior"), "1.33") == ""
    assert window.doc.scene.material_of(key[1]).ior == 1.33
    window.properties.choose_material("preset:glass")
    assert window.doc.scene.material_of(key[1]) == whitted.Material(preset="glass")
    window.properties.row("material", "fresnel").editor.committed.emit(False, False)
    assert window.doc.scene.material_of(key[1]).fresnel is False
    # rotation in degrees, uniform scale
    assert set_text(window, ("transform", "rotate"), "30") == ""
    assert window.doc.item(key).transform.rotate == (30.0, 0.0, 0.0)
    # a light: choice field, intensity
    window.light_actions["point"].trigger()
    window.properties.row("falloff").editor.committed.emit("linear", False)
    assert window.doc.item().falloff == "linear"
    assert set_text(window, ("intensity",), "1.5") == ""
    assert window.doc.item().intensity == 1.5
    # render settings and camera
    window.select(RENDER)
    for path, value in ((("width",), 80), (("max_depth",), 3), (("samples",), 2),
                        (("shadow_samples",), 8), (("threads",), 1)):
        assert set_text(window, path, str(value)) == ""
        assert getattr(window.doc.scene.render, path[0]) == value
    window.select(CAMERA)
    assert set_text(window, ("fov",), "50") == ""
    assert window.doc.scene.camera.fov == 50.0


def test_textures_from_the_drop_down_and_the_file_chooser(window, tmp_path):
    if "texture" not in whitted.Material.model_fields:
        pytest.skip("no textures in the scene model")
    window.object_actions["sphere"].trigger()
    index = window.doc.selection[1]
    window.properties.row("material", "texture", "type").editor.committed.emit("checker", False)
    assert window.doc.scene.material_of(index).texture.type == "checker"
    assert set_text(window, ("material", "texture", "checks"), "4") == ""
    assert window.doc.scene.material_of(index).texture.checks == 4.0
    picture = tmp_path / "wood.png"
    PILImage.new("RGB", (4, 4), (200, 120, 40)).save(picture)
    window.properties.choose_file = lambda title, filters: None  # the dialog is cancelled
    window.properties.row("material", "texture", "type").editor.committed.emit("image", False)
    assert window.doc.scene.material_of(index).texture.type == "checker"
    assert "choose an image" in window.properties.row("material", "texture", "type").error
    window.properties.choose_file = lambda title, filters: str(picture)
    window.properties.row("material", "texture", "type").editor.committed.emit("image", False)
    texture = window.doc.scene.material_of(index).texture
    assert texture.type == "image"
    assert window.doc.scene.resolve_path(texture.file).resolve() == picture.resolve()
    window.properties.row("material", "texture", "type").editor.committed.emit("none", False)
    assert window.doc.scene.material_of(index).texture is None


def test_invalid_values_are_refused_at_the_field(window):
    window.object_actions["sphere"].trigger()
    before = window.doc.scene
    cases = [
        (("radius",), "-1", "greater than 0"),
        (("radius",), "abc", "not a number"),
        (("material", "kr"), "1.5", "at most 1"),
        (("material", "color"), "#zz0000", "not a colour"),
        (("center",), "x", "not a number"),
    ]
    for path, text, message in cases:
        error = set_text(window, path, text)
        assert message in error, (path, error)
        row = window.properties.row(*path)
        assert not row.message.isHidden()
        assert window.doc.scene == before  # nothing invalid reached the scene
    window.select(RENDER)
    assert "width must be at least 1" in set_text(window, ("width",), "0")
    window.select(CAMERA)
    assert "field of view must be less than 180" in set_text(window, ("fov",), "200")
    assert window.doc.scene == before
    # a valid value afterwards clears the message
    assert set_text(window, ("fov",), "60") == ""
    assert window.properties.row("fov").message.isHidden()


def test_undo_and_redo_every_edit(window):
    s0 = window.doc.scene
    window.object_actions["box"].trigger()
    s1 = window.doc.scene
    set_text(window, ("name",), "crate")
    s2 = window.doc.scene
    window.duplicate_selected()
    s3 = window.doc.scene
    window.delete_selected()
    s4 = window.doc.scene
    assert [o.name for o in s3.objects[-2:]] == ["crate", "crate.001"]
    assert len(s4.objects) == len(s2.objects)
    assert window.act_undo.shortcut().toString() == "Ctrl+Z"
    assert window.act_redo.shortcut().toString() == "Ctrl+Shift+Z"
    for expected in (s3, s2, s1, s0):
        window.act_undo.trigger()
        assert window.doc.scene == expected
    assert not window.doc.dirty
    for expected in (s1, s2, s3, s4):
        window.act_redo.trigger()
        assert window.doc.scene == expected
    assert window.doc.dirty


def test_undo_with_the_keyboard_and_delete_key(window, qtbot):
    window.object_actions["cone"].trigger()
    n = len(window.doc.scene.objects)
    window.activateWindow()
    window.tree.setFocus()
    qtbot.keyClick(window.tree, Qt.Key.Key_Delete)
    assert len(window.doc.scene.objects) == n - 1
    qtbot.keyClick(window.tree, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert len(window.doc.scene.objects) == n
    qtbot.keyClick(window.tree, Qt.Key.Key_Z,
                   Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert len(window.doc.scene.objects) == n - 1


def test_a_slider_drag_is_one_undo_step(window):
    window.object_actions["sphere"].trigger()
    key = window.doc.selection
    steps = window.doc.undo_stack.count()
    slider = window.properties.row("material", "kd").editor.slider
    slider.setSliderDown(True)
    window.properties.row("material", "kd").editor._new_session()
    for v in (100, 200, 300, 400):
        slider.setValue(v)
    slider.setSliderDown(False)
    assert window.doc.scene.material_of(key[1]).kd == pytest.approx(0.4)
    assert window.doc.undo_stack.count() == steps + 1
    window.act_undo.trigger()
    assert window.doc.scene.objects[key[1]].material == "plastic"


def test_rename_in_the_tree(window, qtbot):
    window.light_actions["ambient"].trigger()
    key = window.doc.selection
    window.tree.currentItem().setText(0, "sky glow")
    qtbot.waitUntil(lambda: window.doc.item(key).name == "sky glow")
    assert window.tree.currentItem().text(0).startswith("sky glow")


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_save_and_reload_round_trip(make_window, tmp_path, suffix):
    window = make_window()
    window.object_actions["cylinder"].trigger()
    set_text(window, ("radius",), "0.3")
    window.properties.choose_material("preset:mirror")
    window.light_actions["disk"].trigger()
    path = tmp_path / f"scene{suffix}"
    assert window.save_as(path)
    assert not window.doc.dirty and window.windowTitle().startswith(path.name)
    loaded = whitted.load_scene(path)
    assert loaded == window.doc.scene
    assert window.recent.paths()[0] == path.resolve()
    other = make_window(path=path, scene=loaded)
    assert other.doc.scene == loaded
    assert other.open_path(path) and other.doc.scene == loaded


def test_open_refuses_a_broken_file_with_a_message(window, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[[objects]]\ntype = 'sphere'\nradius = -1\n")
    before = window.doc.scene
    assert not window.open_path(bad)
    assert window.errors and "radius" in window.errors[0][1]
    assert window.doc.scene == before


def test_new_scene_asks_about_unsaved_changes(window):
    window.object_actions["sphere"].trigger()
    window.ask_unsaved = lambda: "cancel"
    assert not window.new_scene()
    window.ask_unsaved = lambda: "discard"
    assert window.new_scene()
    assert window.doc.scene == starter_scene() and not window.doc.dirty


def test_close_prompt(window, tmp_path):
    window.object_actions["sphere"].trigger()
    window.ask_unsaved = lambda: "cancel"
    assert not window.close()
    assert window.isVisible()
    saved = tmp_path / "closing.toml"
    window.ask_unsaved = lambda: "save"
    window.ask_save_path = lambda: saved
    assert window.close()
    assert whitted.load_scene(saved) == window.doc.scene


def test_autosave_beside_the_scene_is_offered_after_a_crash(make_window, tmp_path):
    path = tmp_path / "work.toml"
    small_scene().save(path)
    window = make_window(scene=whitted.load_scene(path), path=path)
    assert window.autosave.save_now() is None  # nothing unsaved: nothing written
    window.object_actions["disk"].trigger()
    edited = window.doc.scene
    auto = window.autosave.save_now()
    assert auto == autosave_path(path, window.autosave.folder) and auto.parent == tmp_path
    # the editor "crashes": a new one opens the scene and is offered the autosave
    window.doc.undo_stack.setClean()  # (so that closing this one keeps the autosave)
    again = make_window(scene=whitted.load_scene(path), path=path)
    offered = []
    again.ask_recover = lambda p: offered.append(p) or True
    assert again.offer_recovery()
    assert offered == [auto]
    assert again.doc.scene == edited and again.doc.dirty
    assert again.save()
    assert not auto.exists()
    assert whitted.load_scene(path) == edited


def test_declined_recovery_removes_the_autosave(make_window, tmp_path):
    window = make_window()
    window.object_actions["box"].trigger()
    auto = window.autosave.save_now()
    assert auto is not None and auto.exists()
    window.ask_recover = lambda p: False
    assert not window.offer_recovery()
    assert not auto.exists()


def test_a_file_of_someone_else_s_at_the_autosave_name_is_kept(make_window, tmp_path):
    """The autosave's name is whitted's choice: a file there that whitted did not write is
    neither written over nor removed, and the status bar says so."""
    path = tmp_path / "work.toml"
    small_scene().save(path)
    theirs = autosave_path(path, tmp_path)
    theirs.write_text("my own notes\n")
    window = make_window(scene=whitted.load_scene(path), path=path)
    said = []
    window.autosave.saved.connect(said.append)
    window.object_actions["disk"].trigger()
    assert window.autosave.save_now() is None
    assert theirs.read_text() == "my own notes\n"
    assert said == [f"Autosave off: {theirs.name} is there and whitted did not write it "
                    "(it is kept)"]
    window.autosave.discard()
    assert theirs.read_text() == "my own notes\n"
    theirs.unlink()
    assert window.autosave.save_now() == theirs  # whitted's own from now on: replaced
    window.object_actions["box"].trigger()
    assert window.autosave.save_now() == theirs
    window.autosave.discard()
    assert not theirs.exists()


def test_the_autosave_is_whitted_s_by_its_first_line(make_window, tmp_path, monkeypatch):
    """An autosave carries its proof in its first line: with nowhere to record what whitted
    wrote (a cleared or read-only cache), every later autosave still replaces it and a
    discard still removes it."""
    from whitted.gui.autosave import AUTOSAVE_MARK
    from whitted.output import ownership

    (tmp_path / "a-file").write_text("")  # records "under" a file: none can be kept
    monkeypatch.setattr(ownership, "_records", lambda: tmp_path / "a-file" / "written")
    path = tmp_path / "work.json"  # a JSON scene's autosave is TOML too
    small_scene().save(path)
    window = make_window(scene=whitted.load_scene(path), path=path)
    window.object_actions["disk"].trigger()
    auto = window.autosave.save_now()
    assert auto == tmp_path / ".work.autosave.toml"
    assert auto.read_text().startswith(AUTOSAVE_MARK)
    assert len(whitted.load_scene(auto).objects) == len(window.doc.scene.objects)
    window.object_actions["box"].trigger()
    assert window.autosave.save_now() == auto  # replaced, not "Autosave off"
    window.autosave.discard()
    assert not auto.exists()


def test_camera_position_rotation_and_mouse(window, qtbot):
    window.select(CAMERA)
    assert set_text(window, ("position",), "1") == ""
    cam = window.doc.scene.camera
    assert cam.position[0] == 1.0
    # rotate 90 degrees about Y through the camera: it turns its head
    panel = window.properties
    panel.rotate_axis.setCurrentText("Y")
    panel.rotate_angle.line.setText("90")
    _, _, f0 = cam.basis()
    assert panel.rotate_camera()
    _, _, f1 = window.doc.scene.camera.basis()
    assert np.allclose(f1, (f0[2], f0[1], -f0[0]), atol=1e-5)  # f0 turned 90° about +y
    assert window.doc.scene.camera.position == cam.position
    steps = window.doc.undo_stack.count()
    # a mouse drag orbits (one undo step), the wheel zooms
    vp = window.viewport
    c = vp.rect().center()
    start = QPointF(c.x(), c.y())

    def send(kind, pos, buttons):
        event = QMouseEvent(kind, pos, vp.mapToGlobal(pos), Qt.MouseButton.LeftButton, buttons,
                            Qt.KeyboardModifier.NoModifier)
        if kind == QMouseEvent.Type.MouseButtonPress:
            vp.mousePressEvent(event)
        elif kind == QMouseEvent.Type.MouseMove:
            vp.mouseMoveEvent(event)
        else:
            vp.mouseReleaseEvent(event)

    # View > Lock camera to view: in camera view, the mouse moves the scene's camera
    window.acts["lock_camera"].trigger()
    assert window.navigation.camera_view and window.navigation.locked
    before = window.doc.scene.camera
    send(QMouseEvent.Type.MouseButtonPress, start, Qt.MouseButton.LeftButton)
    for dx in (10, 20, 30):
        send(QMouseEvent.Type.MouseMove, start + QPointF(dx, 5), Qt.MouseButton.LeftButton)
    send(QMouseEvent.Type.MouseButtonRelease, start + QPointF(30, 5), Qt.MouseButton.NoButton)
    after = window.doc.scene.camera
    target = camera_ops.target_of(before)
    assert after.position != before.position
    assert np.linalg.norm(np.subtract(after.position, target)) == pytest.approx(
        np.linalg.norm(np.subtract(before.position, target)), rel=1e-5)
    assert window.doc.undo_stack.count() == steps + 1
    vp.zoom.emit(0.5, -1.0, -1.0)
    zoomed = window.doc.scene.camera
    assert np.linalg.norm(np.subtract(zoomed.position, target)) == pytest.approx(
        0.5 * np.linalg.norm(np.subtract(after.position, target)), rel=1e-4)
    vp.pan.emit(0.1, 0.0, 99)
    assert window.doc.scene.camera.look_at != zoomed.look_at


def test_camera_ops():
    cam = whitted.Camera(position=(0, 0, 5), look_at=(0, 0, 0))
    turned = camera_ops.rotate_about_axis(cam, "Y", 90)
    assert np.allclose(turned.basis()[2], (-1, 0, 0), atol=1e-6)
    circled = camera_ops.rotate_about_axis(cam, "Y", 90, pivot="target")
    assert np.allclose(circled.position, (5, 0, 0), atol=1e-5)
    up = camera_ops.orbit(cam, 0, -89)  # never over the pole
    assert np.linalg.norm(up.position) == pytest.approx(5)
    assert abs(up.position[1]) < 5
    assert camera_ops.zoom(cam, 0.5).position == (0.0, 0.0, 2.5)
    moved = camera_ops.pan(cam, 0.5, 0)
    assert moved.position[0] < 0 and moved.look_at[0] == moved.position[0]
    # the rotate form is turned into look_at with the same view
    rot = whitted.Camera(position=(1, 2, 3), rotate=(10, 20, 0))
    same = camera_ops.zoom(rot, 1.0)
    assert np.allclose(np.array(same.basis()), np.array(rot.basis()), atol=1e-6)


def test_preview_follows_an_edit(window, qtbot):
    wait_preview(qtbot, window, 0)
    first = window.controller.last_preview.pixels.copy()
    shown = window.viewport.image
    done = window.controller.previews_done
    window.select(("objects", 1))
    window.properties.row("material", "color").editor.choose("#00ff00")
    wait_preview(qtbot, window, done)
    second = window.controller.last_preview.pixels
    assert second.shape == first.shape
    assert not np.array_equal(first, second)
    assert window.viewport.image is not shown and window.viewport.kind == "preview"


def test_render_then_stop_keeps_the_partial_picture(make_window, qtbot):
    scene = whitted.default_scene().with_settings(width=320, height=320, samples=16)
    window = make_window(scene=scene, preview=False)
    window.act_render.trigger()
    assert window.controller.rendering and window.act_stop.isEnabled()
    qtbot.waitUntil(lambda: window.controller.full is None
                    or window.controller.full.latest is not None, timeout=SLOW)
    window.act_stop.trigger()
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    image = window.controller.last_image
    stats = image.meta["stats"]
    assert stats.cancelled and 0 < stats.tiles_done < stats.tiles_total
    assert image.pixels.max() > 0
    assert window.viewport.image is not None and window.viewport.kind == "render"
    shown = window.viewport.image
    assert shown.width() == 320 and not shown.isNull()
    # said once, in the status bar (not again beside the hidden progress bar)
    assert "Stopped" in window.statusBar().currentMessage() and window.eta.text() == ""
    assert window.act_render.isEnabled() and not window.act_stop.isEnabled()
    # the kept picture can be saved
    out = Path(window.settings.fileName()).parent / "partial.png"
    assert window.save_image(out) and out.exists()


def test_a_render_starts_over_the_dimmed_preview(make_window, qtbot):
    scene = whitted.default_scene().with_settings(width=320, height=320, samples=16)
    window = make_window(scene=scene)
    wait_preview(qtbot, window, 0)
    window.act_render.trigger()
    active = window.controller.full
    assert active.backdrop is not None and active.backdrop.shape == (320, 320, 3)
    assert active.backdrop.max() > 0
    qtbot.waitUntil(lambda: active.display is not None, timeout=SLOW)
    window.act_stop.trigger()
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    stats = window.controller.last_image.meta["stats"]
    assert 0 < stats.tiles_done < stats.tiles_total
    # where no tile arrived the picture shows the preview, elsewhere the render
    missing = window.controller.last_image.pixels.max(axis=2) == 0
    assert missing.any() and (~missing).any()
    assert (active.display[missing] == active.backdrop[missing]).all()
    assert not (active.display[~missing] == active.backdrop[~missing]).all()


def test_the_editor_renders_what_whitted_render_renders(make_window, qtbot, tmp_path):
    window = make_window(preview=False)
    window.object_actions["box"].trigger()
    window.properties.choose_material("preset:glass")
    window.light_actions["disk"].trigger()
    path = tmp_path / "same.toml"
    assert window.save_as(path)
    window.act_render.trigger()
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    editor_pixels = window.controller.last_image.pixels
    assert not window.controller.last_image.meta["stats"].cancelled
    out = tmp_path / "cli.npy"
    result = CliRunner().invoke(cli_app, ["render", str(path), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    cli_pixels = np.load(out)
    assert cli_pixels.shape == editor_pixels.shape == (48, 64, 3)
    assert np.array_equal(cli_pixels, editor_pixels)
    exr = tmp_path / "editor.exr"
    assert window.save_image(exr)
    assert np.array_equal(whitted.Image.load(exr).pixels, editor_pixels)


def test_the_cli_starts_without_qt():
    code = ("import sys, whitted.cli.main; "
            "sys.exit(any(m.startswith('PySide6') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], timeout=120).returncode == 0
    result = CliRunner().invoke(cli_app, ["gui", "--help"])
    assert result.exit_code == 0 and "editor" in result.output


def test_an_edit_during_a_render_stops_it_and_previews(make_window, qtbot):
    scene = whitted.default_scene().with_settings(width=320, height=320, samples=16)
    window = make_window(scene=scene)
    wait_preview(qtbot, window, 0)
    done = window.controller.previews_done
    window.act_render.trigger()
    qtbot.waitUntil(lambda: window.controller.full is None
                    or window.controller.full.latest is not None, timeout=SLOW)
    window.select(("objects", 1))
    window.properties.row("material", "color").editor.choose("#0000ff")
    qtbot.waitUntil(lambda: not window.controller.rendering, timeout=SLOW)
    wait_preview(qtbot, window, done)
    assert window.viewport.kind == "preview"
    # the recent-files menu lists what was opened
    window._fill_recent()
    assert [a.text() for a in window.recent_menu.actions()] == ["(none)"]
