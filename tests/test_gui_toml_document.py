"""Saving keeps a hand-written TOML scene as it was except for what was edited:
byte for byte when nothing changed, one value when one value changed, new items
compact; and in the editor, through real key presses."""

from __future__ import annotations

import difflib

import pytest

pytest.importorskip("PySide6.QtWidgets")

from PySide6.QtCore import Qt  # noqa: E402

import whitted  # noqa: E402
from gui_input import CTRL, click_tree, make_window, type_into  # noqa: E402, F401
from whitted import scene as S  # noqa: E402
from whitted.scene.toml_document import compact_data, compact_toml, edit_toml, scene_toml

HAND_WRITTEN = '''\
# A hand-written scene: the comments, the blank lines and the short vectors must survive.

[render]
width = 64   # small, for the tests
height = 48
max_depth = 4

[camera]
position = [0, 1.5, 6]        # eye
look_at  = [0, 0.6, 0]
fov = 40

[[lights]]
type = "ambient"
intensity = 0.2

[[lights]]
# the key light
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
center = [0, 0.8, 0]
radius = 0.8
material = { preset = "plastic", color = "#3366cc" }   # blue plastic
'''


@pytest.fixture
def hand_written(tmp_path):
    path = tmp_path / "hand.toml"
    path.write_text(HAND_WRITTEN)
    return path


def changed_lines(a: str, b: str) -> list[str]:
    return [d for d in difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
            if d[:1] in "+-" and not d.startswith(("+++", "---"))]


def test_nothing_edited_is_byte_for_byte(hand_written):
    scene = whitted.load_scene(hand_written)
    assert scene_toml(scene, text=HAND_WRITTEN, loaded=scene) == HAND_WRITTEN


def test_one_edited_value_changes_only_that_value(hand_written):
    scene = whitted.load_scene(hand_written)
    objects = list(scene.objects)
    objects[1] = objects[1].model_copy(update={"radius": 0.6})
    edited = scene.model_copy(update={"objects": objects})
    out = scene_toml(edited, text=HAND_WRITTEN, loaded=scene)
    assert changed_lines(HAND_WRITTEN, out) == ["-radius = 0.8", "+radius = 0.6"]
    # a nested value: the colour inside the inline material table, the comment kept
    material = scene.material_of(1).model_copy(update={"color": (1.0, 0.0, 0.0)})
    objects[1] = objects[1].model_copy(update={"material": material})
    out = scene_toml(scene.model_copy(update={"objects": objects}), text=HAND_WRITTEN,
                     loaded=scene)
    lines = changed_lines(HAND_WRITTEN, out)
    assert len(lines) == 4 and lines[1] == "-material = { preset = \"plastic\", color = " \
        "\"#3366cc\" }   # blue plastic"
    assert lines[3].startswith("+material = { preset = \"plastic\", color = [1.0, 0.0, 0.0]")
    assert lines[3].endswith("# blue plastic")
    assert whitted.scene.io.scene_from_dict(
        whitted.scene.io.parse_scene_text(out, ".toml")).material_of(1).color == (1, 0, 0)


def test_new_and_deleted_items(hand_written):
    scene = whitted.load_scene(hand_written)
    new_ball = S.Sphere(name="glass ball", center=(1.0, 0.5, 0.0), radius=0.5, material="glass")
    edited = scene.model_copy(update={"objects": [*scene.objects, new_ball],
                                      "lights": scene.lights[1:]})
    out = scene_toml(edited, text=HAND_WRITTEN, loaded=scene)
    added = [line[1:] for line in changed_lines(HAND_WRITTEN, out) if line.startswith("+")]
    # the new sphere: compact, only its non-default values
    assert added[-6:] == ["[[objects]]", 'type = "sphere"', 'name = "glass ball"',
                          'material = "glass"', "center = [1.0, 0.5, 0.0]", "radius = 0.5"]
    assert "# the key light" in out and "# blue plastic" in out
    assert out.count("[[lights]]") == 1


