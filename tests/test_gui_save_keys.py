"""Keying and saving never loses what the user wrote. Every example is
opened, an object clicked in the picture, I pressed, Ctrl+S pressed: the file changes only by
its new keys (comments, layout and every setting of the animation, ``cyclic`` included, stay).
When the edit cannot be written into the file as it is, the user is asked first."""

from __future__ import annotations

import difflib
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import QPoint, Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, make_window  # noqa: E402, F401
from whitted.gui import files as files_module  # noqa: E402

EXAMPLES = Path(__file__).parents[1] / "examples"
NAMES = sorted(p.name for p in EXAMPLES.glob("*.toml"))


@pytest.fixture
def examples(tmp_path) -> Path:
    folder = tmp_path / "examples"
    shutil.copytree(EXAMPLES, folder)
    return folder


def object_pixel(window, index: int) -> QPoint | None:
    """A widget position on the picture where object ``index`` is seen (None: not seen)."""
    ids = window.ids.ids_for(window.shown_scene())
    ys, xs = np.nonzero(ids == index)
    if not len(xs):
        return None
    k = len(xs) // 2
    h, w = ids.shape
    p = window.viewport.to_widget((xs[k] + 0.5) / w, (ys[k] + 0.5) / h)
    return QPoint(round(p.x()), round(p.y()))


def seen_object(window) -> tuple[int, QPoint]:
    """The last object of the scene that the picture shows (the teal cone of camera_orbit)."""
    for index in reversed(range(len(window.doc.scene.objects))):
        pos = object_pixel(window, index)
        if pos is not None:
            return index, pos
    raise AssertionError("no object is seen")


@pytest.mark.parametrize("name", NAMES)
def test_an_example_keyed_and_saved_changes_only_by_its_new_keys(
        make_window, qtbot, examples, name):  # noqa: F811
    path = examples / name
    text = path.read_text(encoding="utf-8")
    original = whitted.load_scene(path)
    window = make_window(original, path, preview=False, warm_up=False)
    index, pos = seen_object(window)
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton, pos=pos)
    assert window.doc.selection == ("objects", index)
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)
    assert window.doc.dirty
    asked = []
    window.ask_rewrite = lambda p: asked.append(p) or "cancel"
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    assert not asked and not window.errors and not window.doc.dirty
    saved = path.read_text(encoding="utf-8")
    diff = [line for line in difflib.unified_diff(text.splitlines(), saved.splitlines(),
                                                  lineterm="", n=0)
            if line[:1] in "+-" and not line.startswith(("+++", "---"))]
    assert diff and all(line.startswith("+") for line in diff), diff  # only added lines
    added = "\n".join(line[1:] for line in diff)
    assert "keys" in added and "path" in added
    loaded = whitted.load_scene(path)
    anim, before = loaded.animation, original.animation
    if before is not None:  # every setting of the animation stays, cyclic included
        assert (anim.frames, anim.fps, anim.cyclic) == (before.frames, before.fps,
                                                        before.cyclic)
        assert anim.tracks[: len(before.tracks)] == before.tracks
    assert len(anim.tracks) > (len(before.tracks) if before is not None else 0)


def test_camera_orbit_stays_cyclic_after_a_key(make_window, qtbot, examples):  # noqa: F811
    """The report's case: the teal cone keyed in camera_orbit.toml; the film still loops."""
    path = examples / "camera_orbit.toml"
    window = make_window(whitted.load_scene(path), path, preview=False, warm_up=False)
    cone = next(i for i, o in enumerate(window.doc.scene.objects) if o.name == "cones")
    pos = object_pixel(window, cone)
    qtbot.mouseClick(window.viewport, Qt.MouseButton.LeftButton, pos=pos)
    assert window.doc.selection == ("objects", cone)
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    loaded = whitted.load_scene(path)
    assert loaded.animation.cyclic is True
    assert "cyclic = true" in path.read_text(encoding="utf-8")


