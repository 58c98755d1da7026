"""Scene files: every user mistake is a one-line SceneError naming file, line, key and problem;
valid files load, round-trip and decode colours and presets as documented. No rendering."""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest
from pydantic import ValidationError

import whitted
from whitted import SceneError, load_scene
from whitted.scene.writing import rebase_files

# A small valid scene. Each bad case below changes one thing in it. The comments after the
# [[objects]] headers make those lines easy to find (and check that comments are allowed there).
BASE = """\
[render]
width = 32
height = 24

[camera]
position = [0.0, 1.0, 6.0]
look_at = [0.0, 1.0, 0.0]

[[lights]]
type = "point"
position = [0.0, 5.0, 5.0]

[[objects]]  # the floor
type = "plane"
normal = [0.0, 1.0, 0.0]
material = "matte"

[[objects]]  # the ball
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 1.0
material = "glass"
"""

DIRECTORY = object()  # BadScene.content: make a folder instead of a file

def edit(old: str, new: str, text: str = BASE) -> str:
    """``text`` with the single occurrence of ``old`` replaced by ``new``."""
    assert text.count(old) == 1, old
    return text.replace(old, new)


@dataclass(frozen=True)
class BadScene:
    """A scene file with one mistake and what its error message must say."""

    id: str
    name: str  # file name in the test's folder
    content: str | bytes | object | None  # None: no file at all; DIRECTORY: a folder
    where: str | None  # the key path the message names
    line: str | int | None  # the line number, or text found only on that line
    words: tuple[str, ...]  # recognisable problem words (compared case-insensitively)
    api_xfail: str | None = None  # reason, where load_scene itself is wrong
    cli_xfail: str | None = None  # reason, where only the command line is wrong

    def write(self, folder: Path) -> Path:
        path = folder / self.name
        if self.content is DIRECTORY:
            path.mkdir()
        elif isinstance(self.content, bytes):
            path.write_bytes(self.content)
        elif isinstance(self.content, str):
            path.write_text(self.content, encoding="utf-8")
        return path

    def line_number(self) -> int | None:
        if self.line is None or isinstance(self.line, int):
            return self.line
        assert isinstance(self.content, str)
        hits = [i for i, raw in enumerate(self.content.splitlines(), 1) if self.line in raw]
        assert len(hits) == 1, f"{self.line!r} should be on exactly one line"
        return hits[0]


BAD_JSON = """\
{
  "render": {"width": 32, "height": 24},
  "objects": [
    {"type": "sphere", "radius": 1.0,}
  ]
}
"""

GLASS = 'material = "glass"'

