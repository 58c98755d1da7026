"""scene/toml_document.py without the editor: compact TOML of every kind of item (CSG
children, named materials, animation tracks, a table of defaults), edits of named materials,
lights, objects and the ``[animation]`` table that keep the rest of a file byte for byte, the
fall-backs when an edit cannot be carried, and saving into another folder."""

from __future__ import annotations

import pytest

import whitted
from whitted import scene as S
from whitted.scene.animation import Animation, Track
from whitted.scene.io import parse_scene_text, scene_from_dict
from whitted.scene.toml_document import (
    compact_data,
    compact_toml,
    edit_toml,
    edited_toml,
    scene_toml,
)
from whitted.scene.writing import save_scene


def load(text: str) -> whitted.Scene:
    return scene_from_dict(parse_scene_text(text, ".toml"))


FILM = '''\
# film
[materials.red]
color = [1, 0, 0]   # red
[materials.blue]
color = [0, 0, 1]

[[lights]]
type = "point"
position = [0, 5, 0]

[[objects]]
type = "sphere"
radius = 1
material = "red"

[animation]
frames = 10   # short
[[animation.tracks]]
path = "camera.position"
keys = [
    [0, [0, 0, 5]],   # start
    [9, [1, 0, 5]],
]
[[animation.tracks]]
path = "camera.fov"
keys = [[0, 40], [9, 50]]
'''

LIGHTS_AND_OBJECTS = FILM[FILM.index("[[lights]]"):FILM.index("[animation]")]
ANIMATION = FILM[FILM.index("[animation]"):]


def edited(new: whitted.Scene) -> str:
    """FILM edited to say ``new``, checked to load as ``new``."""
    out = edit_toml(FILM, load(FILM), new)
    assert load(out) == new
    return out


# ---------------------------------------------------------------------- compact form


def test_a_table_of_defaults_is_written_as_an_empty_table():
    """``[render.antialias]`` with every value left at its default turns anti-aliasing on: the
    compact form must say so (it wrote nothing, so saving fell back to the long form)."""
    scene = whitted.Scene(render={"antialias": {}})
    assert compact_data(scene.render) == {"antialias": {}}
    assert compact_toml(scene) == "[render]\nantialias = {}\n"
    assert scene_toml(scene) == "[render]\nantialias = {}\n"
    assert load(scene_toml(scene)) == scene


