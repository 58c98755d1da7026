"""The editor's timeline, driven as a person drives it: clicks on the frame
slider and the Play button, the I key wherever the focus is, Ctrl+Z, Ctrl+S; offscreen."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, SHIFT, SLOW, click_tree, make_window, type_into  # noqa: E402, F401
from whitted.gui.document import CAMERA  # noqa: E402
from whitted.gui.render_controller import preview_scene  # noqa: E402

LEFT = Qt.MouseButton.LeftButton
NO_MOD = Qt.KeyboardModifier.NoModifier
BALL = ("objects", 1)

ROLLING_BALL = """\
# A small animated scene: the ball rolls to the right over eight frames.

[render]
width = 64
height = 48
max_depth = 2

[camera]
position = [0, 1.5, 6]
look_at = [0, 0.6, 0]
fov = 40

[[lights]]
type = "ambient"
intensity = 0.2

[[lights]]
type = "point"
name = "lamp"
position = [-4, 6, 5]
intensity = 0.9

[[objects]]
type = "plane"
name = "floor"
material = "matte"

[[objects]]
type = "sphere"
name = "ball"
center = [-1, 0.8, 0]
radius = 0.8
material = "plastic"

[animation]
frames = 8
fps = 24

[[animation.tracks]]
path = "objects[ball].center"   # left to right
keys = [
  [0, [-1, 0.8, 0]],
  [7, [1.5, 0.8, 0]],
]
"""


def ball_x(frame: float) -> float:
    return -1 + 2.5 * frame / 7


@pytest.fixture
def rolling(tmp_path):
    path = tmp_path / "rolling.toml"
    path.write_text(ROLLING_BALL, encoding="utf-8")
    return path


@pytest.fixture
def open_rolling(make_window, rolling):  # noqa: F811 - the fixture of gui_input
    def make(**options):
        return make_window(whitted.load_scene(rolling), rolling, **options)

    return make


def click_frame(qtbot, timeline, frame: int) -> None:
    slider = timeline.slider
    qtbot.mouseClick(slider, LEFT, NO_MOD, QPoint(slider.x_of(frame), slider.height() // 2))


def center_shown(window) -> tuple[float, ...]:
    return tuple(float(line.text()) for line in window.properties.row("center").editor.lines)


def test_a_click_on_the_slider_previews_that_frame(open_rolling, rolling, qtbot):
    window = open_rolling()
    timeline, controller = window.timeline, window.controller
    assert timeline.isVisible() and timeline.slider.maximum() == 7
    qtbot.waitUntil(lambda: controller.previews_done >= 1, timeout=SLOW)

    click_frame(qtbot, timeline, 5)
    assert timeline.frame == 5 and timeline.frame_box.value() == 5
    expected = whitted.load_scene(rolling).at_frame(5)
    assert expected.objects[1].center == pytest.approx((ball_x(5), 0.8, 0.0))
    assert timeline.still(window.doc.scene) == expected
    click_tree(qtbot, window.tree, BALL)  # the panel shows frame 5's values
    assert center_shown(window) == pytest.approx((ball_x(5), 0.8, 0.0), abs=1e-3)

    done = controller.previews_done
    qtbot.waitUntil(lambda: controller.previews_done > done and controller.preview is None
                    and controller._pending is None, timeout=SLOW)
    shown = controller.last_preview.pixels
    assert shown.shape[:2] == (48, 64)  # the preview of a 64x48 scene is full size
    truth = whitted.render(preview_scene(expected, 64 * 48)).pixels
    assert np.array_equal(shown, truth)
    frame0 = whitted.render(preview_scene(whitted.load_scene(rolling).at_frame(0), 64 * 48))
    assert not np.array_equal(shown, frame0.pixels)  # the ball moved

    # keys move the slider too: Home goes to frame 0, Right steps one frame
    qtbot.keyClick(timeline.slider, Qt.Key.Key_Home)
    qtbot.keyClick(timeline.slider, Qt.Key.Key_Right)
    assert timeline.frame == 1
    assert window.doc.scene.objects[1].center == pytest.approx((ball_x(1), 0.8, 0.0))


def test_i_keys_the_selection_at_the_frame_and_undo_removes_the_key(open_rolling, qtbot):
    window = open_rolling(preview=False, warm_up=False)
    timeline = window.timeline
    click_frame(qtbot, timeline, 3)
    click_tree(qtbot, window.tree, BALL)
    assert window.tree.hasFocus()
    qtbot.keyClick(window.tree, Qt.Key.Key_I)

    tracks = window.doc.scene.animation.tracks
    assert [t.path for t in tracks] == ["objects[ball].center", "objects[ball].transform"]
    assert [k[0] for k in tracks[0].keys] == [0, 3, 7]
    assert tracks[0].keys[1][1] == pytest.approx([ball_x(3), 0.8, 0.0])
    assert tracks[1].keys == [(3, {"scale": 1.0, "rotate": [0.0, 0.0, 0.0],
                                   "translate": [0.0, 0.0, 0.0]})]
    assert timeline.slider.keys == [0.0, 3.0, 7.0]

    # the camera, with the focus on the picture
    window.select(CAMERA)
    click_frame(qtbot, timeline, 6)
    window.viewport.setFocus()
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)
    paths = [t.path for t in window.doc.scene.animation.tracks]
    assert paths[2:] == ["camera.position", "camera.look_at"]
    assert window.doc.scene.animation.tracks[2].keys == [(6, [0.0, 1.5, 6.0])]

    # Ctrl+Z takes the keys back, one key press at a time; the frame stays
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    assert len(window.doc.scene.animation.tracks) == 2
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    tracks = window.doc.scene.animation.tracks
    assert len(tracks) == 1 and [k[0] for k in tracks[0].keys] == [0, 7]
    assert timeline.frame == 6 and timeline.slider.keys == [0.0, 7.0]
    # the scene is shown posed at frame 6 by the original track
    assert window.doc.scene.objects[1].center == pytest.approx((ball_x(6), 0.8, 0.0))
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL | SHIFT)
    assert [k[0] for k in window.doc.scene.animation.tracks[0].keys] == [0, 3, 7]

    # Alt+I deletes the ball's keys at frame 3 (its transform track, left empty, goes)
    click_frame(qtbot, timeline, 3)
    click_tree(qtbot, window.tree, BALL)
    qtbot.keyClick(window.tree, Qt.Key.Key_I, Qt.KeyboardModifier.AltModifier)
    tracks = window.doc.scene.animation.tracks
    assert [t.path for t in tracks] == ["objects[ball].center"]
    assert [k[0] for k in tracks[0].keys] == [0, 7]
    qtbot.keyClick(window.tree, Qt.Key.Key_Z, CTRL)
    assert [k[0] for k in window.doc.scene.animation.tracks[0].keys] == [0, 3, 7]
    click_frame(qtbot, timeline, 6)

    # an edit not keyed gives way to the track when the frame changes, and says so
    click_tree(qtbot, window.tree, BALL)
    type_into(qtbot, window.properties.row("center").editor.lines[2], "-1")
    # (the panel shows 6 digits and commits x as shown)
    assert window.doc.scene.objects[1].center == pytest.approx((ball_x(6), 0.8, -1.0), abs=1e-5)
    click_frame(qtbot, timeline, 5)
    assert window.doc.scene.objects[1].center == pytest.approx((ball_x(5), 0.8, 0.0))
    assert "objects[ball].center was not keyed" in window.statusBar().currentMessage()

    # with the focus on a slider of the properties panel, I keys (one more key at frame 5)
    slider = window.properties.row("material", "kr").editor.slider
    qtbot.mouseClick(slider, LEFT, NO_MOD, QPoint(2, slider.height() // 2))
    assert slider.hasFocus()
    qtbot.keyClick(slider, Qt.Key.Key_I)
    assert 5 in [k[0] for k in window.doc.scene.animation.tracks[0].keys]

    # typing an "i" in a text field types it: no key
    window.select(BALL)
    before = window.doc.scene.animation
    line = window.properties.row("name").editor.line
    type_into(qtbot, line, "big", finish=False)
    qtbot.keyClick(line, Qt.Key.Key_I)
    assert line.text() == "bigi" and window.doc.scene.animation == before


def test_the_first_key_of_a_still_scene_makes_the_animation(make_window, qtbot):  # noqa: F811
    window = make_window(preview=False, warm_up=False)
    timeline = window.timeline
    assert window.doc.scene.animation is None and not timeline.isVisible()
    window.viewport.setFocus()
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)  # the camera is selected
    anim = window.doc.scene.animation
    assert anim is not None and anim.frames == 48 and anim.fps == 24
    assert [t.path for t in anim.tracks] == ["camera.position", "camera.look_at"]
    assert timeline.isVisible()
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    assert window.doc.scene.animation is None
    # the render settings have nothing to key: a message, no edit
    window.select(("render",))
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)
    assert window.doc.scene.animation is None
    assert "select an object" in window.statusBar().currentMessage()


def test_a_key_on_an_edit_lands_in_the_saved_file(open_rolling, rolling, qtbot):
    window = open_rolling(preview=False, warm_up=False)
    timeline = window.timeline
    timeline.slider.setFocus()
    qtbot.keyClick(timeline.slider, Qt.Key.Key_End)
    assert timeline.frame == 7
    click_tree(qtbot, window.tree, BALL)
    assert center_shown(window) == pytest.approx((1.5, 0.8, 0.0))
    type_into(qtbot, window.properties.row("center").editor.lines[1], "2")  # y: up
    # not keyed yet: the picture shows the edit, the track does not undo it
    assert timeline.still(window.doc.scene).objects[1].center == (1.5, 2.0, 0.0)
    click_tree(qtbot, window.tree, BALL)
    qtbot.keyClick(window.tree, Qt.Key.Key_I)
    qtbot.keyClick(window.tree, Qt.Key.Key_S, CTRL)
    assert not window.errors and not window.doc.dirty

    text = rolling.read_text(encoding="utf-8")
    assert "# A small animated scene: the ball rolls" in text
    assert 'path = "objects[ball].center"   # left to right' in text
    assert "  [0, [-1, 0.8, 0]],\n  [7, [1.5, 2.0, 0.0]],\n]" in text
    saved = whitted.load_scene(rolling)
    assert saved.at_frame(7).objects[1].center == (1.5, 2.0, 0.0)
    assert saved.at_frame(0).objects[1].center == (-1.0, 0.8, 0.0)
    assert saved.at_frame(4).objects[1].center == pytest.approx((ball_x(4), 0.8 + 1.2 * 4 / 7,
                                                                 0.0))


def test_play_advances_frames_and_stop_stops(open_rolling, qtbot):
    window = open_rolling(preview=False, warm_up=False)
    timeline = window.timeline
    seen = []
    timeline.frame_changed.connect(seen.append)
    qtbot.mouseClick(timeline.play_button, LEFT)
    assert timeline.playing and timeline.play_button.text().endswith("Stop")
    assert window.controller.interacting  # coarse previews while playing
    qtbot.waitUntil(lambda: len(seen) >= 10, timeout=5000)  # 24 fps, eight frames: loops
    qtbot.mouseClick(timeline.play_button, LEFT)
    assert not timeline.playing and timeline.play_button.text().endswith("Play")
    assert not window.controller.interacting  # the frame stopped at refines
    assert seen[:10] == [1, 2, 3, 4, 5, 6, 7, 0, 1, 2]
    stopped = timeline.frame
    qtbot.wait(200)
    assert timeline.frame == stopped and len(seen) in (10, 11)
    assert window.doc.scene.objects[1].center == pytest.approx((ball_x(stopped), 0.8, 0.0))
    assert not window.doc.dirty  # showing frames is not an edit


def test_render_animation_saves_then_makes_the_film_that_whitted_animate_makes(
        open_rolling, rolling, qtbot, tmp_path):
    import imageio.v3 as iio

    from whitted.animation.frames import frame_digest, frame_is_current

    window = open_rolling(preview=False, warm_up=False)
    timeline = window.timeline
    film = tmp_path / "rolling.gif"
    timeline.ask_film_path = lambda: film
    click_tree(qtbot, window.tree, BALL)
    click_frame(qtbot, timeline, 4)
    qtbot.keyClick(window.tree, Qt.Key.Key_I)  # unsaved: saved before the film, once asked
    asked = []
    window.ask_save_for_film = lambda: asked.append("no") and False
    qtbot.mouseClick(timeline.film_button, LEFT)
    assert asked == ["no"] and window.doc.dirty and not timeline.film_running
    window.ask_save_for_film = lambda: asked.append("yes") or True
    with qtbot.waitSignal(timeline.film_done, timeout=SLOW) as done:
        qtbot.mouseClick(timeline.film_button, LEFT)
        assert asked == ["no", "yes"] and not window.doc.dirty and timeline.film_running
    job = done.args[0]
    assert job.error is None and not job.stopped and job.rendered == 8
    assert "Wrote" in timeline.film_status.text() and timeline.film_progress.value() == 1000
    frames = iio.imread(film, index=None)
    assert frames.shape[:3] == (8, 48, 64)
    saved = whitted.load_scene(rolling)
    assert len(saved.animation.tracks) == 2  # the key made in the editor is in the film
    for k in range(8):  # the frames whitted animate (and render --frame K) would write
        assert frame_is_current(tmp_path / "rolling_frames" / f"{k:04d}.png",
                                frame_digest(saved.at_frame(k), k))


def _rendering_frame(status: str) -> int:
    """k of a film status 'frame k/8 ...', 0 for any other text."""
    import re

    found = re.match(r"frame (\d+)/8", status)
    return int(found.group(1)) if found else 0


def test_a_stopped_film_keeps_its_frames_and_the_next_run_continues(make_window, qtbot,  # noqa: F811
                                                                    tmp_path):
    path = tmp_path / "rolling.toml"  # frames of a few tenths of a second: time to stop
    path.write_text(ROLLING_BALL.replace("width = 64\nheight = 48",
                                         "width = 400\nheight = 300\nsamples = 4"))
    window = make_window(whitted.load_scene(path), path, preview=False, warm_up=False)
    timeline = window.timeline
    film = tmp_path / "rolling.mp4"
    timeline.ask_film_path = lambda: film
    with qtbot.waitSignal(timeline.film_done, timeout=SLOW) as done:
        timeline.render_animation()
        qtbot.waitUntil(lambda: timeline.film.done >= 2, timeout=SLOW)
        # the panel says which frame is rendering (the third or, on a slow machine where a
        # short frame passed between two looks, a later one)
        qtbot.waitUntil(lambda: _rendering_frame(timeline.film_status.text()) >= 3,
                        timeout=SLOW)
        assert 200 <= timeline.film_progress.value() < 1000
        qtbot.mouseClick(timeline.film_stop, LEFT)
    first = done.args[0]
    assert first.stopped and 2 <= first.done < 8 and not film.exists()
    assert "Stopped" in timeline.film_status.text()
    on_disk = sorted(p.name for p in (tmp_path / "rolling_frames").glob("*.png"))
    assert on_disk == [f"{k:04d}.png" for k in range(first.done)]

    with qtbot.waitSignal(timeline.film_done, timeout=SLOW) as done:
        qtbot.mouseClick(timeline.film_button, LEFT)
    second = done.args[0]
    assert second.kept == first.done and second.rendered == 8 - first.done
    assert film.stat().st_size > 0 and not window.errors


def test_frames_box_edits_the_animation_and_refuses_to_cut_keys(open_rolling, qtbot):
    window = open_rolling(preview=False, warm_up=False)
    box = window.timeline.frames_box
    qtbot.mouseClick(box, LEFT)
    for text, frames in (("12", 12), ("4", 12)):  # 4 would leave the key at frame 7 out
        qtbot.keyClick(box, Qt.Key.Key_A, CTRL)
        qtbot.keyClicks(box, text)
        qtbot.keyClick(box, Qt.Key.Key_Return)
        assert window.doc.scene.animation.frames == frames
    assert "outside 0..3" in window.statusBar().currentMessage()
    assert window.timeline.slider.maximum() == 11
    qtbot.keyClick(box, Qt.Key.Key_Z, CTRL)
    assert window.doc.scene.animation.frames == 8 and window.timeline.slider.maximum() == 7


# ---------------------------------------------------------------------- keys and poses, no Qt


def test_posing_is_what_at_frame_shows_and_leaves_shared_materials_shared(rolling):
    from whitted.animation import Track
    from whitted.gui.keyframes import frame_still, posed

    scene = whitted.load_scene(rolling)
    kt = Track("objects[ball].material.kr", {0: 0.0, 7: 0.7})
    scene = scene.with_animation(8, 24, [*scene.animation.tracks, kt])
    for frame in (0, 3, 7):
        pose = posed(scene, frame)
        assert pose.objects[1].center == pytest.approx((ball_x(frame), 0.8, 0.0))
        assert pose.objects[1].material == "plastic"  # not given its own copy
        assert posed(pose, frame) == pose
        assert frame_still(pose, frame) == scene.at_frame(frame)
        assert frame_still(pose, frame).objects[1].material.kr == pytest.approx(0.1 * frame)
    assert scene.objects[1].center == (-1.0, 0.8, 0.0)  # the scene posed is unchanged


def test_insert_keys_names_items_readably_and_replaces_a_key_at_the_frame(rolling):
    from whitted.gui.keyframes import insert_keys, key_targets

    scene = whitted.load_scene(rolling)
    lamp = key_targets(scene, ("lights", 1))
    assert lamp == [("lights[lamp].position", [-4.0, 6.0, 5.0])]
    assert key_targets(scene, ("lights", 0)) == []  # an ambient light has no place
    assert key_targets(scene, ("render",)) == [] and key_targets(scene, None) == []
    twin = scene.model_copy(update={"objects": [*scene.objects, scene.objects[1]]})
    assert key_targets(twin, ("objects", 2))[0][0] == "objects[2].center"  # name not unique
    keyed = insert_keys(scene, [("objects[1].center", [0.0, 3.0, 0.0])], 7)
    track = keyed.animation.tracks[0]  # the same value, spelt another way: the same track
    assert len(keyed.animation.tracks) == 1 and track.path == "objects[ball].center"
    assert track.keys == [(0, [-1, 0.8, 0]), (7, [0.0, 3.0, 0.0])]
    with pytest.raises(ValueError, match="outside 0..7"):
        insert_keys(scene, lamp, 9)


def test_saving_writes_the_animation_table_compactly_and_reads_it_back(rolling):
    from whitted.scene.toml_document import compact_toml, scene_toml

    scene = whitted.load_scene(rolling)
    text = compact_toml(scene)
    assert "[animation]\nframes = 8\n\n[[animation.tracks]]\npath = \"objects[ball].center\"\n" \
           "keys = [\n    [0, [-1, 0.8, 0]],\n    [7, [1.5, 0.8, 0]],\n]\n" in text
    assert whitted.scene.io.scene_from_dict(whitted.scene.io.parse_scene_text(
        text, ".toml")) == scene
    still = scene.model_copy(update={"animation": None})
    assert "animation" not in scene_toml(still, text=ROLLING_BALL, loaded=scene)
    assert scene_toml(scene, text=ROLLING_BALL, loaded=scene) == ROLLING_BALL


def test_saving_edits_frames_and_keys_of_the_animation_table_in_place(rolling):
    from whitted.gui.keyframes import insert_keys
    from whitted.scene.toml_document import scene_toml

    scene = whitted.load_scene(rolling)
    longer = scene.with_animation(12, 30, scene.animation.tracks)
    keyed = insert_keys(longer, [("objects[ball].center", [0, 2, 0])], 10)
    text = scene_toml(keyed, text=ROLLING_BALL, loaded=scene)
    expected = ROLLING_BALL.replace("frames = 8\nfps = 24", "frames = 12\nfps = 30.0").replace(
        "  [7, [1.5, 0.8, 0]],\n", "  [7, [1.5, 0.8, 0]],\n  [10, [0, 2, 0]],\n")
    assert text == expected
    unkeyed = scene.with_animation(8, 24, [])
    text = scene_toml(unkeyed, text=ROLLING_BALL, loaded=scene)
    assert "[[animation.tracks]]" not in text and "frames = 8" in text


def test_tracks_follow_their_object_through_rename_duplicate_and_delete(open_rolling, qtbot):
    window = open_rolling(preview=False, warm_up=False)
    tree = window.tree
    click_tree(qtbot, tree, BALL)
    type_into(qtbot, window.properties.row("name").editor.line, "bowl")
    assert window.doc.scene.objects[1].name == "bowl"
    assert window.doc.scene.animation.tracks[0].path == "objects[bowl].center"

    click_tree(qtbot, tree, ("objects", 0))
    qtbot.keyClick(tree, Qt.Key.Key_D, CTRL)  # the floor's copy goes before the bowl
    qtbot.keyClick(window.viewport, Qt.Key.Key_Escape)  # (left where the floor is)
    assert [o.name for o in window.doc.scene.objects] == ["floor", "floor.001", "bowl"]
    assert window.doc.scene.at_frame(7).objects[2].center == (1.5, 0.8, 0.0)

    click_tree(qtbot, tree, ("objects", 2))
    qtbot.keyClick(tree, Qt.Key.Key_Delete)  # its track goes with it
    assert len(window.doc.scene.objects) == 2 and window.doc.scene.animation.tracks == []
    qtbot.keyClick(tree, Qt.Key.Key_Z, CTRL)
    assert window.doc.scene.animation.tracks[0].path == "objects[bowl].center"


def test_a_track_by_index_follows_its_item_when_the_list_moves(rolling):
    from whitted.animation import Track
    from whitted.gui.keyframes import tracks_following_items

    scene = whitted.load_scene(rolling)
    scene = scene.with_animation(8, 24, [Track("objects[1].center", {0: [0, 1, 0]}),
                                         Track("lights[lamp].intensity", {0: 0.5})])
    floor, ball = scene.objects
    anim = tracks_following_items(scene, {"objects": [floor.model_copy(), floor, ball]})
    assert [t.path for t in anim.tracks] == ["objects[2].center", "lights[lamp].intensity"]
    assert tracks_following_items(scene, {"objects": [floor, ball]}) is None
    anim = tracks_following_items(scene, {"lights": [scene.lights[0]]})  # the lamp deleted
    assert [t.path for t in anim.tracks] == ["objects[1].center"]
