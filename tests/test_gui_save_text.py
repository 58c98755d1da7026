"""A save changes the file's text only where the user changed a value: a CSG child moved keeps
the multi-line array and its comments, one component moved leaves the others' spelling, an
object deleted and restored comes back as written (comments included), new numbers are
rounded as the file's are, and a key inserted at a frame leaves the still values alone. All
through real keys on the editor; the file's text compared before and after."""

from __future__ import annotations

import difflib
import re

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, click_tree, make_window, mouse  # noqa: E402, F401

LEFT, NO_MOD = Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier

SCENE = """\
# a hand-written scene
[render]
width = 48
height = 36

[camera]
position = [0.000, 1.500, 6.000]   # eye
look_at = [0, 0.6, 0]

[[lights]]
type = "point"
position = [-4, 6, 5]

# the red ball, on the left
[[objects]]
type = "sphere"
name = "ball"
center = [-2.100, 0.500, -0.500]   # where it rests
radius = 0.5
material = { color = "#c8322d", ka = 0.2 }

# the die
[[objects]]
type = "csg"
name = "die"
operation = "difference"
objects = [
    # the body
    { type = "box", min = [-0.5, 0, -0.5], max = [0.5, 1, 0.5] },
    # the pip
    { type = "sphere", name = "pip", center = [0, 0.500, 0.5], radius = 0.2 },
]
"""

BALL, DIE, PIP = ("objects", 0), ("objects", 1), ("objects", 1, 1)


@pytest.fixture
def opened(make_window, tmp_path):  # noqa: F811
    def open_(text: str = SCENE, **options):
        path = tmp_path / "scene.toml"
        path.write_text(text, encoding="utf-8")
        options.setdefault("preview", False)
        options.setdefault("warm_up", False)
        window = make_window(whitted.load_scene(path), path, **options)
        window.ask_rewrite = lambda p: pytest.fail("the save asked to rewrite the file")
        return window, path

    return open_


def changed(a: str, b: str) -> list[str]:
    return [d for d in difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
            if d[:1] in "+-" and not d.startswith(("+++", "---"))]


def save(qtbot, window) -> None:
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    assert not window.errors and not window.doc.dirty


def typed_move(qtbot, window, key, *keys: str) -> None:
    """G (with the tree's focus on ``key``), then the keys typed in the picture, Enter."""
    click_tree(qtbot, window.tree, key)
    qtbot.keyClick(window.tree, Qt.Key.Key_G)
    vp = window.viewport
    assert vp.tool is not None
    for k in keys:
        qtbot.keyClicks(vp, k)
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert vp.tool is None


def test_a_csg_child_moved_changes_one_number_in_the_array(opened, qtbot):
    window, path = opened()
    typed_move(qtbot, window, PIP, "x", "1")
    assert window.doc.item(PIP).center == pytest.approx((1.0, 0.5, 0.5))
    save(qtbot, window)
    assert changed(SCENE, path.read_text()) == [
        '-    { type = "sphere", name = "pip", center = [0, 0.500, 0.5], radius = 0.2 },',
        '+    { type = "sphere", name = "pip", center = [1.0, 0.500, 0.5], radius = 0.2 },']


def test_one_component_moved_then_undone_leaves_the_file_as_written(opened, qtbot):
    window, path = opened()
    typed_move(qtbot, window, BALL, "z", "0.25")
    save(qtbot, window)
    assert changed(SCENE, path.read_text()) == [
        "-center = [-2.100, 0.500, -0.500]   # where it rests",
        "+center = [-2.100, 0.500, -0.25]   # where it rests"]
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    save(qtbot, window)
    assert path.read_text() == SCENE  # "-0.500" again, not "-0.5"


def test_deleted_saved_restored_saved_is_the_file_as_written(opened, qtbot):
    window, path = opened()
    click_tree(qtbot, window.tree, BALL)
    qtbot.keyClick(window.tree, Qt.Key.Key_Delete)
    save(qtbot, window)
    gone = path.read_text()
    assert "ball" not in gone and "# the red ball" not in gone and "#c8322d" not in gone
    assert "# the die" in gone and "# the pip" in gone
    qtbot.keyClick(window.viewport, Qt.Key.Key_Z, CTRL)
    save(qtbot, window)
    assert path.read_text() == SCENE  # its comments, key order, "#c8322d" and ka = 0.2