def test_compact_csg_children_named_materials_and_tracks():
    csg = S.CSG(operation="difference", objects=[S.Box(min=(-1, -1, -1), max=(1, 1, 1)),
                                                 S.Sphere(radius=1.2)])
    scene = whitted.Scene(
        objects=[csg], materials={"red": whitted.Material(color=(1, 0, 0))},
        animation={"frames": 10, "tracks": [
            {"path": "camera.position", "keys": [[0, [0, 0, 5]], [9, [1, 0, 5]]],
             "interpolation": "smooth"},
            {"path": "camera.fov", "keys": [[0, 40]]}]})
    assert compact_data(scene) == {
        "materials": {"red": {"color": [1.0, 0.0, 0.0]}},
        "objects": [{"type": "csg", "operation": "difference", "objects": [
            {"type": "box", "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
            {"type": "sphere", "radius": 1.2}]}],
        "animation": {"frames": 10, "tracks": [
            {"path": "camera.position", "keys": [[0, [0, 0, 5]], [9, [1, 0, 5]]],
             "interpolation": "smooth"},
            {"path": "camera.fov", "keys": [[0, 40]]}]},
    }
    text = compact_toml(scene)
    assert text == (
        '[materials.red]\ncolor = [1.0, 0.0, 0.0]\n\n'
        '[[objects]]\ntype = "csg"\noperation = "difference"\n'
        'objects = [{type = "box", min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0]}, '
        '{type = "sphere", radius = 1.2}]\n\n'
        '[animation]\nframes = 10\n\n'
        '[[animation.tracks]]\npath = "camera.position"\ninterpolation = "smooth"\n'
        'keys = [\n    [0, [0, 0, 5]],\n    [9, [1, 0, 5]],\n]\n\n'
        '[[animation.tracks]]\npath = "camera.fov"\nkeys = [[0, 40]]\n')
    assert load(text) == scene


def test_when_the_compact_form_does_not_load_back_every_value_is_spelt_out(monkeypatch):
    from whitted.scene import toml_document

    scene = whitted.Scene(objects=[S.Sphere(radius=2)])
    monkeypatch.setattr(toml_document, "compact_toml", lambda s: "[[objects]]\ntype = 'x'\n")
    text = scene_toml(scene)
    assert "[render]\nwidth = 640\nheight = 480\n" in text and "ka = 0.2" not in text
    assert '[[objects]]\ntype = "sphere"\n' in text and "radius = 2.0\n" in text
    assert load(text) == scene


# ---------------------------------------------------------------------- edits


def test_named_materials_changed_removed_and_added():
    scene = load(FILM)
    mats = {"red": whitted.Material(color=(1, 0.5, 0)),
            "green": whitted.Material(color=(0, 1, 0))}
    out = edited(scene.model_copy(update={"materials": mats}))
    # red edited in place (only the number that changed; its comment kept), blue gone (with
    # the blank line after it), green new; the rest as it was
    assert out == FILM.replace(
        "color = [1, 0, 0]   # red\n[materials.blue]\ncolor = [0, 0, 1]\n\n",
        "color = [1, 0.5, 0]   # red\n\n[materials.green]\ncolor = [0.0, 1.0, 0.0]\n")
    # the last material gone: the table goes (and the object's reference with it)
    out = edited(scene.model_copy(update={"materials": {}, "objects": [S.Sphere(radius=1)]}))
    assert out == "# film\n" + LIGHTS_AND_OBJECTS.replace('material = "red"\n', "") + ANIMATION


def test_named_materials_into_a_file_without_any():
    text = "[[objects]]\ntype = \"sphere\"\nradius = 1\n"
    old = load(text)
    new = old.model_copy(update={"materials": {"gold": whitted.Material(preset="chrome",
                                                                        color=(1, 0.8, 0))}})
    out = edit_toml(text, old, new)
    assert out == text + '\n[materials.gold]\npreset = "chrome"\ncolor = [1.0, 0.8, 0.0]\n'
    assert load(out) == new


def test_the_last_light_removed_and_an_object_replaced_by_another_kind():
    scene = load(FILM)
    out = edited(scene.model_copy(update={"lights": []}))
    assert out == FILM.replace('[[lights]]\ntype = "point"\nposition = [0, 5, 0]\n\n', "")
    out = edited(scene.model_copy(update={"objects": [S.Box(min=(0, 0, 0), max=(1, 1, 1))]}))
    assert '[[objects]]\ntype = "box"\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n' in out
    assert "sphere" not in out and out.endswith(ANIMATION)


def test_lights_into_a_file_without_any():
    text = "[camera]\nfov = 30\n"
    old = load(text)
    new = old.model_copy(update={"lights": [S.PointLight(position=(1, 2, 3))]})
    out = edit_toml(text, old, new)
    assert out == text + '\n[[lights]]\ntype = "point"\nposition = [1.0, 2.0, 3.0]\n'
    assert load(out) == new


def test_settings_tables_new_and_edited():
    text = "[camera]\nfov = 30   # narrow\n"
    old = load(text)
    new = old.model_copy(update={
        "camera": old.camera.model_copy(update={"fov": 45.0}),  # back to its default
        "render": old.render.model_copy(update={"width": 32}),
        "background": old.background.model_copy(update={"color": (0.5, 0.5, 0.5)})})
    out = edit_toml(text, old, new)
    assert out == ("[camera]\n\n[render]\nwidth = 32\n\n"
                   "[background]\ncolor = [0.5, 0.5, 0.5]\n")
    assert load(out) == new


# ---------------------------------------------------------------------- [animation]


def test_frames_fps_and_keys_edited_in_place():
    scene = load(FILM)
    anim = scene.animation
    position = anim.tracks[0].model_copy(update={
        "keys": [(0, [0, 0, 5]), (4, [0, 1, 5]), (9, [2, 0, 5])]})
    fov = anim.tracks[1].model_copy(update={"keys": [(0, 40), (5, 45), (9, 50)],
                                            "interpolation": "smooth"})
    out = edited(scene.model_copy(update={"animation": anim.model_copy(
        update={"frames": 12, "fps": 30.0, "tracks": [position, fov]})}))
    # the comment on the first key stays; a one-line keys array grows one key a line
    assert out.endswith(
        "[animation]\nframes = 12   # short\nfps = 30.0\n[[animation.tracks]]\n"
        'path = "camera.position"\nkeys = [\n    [0, [0, 0, 5]],   # start\n'
        "    [4, [0, 1, 5]],\n    [9, [2, 0, 5]],\n]\n[[animation.tracks]]\n"
        'path = "camera.fov"\nkeys = [\n    [0, 40],\n    [5, 45],\n    [9, 50],\n]\n'
        'interpolation = "smooth"\n')
    assert out.startswith(FILM[:FILM.index("[animation]")])


def test_a_key_removed_from_a_multiline_array():
    scene = load(FILM)
    anim = scene.animation
    one = anim.tracks[0].model_copy(update={"keys": [(9, [1, 0, 5])]})
    out = edited(scene.model_copy(update={"animation": anim.model_copy(
        update={"tracks": [one, anim.tracks[1]]})}))
    assert "keys = [\n    [9, [1, 0, 5]],\n]\n" in out and "# start" not in out


def test_tracks_removed_added_and_the_whole_table_dropped():
    scene = load(FILM)
    anim = scene.animation
    out = edited(scene.model_copy(update={"animation": anim.model_copy(
        update={"tracks": [anim.tracks[1]]})}))
    assert out.endswith("frames = 10   # short\n[[animation.tracks]]\n"
                        'path = "camera.fov"\nkeys = [[0, 40], [9, 50]]\n')
    out = edited(scene.model_copy(update={"animation": anim.model_copy(update={"tracks": []})}))
    assert out.endswith("[animation]\nframes = 10   # short\n")
    colour = Track("background.color", {0: [0, 0, 0], 9: [1, 1, 1]})
    out = edited(scene.model_copy(update={"animation": anim.model_copy(
        update={"tracks": [*anim.tracks, colour]})}))
    assert out == FILM + ('\n[[animation.tracks]]\npath = "background.color"\n'
                          "keys = [\n    [0, [0, 0, 0]],\n    [9, [1, 1, 1]],\n]\n")
    out = edited(scene.model_copy(update={"animation": None}))
    assert out == FILM[:FILM.index("[animation]")]


def test_inline_tracks_become_tables_and_animation_is_added_to_a_still():
    text = '[animation]\nframes = 5\ntracks = [{path = "camera.fov", keys = [[0, 40]]}]\n'
    old = load(text)
    new = old.model_copy(update={"animation": old.animation.model_copy(
        update={"tracks": [Track("camera.fov", {0: 30, 4: 60})]})})
    out = edit_toml(text, old, new)
    assert out == ('[animation]\nframes = 5\n\n[[animation.tracks]]\npath = "camera.fov"\n'
                   "keys = [\n    [0, 30],\n    [4, 60],\n]\n")
    assert load(out) == new
    still = "[camera]\nfov = 40\n"
    old = load(still)
    new = old.model_copy(update={"animation": Animation(frames=3, fps=12)})
    out = edit_toml(still, old, new)
    assert out == still + "\n[animation]\nframes = 3\nfps = 12.0\n"
    assert load(out) == new
    text = still + "[animation]\nframes = 3\n"
    old = load(text)
    new = old.model_copy(update={"animation": Animation(
        frames=3, tracks=[Track("camera.fov", {0: 30, 2: 60}, interpolation="step")])})
    out = edit_toml(text, old, new)
    assert out == text + ('\n[[animation.tracks]]\npath = "camera.fov"\n'
                          'interpolation = "step"\nkeys = [\n    [0, 30],\n    [2, 60],\n]\n')
    assert load(out) == new


# ---------------------------------------------------------------------- fall-backs, saving


def test_an_edit_that_cannot_be_carried_is_none():
    sphere = "[[objects]]\ntype = \"sphere\"\nradius = 1\n"
    # not TOML at all
    assert edited_toml(whitted.Scene(), "[[objects\n", load(sphere)) is None
    # the text is not what ``loaded`` says (a sphere, not a box): the edit writes a box's
    # keys into the sphere's table, which then does not load
    box = whitted.Scene(objects=[S.Box(min=(0, 0, 0), max=(1, 1, 1))])
    moved = whitted.Scene(objects=[S.Box(min=(0, 0, 0), max=(2, 2, 2))])
    assert edited_toml(moved, sphere, box) is None
    out = scene_toml(moved, text=sphere, loaded=box)  # the compact form instead
    assert out == ('[[objects]]\ntype = "box"\nmin = [0.0, 0.0, 0.0]\n'
                   "max = [2.0, 2.0, 2.0]\n")


def test_saving_into_another_folder_rebases_file_names(tmp_path):
    home, other = tmp_path / "home", tmp_path / "other"
    (home / "models").mkdir(parents=True)
    other.mkdir()
    (home / "models" / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    text = '[[objects]]\ntype = "mesh"\nfile = "models/tri.obj"   # the model\n'
    (home / "scene.toml").write_text(text)
    scene = whitted.load_scene(home / "scene.toml")
    # the same folder: the file as it was (nothing edited)
    save_scene(scene, home / "scene.toml", text=text, loaded=scene)
    assert (home / "scene.toml").read_text() == text
    save_scene(scene, other / "scene.toml", text=text, loaded=scene)
    written = (other / "scene.toml").read_text()
    assert written == '[[objects]]\ntype = "mesh"\nfile = "../home/models/tri.obj"\n'
    moved = whitted.load_scene(other / "scene.toml")
    assert moved.resolve_path(moved.objects[0].file).resolve() == home / "models" / "tri.obj"
    # Scene.save writes the same file as save_scene (one writer: compact TOML)
    scene.save(other / "again.toml")
    assert (other / "again.toml").read_text() == written
    assert sorted(p.name for p in other.iterdir()) == ["again.toml", "scene.toml"]


@pytest.mark.parametrize("preset", ["glass", "mirror"])
def test_a_preset_material_is_compared_with_its_preset(preset):
    own = whitted.Material(preset=preset, ior=1.7)
    assert compact_data(own) == {"preset": preset, "ior": 1.7}
    scene = whitted.Scene(objects=[S.Sphere(radius=1, material=own)])
    assert load(compact_toml(scene)) == scene


def test_items_edited_in_place_removed_and_added_and_a_track_retimed():
    text = ('[[lights]]\ntype = "ambient"\nintensity = 0.2\n\n[[lights]]\n# key\n'
            'type = "point"\nposition = [0, 5, 0]\n\n[[objects]]\ntype = "sphere"\n'
            'radius = 1   # unit\nmaterial = { preset = "plastic", color = [0, 0, 1] }\n\n'
            '[animation]\nframes = 4\n[[animation.tracks]]\npath = "camera.fov"\n'
            "keys = [[0, 30], [3, 60]]\n")
    old = load(text)
    ball = old.objects[0]
    ball = ball.model_copy(update={"radius": 2.0, "material": ball.material.model_copy(
        update={"color": (1.0, 0.0, 0.0)})})
    track = old.animation.tracks[0].model_copy(update={"interpolation": "smooth"})
    new = old.model_copy(update={
        "lights": old.lights[1:],
        "objects": [ball, S.Sphere(name="b", radius=0.5)],
        "animation": old.animation.model_copy(update={"tracks": [track]})})
    out = edit_toml(text, old, new)
    assert out == (
        '[[lights]]\n# key\ntype = "point"\nposition = [0, 5, 0]\n\n[[objects]]\n'
        'type = "sphere"\nradius = 2.0   # unit\n'
        'material = { preset = "plastic", color = [1.0, 0, 0.0] }\n'
        '\n[[objects]]\ntype = "sphere"\nname = "b"\nradius = 0.5\n\n'
        '[animation]\nframes = 4\n[[animation.tracks]]\npath = "camera.fov"\n'
        'keys = [[0, 30], [3, 60]]\ninterpolation = "smooth"\n')
    assert load(out) == new