BAD_SCENES = [
    BadScene("malformed-toml", "scene.toml", edit("radius = 1.0", "radius = = 1.0"),
             None, "radius = = 1.0", ("malformed toml",)),
    BadScene("malformed-json", "scene.json", BAD_JSON, None, '"radius": 1.0,}',
             ("malformed json",)),
    BadScene("unknown-top-level-key", "scene.toml", 'colour = "#ffffff"\n' + BASE,
             "colour", "colour =", ("unknown key",)),
    BadScene("unknown-object-key", "scene.toml",
             edit('type = "plane"\nnormal = [0.0, 1.0, 0.0]', 'type = "sphere"\nradiuss = 2.0'),
             "objects[0].radiuss", "radiuss = 2.0", ("unknown key", "did you mean 'radius'")),
    BadScene("unknown-camera-key", "scene.toml", edit("look_at =", "lookat ="),
             "camera.lookat", "lookat =", ("unknown key", "did you mean 'look_at'")),
    BadScene("wrong-type", "scene.toml", edit("radius = 1.0", 'radius = "big"'),
             "objects[1].radius", 'radius = "big"', ("number", "big")),
    BadScene("missing-value", "scene.toml", edit("radius = 1.0\n", ""),
             "objects[1].radius", "# the ball", ("missing",)),
    BadScene("negative-radius", "scene.toml", edit("radius = 1.0", "radius = -1.0"),
             "objects[1].radius", "radius = -1.0", ("greater than 0", "-1.0")),
    BadScene("zero-normal", "scene.toml",
             edit("normal = [0.0, 1.0, 0.0]", "normal = [0.0, 0.0, 0.0]"),
             "objects[0].normal", "normal =", ("zero",)),
    BadScene("zero-axis-inline", "scene.toml",
             edit(GLASS, GLASS + "\ntransform = { axis_angle = { axis = [0, 0, 0], angle = 30 } }"),
             "objects[1].transform.axis_angle.axis", "transform =", ("zero",)),
    BadScene("zero-axis-table", "scene.toml",
             BASE + "\n[objects.transform.axis_angle]\naxis = [0.0, 0.0, 0.0]\nangle = 30.0\n",
             "objects[1].transform.axis_angle.axis", "axis = [0.0, 0.0, 0.0]", ("zero",)),
    BadScene("nan", "scene.toml",
             edit("center = [0.0, 1.0, 0.0]", "center = [0.0, nan, 0.0]"),
             "objects[1].center", "nan", ("finite", "nan")),
    BadScene("inf", "scene.toml",
             edit("position = [0.0, 5.0, 5.0]", "position = [0.0, inf, 5.0]"),
             "lights[0].position", "inf", ("finite", "inf")),
    BadScene("minus-inf", "scene.toml",
             edit("position = [0.0, 1.0, 6.0]", "position = [0.0, 1.0, -inf]"),
             "camera.position", "-inf", ("finite", "-inf")),
    BadScene("inf-radius", "scene.toml", edit("radius = 1.0", "radius = inf"),
             "objects[1].radius", "radius = inf", ("finite", "inf")),
    BadScene("unknown-shape", "scene.toml", edit('type = "sphere"', 'type = "blob"'),
             "objects[1]", 'type = "blob"', ("unknown type", "blob")),
    BadScene("unknown-material", "scene.toml", edit(GLASS, 'material = "gold"'),
             "objects[1].material", 'material = "gold"', ("unknown material", "gold")),
    BadScene("unknown-preset", "scene.toml", edit(GLASS, 'material = { preset = "gold" }'),
             "objects[1].material", "preset", ("unknown material preset", "gold")),
    BadScene("unknown-preset-named", "scene.toml",
             edit(GLASS, 'material = "shiny"') + '\n[materials.shiny]\npreset = "gold"\n',
             "materials.shiny", "[materials.shiny]", ("unknown material preset", "gold")),
    BadScene("quoted-material-name", "scene.toml",
             edit(GLASS, 'material = "my glass"') + '\n[materials."my glass"]\nkt = 2.0\n',
             'materials."my glass".kt', "kt = 2.0", ("less than or equal to 1",)),
    BadScene("colour-out-of-range", "scene.toml",
             edit(GLASS, "material = { color = [1.5, 0.0, 0.0] }"),
             "objects[1].material.color", "1.5", ("colour", "outside 0..1", "1.5")),
    BadScene("colour-bad-hex", "scene.toml",
             edit('material = "matte"', 'material = { color = "#ff00zz" }'),
             "objects[0].material.color", "#ff00zz", ("hex", "#ff00zz")),
    BadScene("colour-not-hex", "scene.toml", 'background = "red"\n' + BASE,
             "background.color", 'background = "red"', ("'red'", "#rrggbb", "[r, g, b]")),
    BadScene("absurd-size", "scene.toml",
             edit("width = 32\nheight = 24", "width = 20000\nheight = 10000"),
             "render", "[render]", ("20000x10000", "megapixels")),
    BadScene("max-depth-over-64", "scene.toml", edit("height = 24", "height = 24\nmax_depth = 65"),
             "render.max_depth", "max_depth", ("64", "65")),
    BadScene("kt-over-1", "scene.toml",
             edit(GLASS, 'material = { preset = "glass", kt = 1.5 }'),
             "objects[1].material.kt", "kt = 1.5", ("less than or equal to 1", "1.5")),
    BadScene("missing-file", "nowhere.toml", None, None, None, ("no such file",)),
    BadScene("directory", "scene.toml", DIRECTORY, None, None, ("directory",)),
    BadScene("yaml", "scene.yaml", "render:\n  width: 32\n", None, None, ("format", ".yaml")),
    BadScene("not-utf8", "scene.toml", b"[render]\nwidth = 32\nheight = 24  # caf\xe9\n",
             None, 3, ("utf-8",)),
    BadScene("json-value", "scene.json",
             '{\n  "objects": [\n    {"type": "sphere",\n     "radius": -1.0}\n  ]\n}\n',
             "objects[0].radius", '"radius": -1.0', ("greater than 0",)),
]