def test_a_save_that_would_rewrite_the_file_asks_first(
        make_window, qtbot, examples, monkeypatch):  # noqa: F811
    """When the file's own layout cannot carry an edit, Ctrl+S asks; "cancel" leaves the
    file byte for byte; "rewrite" writes the whole scene."""
    path = examples / "glass_cube.toml"
    text = path.read_bytes()
    window = make_window(whitted.load_scene(path), path, preview=False, warm_up=False)
    qtbot.keyClick(window.viewport, Qt.Key.Key_I)  # the camera is selected: key it
    assert window.doc.dirty
    monkeypatch.setattr(files_module, "edited_toml", lambda *args, **kwargs: None)
    asked = []
    window.ask_rewrite = lambda p: asked.append(p) or "cancel"
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    assert asked == [path] and path.read_bytes() == text and window.doc.dirty
    assert "Not saved" in window.statusBar().currentMessage()
    window.ask_rewrite = lambda p: "rewrite"
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    assert not window.doc.dirty and path.read_bytes() != text
    assert whitted.load_scene(path) == window.doc.scene


# ---------------------------------------------------------------------- fuzzing the saver

from functools import cache  # noqa: E402

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from whitted import scene as S  # noqa: E402
from whitted.gui.document import rebuild_scene  # noqa: E402
from whitted.gui.keyframes import insert_keys, key_targets  # noqa: E402
from whitted.scene.toml_document import edited_toml  # noqa: E402

#: what the editor does to a scene: (name, object index, frame or value)
EDITS = st.lists(st.tuples(
    st.sampled_from(["key", "move", "radius", "add", "delete", "frames"]),
    st.integers(0, 30), st.integers(1, 60)), min_size=1, max_size=5)


@cache
def _example(name: str):
    path = EXAMPLES / name
    return path.read_text(encoding="utf-8"), whitted.load_scene(path)


def _edit(scene, what: str, index: int, n: int):
    """One edit as the editor makes it (validated; tracks follow moved and deleted items)."""
    objects = list(scene.objects)
    k = index % len(objects)
    obj = objects[k]
    if what == "key":
        return insert_keys(scene, key_targets(scene, ("objects", k)), n % 48)
    if what == "frames" and scene.animation is not None:  # a longer film
        frames = scene.animation.frames + n
        return rebuild_scene(scene, animation=scene.animation.model_copy(
            update={"frames": frames}))
    if what == "move" and getattr(obj, "center", None) is not None:
        c = obj.center
        objects[k] = obj.model_copy(update={"center": (c[0] + n / 10, c[1], c[2])})
    elif what == "radius" and getattr(obj, "radius", None) is not None:
        objects[k] = obj.model_copy(update={"radius": n / 20})
    elif what == "add":
        objects.append(S.Sphere(name=f"new {n}", center=(n / 10, 0.5, 0.0), radius=0.5))
    elif what == "delete" and len(objects) > 1:
        del objects[k]
    return rebuild_scene(scene, objects=objects)


@pytest.mark.parametrize("name", ["camera_orbit.toml", "glass_cube.toml"])
@given(edits=EDITS)
@settings(max_examples=15, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_fuzz_the_editors_edits_are_written_into_the_file_and_keep_its_comments(name, edits):
    """Whatever run of the editor's edits (keys, moves, new values, new and deleted objects,
    a longer film) is saved, it is written into the file as it is: the result reads back as
    the edited scene (checked inside), every comment stays, and ``cyclic`` too."""
    text, original = _example(name)
    scene = original
    for edit in edits:
        scene = _edit(scene, *edit)
    out = edited_toml(scene, text, original)
    assert out is not None  # never a whole rewrite for these
    kept = set(out.splitlines())
    assert all(line in kept for line in text.splitlines() if line.lstrip().startswith("#"))
    if original.animation is not None and original.animation.cyclic:
        assert "cyclic = true" in kept