def test_compact_form_has_only_non_default_values():
    assert compact_data(S.Sphere(center=(0, 1, 0), radius=2)) == {
        "type": "sphere", "center": [0.0, 1.0, 0.0], "radius": 2.0}
    assert compact_data(whitted.Material(preset="glass")) == {"preset": "glass"}
    assert compact_data(whitted.Material(preset="glass", kr=0.5)) == {"preset": "glass",
                                                                        "kr": 0.5}
    scene = whitted.default_scene()
    text = compact_toml(scene)
    assert whitted.scene.io.scene_from_dict(whitted.scene.io.parse_scene_text(
        text, ".toml")) == scene
    assert "ka = 0.2" not in text  # a default is not written out


def test_an_edit_that_the_file_cannot_carry_falls_back_to_the_compact_form(hand_written):
    scene = whitted.load_scene(hand_written)
    other = whitted.default_scene()
    # ``loaded`` not what the text holds: the edit cannot be trusted, the compact form is
    assert edit_toml(HAND_WRITTEN, scene, scene) == HAND_WRITTEN
    out = scene_toml(other, text=HAND_WRITTEN, loaded=scene.model_copy(
        update={"objects": []}))
    assert whitted.scene.io.scene_from_dict(whitted.scene.io.parse_scene_text(
        out, ".toml")) == other


def test_the_editor_saves_only_what_was_typed(make_window, hand_written, qtbot):  # noqa: F811
    window = make_window(scene=whitted.load_scene(hand_written), path=hand_written,
                         preview=False, warm_up=False)
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)  # nothing edited: the same bytes
    assert hand_written.read_text() == HAND_WRITTEN
    click_tree(qtbot, window.tree, ("objects", 1))
    type_into(qtbot, window.properties.row("radius").editor.line, "0.6")
    qtbot.keyClick(window.properties.row("radius").editor.line, Qt.Key.Key_S, CTRL)
    assert not window.errors and not window.doc.dirty, window.errors
    assert changed_lines(HAND_WRITTEN, hand_written.read_text()) == [
        "-radius = 0.8", "+radius = 0.6"]
    # a light added from the menu is written compactly at the end of the lights
    window.light_actions["point"].trigger()
    qtbot.keyClick(window.viewport, Qt.Key.Key_S, CTRL)
    text = hand_written.read_text()
    added = [line for line in changed_lines(HAND_WRITTEN, text) if line.startswith("+")]
    assert len(added) < 10 and "+[[lights]]" in added
    assert whitted.load_scene(hand_written) == window.doc.scene.with_base_dir(
        hand_written.parent)


def test_a_named_material_made_the_objects_own_stays_inline_and_new_blocks_are_apart():
    """``material = "glass"`` becoming an object's own material is
    written on its line (not as a sub-table), and new ``[[objects]]`` blocks are separated
    by a blank line, as people write them."""
    text = ('[materials.glass]\npreset = "glass"\n\n[[objects]]\ntype = "sphere"\n'
            'radius = 1\nmaterial = "glass"\n')
    from whitted.scene.io import parse_scene_text, scene_from_dict

    scene = scene_from_dict(parse_scene_text(text, ".toml"))
    own = scene.materials["glass"].model_copy(update={"ior": 1.6})
    objects = [scene.objects[0].model_copy(update={"material": own}),
               S.Sphere(name="a", center=(0, 1, 0), radius=0.5),
               S.Sphere(name="b", center=(1, 1, 0), radius=0.5)]
    edited = scene.model_copy(update={"objects": objects})
    out = scene_toml(edited, text=text, loaded=scene)
    assert out.startswith(text.replace('material = "glass"\n', ""))
    assert 'material = {preset = "glass", ior = 1.6}\n' in out
    assert "[objects.material]" not in out
    assert out.endswith('\n\n[[objects]]\ntype = "sphere"\nname = "a"\ncenter = [0.0, 1.0, 0.0]\n'
                       'radius = 0.5\n\n[[objects]]\ntype = "sphere"\nname = "b"\n'
                       'center = [1.0, 1.0, 0.0]\nradius = 0.5\n')
    assert "\n\n[[objects]]" in compact_toml(edited)