def bad_scene_params(xfail_field: str) -> list:
    params = []
    for case in BAD_SCENES:
        reason = getattr(case, xfail_field)
        marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
        params.append(pytest.param(case, id=case.id, marks=marks))
    return params


@pytest.mark.parametrize("case", bad_scene_params("api_xfail"))
def test_bad_scene_is_one_line_error(case: BadScene, tmp_path: Path):
    path = case.write(tmp_path)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    err = info.value
    text = str(err)
    line = case.line_number()
    assert "\n" not in text
    assert err.file == str(path)
    assert err.line == line
    assert err.where == case.where
    head = f"{path}:{line}: " if line else f"{path}: "
    assert text.startswith(head), text
    if case.where:
        assert text.startswith(f"{head}{case.where}: "), text
    for word in case.words:
        assert word.lower() in text.lower(), (word, text)


def test_message_format_matches_the_documented_example(tmp_path: Path):
    path = tmp_path / "scene.toml"
    path.write_text(edit("radius = 1.0", "radius = -1.0"))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == (
        f"{path}:21: objects[1].radius: input should be greater than 0 (got -1.0)"
    )


def test_scene_error_is_a_whitted_error():
    assert issubclass(SceneError, whitted.WhittedError)


@pytest.mark.parametrize(
    "make",
    [
        pytest.param(lambda v: whitted.Sphere(radius=v), id="sphere-radius"),
        pytest.param(lambda v: whitted.Disk(radius=v), id="disk-radius"),
        pytest.param(lambda v: whitted.Cylinder(radius=v), id="cylinder-radius"),
        pytest.param(lambda v: whitted.Cone(radius=1.0, top_radius=v), id="cone-top-radius"),
        pytest.param(lambda v: whitted.DiskLight(center=[0, 0, 0], radius=v), id="disk-light"),
        pytest.param(lambda v: whitted.PointLight(position=[0, 0, 0], dist_scale=v),
                     id="dist-scale"),
        pytest.param(lambda v: whitted.Camera(ortho_height=v), id="ortho-height"),
    ],
)
@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan])
def test_python_api_rejects_non_finite_numbers(make, value: float):
    make(1.0)  # fine
    with pytest.raises(ValidationError):
        make(value)


# ----------------------------------------------------------------------------- valid scenes

GOOD = BASE + """
[background]
gradient = { top = "#336699", bottom = [0.9, 0.9, 0.9] }

[materials.tinted_glass]
preset = "glass"
color = "#e0f0ff"
attenuation = [0.1, 0.05, 0.02]

[[objects]]
type = "box"
min = [-3.0, 0.0, -3.0]
max = [-2.0, 1.0, -2.0]
material = "tinted_glass"
transform = { rotate = [0.0, 30.0, 0.0], scale = 0.5 }

[[objects]]
type = "triangle"
vertices = [[0.0, 0.0, -4.0], [1.0, 0.0, -4.0], [0.0, 1.0, -4.0]]
material = { preset = "plastic", kd = 0.4 }

[[lights]]
type = "ambient"
intensity = 0.2
"""