def test_a_move_by_the_pointer_writes_numbers_rounded_as_the_file(opened, qtbot):
    window, path = opened(SCENE.replace("width = 48\nheight = 36", "width = 160\nheight = 120"))
    text = path.read_text()
    click_tree(qtbot, window.tree, BALL)
    vp = window.viewport
    centre = vp.picture_rect().center()
    mouse(vp, "move", centre, Qt.MouseButton.NoButton)
    qtbot.keyClick(window.tree, Qt.Key.Key_G)
    mouse(vp, "move", centre + QPoint(23, 7), Qt.MouseButton.NoButton)
    mouse(vp, "press", centre + QPoint(23, 7))
    mouse(vp, "release", centre + QPoint(23, 7))
    assert vp.tool is None
    save(qtbot, window)
    diff = changed(text, path.read_text())
    assert len(diff) == 2 and diff[0].startswith("-center") and diff[1].startswith("+center")
    numbers = re.findall(r"-?\d+\.\d+", diff[1])
    assert numbers and all(len(n.split(".")[1]) <= 3 for n in numbers), diff
    assert "0.500" in diff[1]  # the height did not change: its spelling stays
    saved = whitted.load_scene(path).objects[0].center
    assert saved == pytest.approx(window.doc.item(BALL).center, abs=5e-4)


ANIMATED = SCENE + """
[animation]
frames = 24

[[animation.tracks]]
path = "camera.position"
keys = [
    [0, [0, 1.5, 6]],
    [20, [3, 1.5, 4]],
]
"""


def test_a_key_at_an_unkeyed_frame_leaves_the_still_position(opened, qtbot):
    from test_gui_timeline import click_frame

    window, path = opened(ANIMATED)
    click_frame(qtbot, window.timeline, 7)
    assert window.timeline.frame == 7
    posed = window.doc.scene.camera.position
    assert posed != (0.0, 1.5, 6.0)  # between its keys
    click_tree(qtbot, window.tree, ("camera",))
    qtbot.keyClick(window.tree, Qt.Key.Key_I)
    save(qtbot, window)
    diff = changed(ANIMATED, path.read_text())
    assert all(d.startswith("+") for d in diff), diff  # only keys added
    assert "position = [0.000, 1.500, 6.000]   # eye" in path.read_text()
    added = "\n".join(diff)
    assert "[7, [" in added and "transform" not in added
    assert all(len(n.split(".")[1]) <= 3 for n in re.findall(r"\d+\.\d+", added)), added


# ------------------------------------------------------------- fuzzing: undone leaves no trace

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_gui_save_keys import _edit, _example  # noqa: E402
from whitted.scene.toml_document import edited_toml  # noqa: E402


@pytest.mark.parametrize("name", ["die.toml", "camera_orbit.toml"])
@given(edits=st.lists(st.tuples(st.sampled_from(["move", "radius", "add", "delete"]),
                                st.integers(0, 30), st.integers(1, 60)), min_size=1, max_size=5),
       kept=st.integers(0, 5))
@settings(max_examples=10, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_fuzz_edits_saved_then_some_undone_give_the_file_as_if_never_made(name, edits, kept):
    """Any run of the editor's edits of objects (moves, new radii, added and deleted ones)
    saved, then the last ones undone and saved again: the file the first edits alone would
    have given (what was undone leaves no trace), and with all undone the file's own text.
    (Keys have layout rules of their own: a track's keys stay one a line once they were.)"""
    text, original = _example(name)
    scenes = [original]
    for edit in edits:
        scenes.append(_edit(scenes[-1], *edit))
    saved = edited_toml(scenes[-1], text, original)
    assert saved is not None
    loaded = whitted.scene.io.scene_from_dict(whitted.scene.io.parse_scene_text(saved, ".toml"))
    target = scenes[min(kept, len(edits))]
    back = edited_toml(target, saved, loaded, history=[(text, original)])
    assert back == edited_toml(target, text, original)
    if target == original:
        assert back == text