def test_toml_and_json_load_to_equal_scenes(tmp_path: Path):
    toml_path = tmp_path / "scene.toml"
    json_path = tmp_path / "scene.json"
    toml_path.write_text(GOOD)
    json_path.write_text(json.dumps(tomllib.loads(GOOD), indent=2))
    from_toml = load_scene(toml_path)
    from_json = load_scene(json_path)
    assert len(from_toml.objects) == 4 and len(from_toml.lights) == 2
    assert from_toml == from_json


def round_trip_sources() -> list:
    examples = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))
    assert examples, "no example scenes found"
    return [pytest.param(p, id=p.name) for p in examples] + [pytest.param(None, id="default")]


@pytest.mark.parametrize("suffix", [".toml", ".json"])
@pytest.mark.parametrize("source", round_trip_sources())
def test_save_then_load_round_trips(source: Path | None, suffix: str, tmp_path: Path):
    scene = whitted.default_scene() if source is None else load_scene(source)
    path = tmp_path / f"saved{suffix}"
    assert scene.save(path) == path
    again = load_scene(path)
    # saved elsewhere, relative model/texture names are re-pointed at the same files
    assert again == rebase_files(scene, tmp_path)
    for before, after in zip(scene.objects, again.objects, strict=True):
        if getattr(before, "file", None):
            assert again.resolve_path(after.file).resolve() == \
                scene.resolve_path(before.file).resolve()
    # and once more through the other format
    other = tmp_path / ("saved.json" if suffix == ".toml" else "saved.toml")
    again.save(other)
    assert load_scene(other) == again


def test_good_scene_round_trips(tmp_path: Path):
    path = tmp_path / "scene.toml"
    path.write_text(GOOD)
    scene = load_scene(path)
    for suffix in (".toml", ".json"):
        scene.save(tmp_path / f"saved{suffix}")
        assert load_scene(tmp_path / f"saved{suffix}") == scene


def test_save_refuses_unknown_format(tmp_path: Path):
    with pytest.raises(SceneError, match="yaml"):
        whitted.default_scene().save(tmp_path / "scene.yaml")
    assert not (tmp_path / "scene.yaml").exists()


def test_hex_colours_are_srgb_decoded(tmp_path: Path):
    path = tmp_path / "scene.toml"
    path.write_text(
        'background = "#808080"\n'
        + edit(GLASS, 'material = { color = "#ff0000", specular_color = "#FFFFFF" }')
    )
    scene = load_scene(path)
    for channel in scene.background.color:
        assert channel == pytest.approx(0.2158605, abs=1e-6)
    material = scene.material_of(1)
    assert material.color == (1.0, 0.0, 0.0)
    assert material.specular_color == (1.0, 1.0, 1.0)
    # lists are linear already: taken as they are
    assert whitted.Background(color=[0.5, 0.25, 0.0]).color == (0.5, 0.25, 0.0)


def test_presets_fill_fields_and_explicit_keys_override(tmp_path: Path):
    path = tmp_path / "scene.toml"
    path.write_text(
        edit(GLASS, 'material = { preset = "glass", kt = 0.5, color = [0.9, 1.0, 0.9] }')
        + '\n[materials.steel]\npreset = "chrome"\nkr = 0.2\n'
    )
    scene = load_scene(path)
    glass = whitted.PRESETS["glass"]
    inline = scene.material_of(1)
    assert inline.kt == 0.5 and inline.color == (0.9, 1.0, 0.9)  # overridden
    assert inline.ior == glass["ior"] and inline.fresnel is True  # from the preset
    assert inline.kd == glass["kd"] and inline.ks == glass["ks"]
    steel = scene.materials["steel"]
    assert steel.kr == 0.2
    assert steel.specular_color == whitted.PRESETS["chrome"]["specular_color"]
    # a bare preset name as an object's material
    assert scene.material_of(0) == whitted.Material(preset="matte")
    assert scene.material_of(0).kd == whitted.PRESETS["matte"]["kd"]
