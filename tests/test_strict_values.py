"""``--set`` and sweep values follow the scene file's rules: the same types, the same messages,
exit status 2 (a value the file refuses is never converted: ``photons = true`` is not 1 photon,
``width = "32"`` is not 32)."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cli_run import one_line_error, run_main
from whitted.animation.overrides import apply_overrides, parse_value
from whitted.errors import SceneError
from whitted.scene import load_scene
from whitted.scene.paths import get_value

BASE = "[render]\nwidth = 8\nheight = 6\n\n[materials.m]\ncolor = [0.5, 0.5, 0.5]\n"
# (path, the TOML table that holds its last key)
PATHS = {
    "render.caustics.photons": "render.caustics",
    "render.caustics.radius": "render.caustics",
    "render.width": "render",
    "render.seed": "render",
    "render.tonemap": "render",
    "camera.aperture": "camera",
    "camera.position": "camera",
    "materials.m.kt": "materials.m",
    "materials.m.color": "materials.m",
}


def _file_outcome(tmp_path, path: str, literal: str):
    """(value, None) when a scene file with ``path = literal`` loads, else (None, its
    message without the file and line)."""
    table, key = PATHS[path], path.rsplit(".", 1)[1]
    tables = {"render": {"width": "8", "height": "6"}, "materials.m": {"color": "[0.5, 0.5, 0.5]"}}
    tables.setdefault(table, {})[key] = literal
    text = "".join(f"[{name}]\n" + "".join(f"{k} = {v}\n" for k, v in rows.items()) + "\n"
                   for name, rows in tables.items())
    file = tmp_path / "s.toml"
    file.write_text(text, encoding="utf-8")
    try:
        scene = load_scene(file)
    except SceneError as exc:
        return None, exc.message if exc.where is None else f"{exc.where}: {exc.message}"
    return get_value(scene, path), None


def _set_outcome(tmp_path, path: str, literal: str):
    base = tmp_path / "base.toml"
    base.write_text(BASE, encoding="utf-8")
    scene = load_scene(base)
    try:
        new = apply_overrides(scene, [(path, literal)])
    except SceneError as exc:
        message = str(exc)
        assert message.startswith("--set: "), message
        return None, message.removeprefix("--set: ")
    return get_value(new, path), None


CASES = [
    ("render.caustics.photons", "true", "render.caustics.photons: expected an integer (got True)"),
    ("render.caustics.photons", '"100"', "expected an integer (got '100')"),
    ("render.caustics.photons", "1e4", "expected an integer (got 10000.0)"),
    ("render.caustics.radius", "true", "render.caustics.radius: expected a number (got True)"),
    ("camera.aperture", '"0.1"', "camera.aperture: expected a number (got '0.1')"),
    ("render.width", '"32"', "render.width: expected an integer (got '32')"),
    ("materials.m.kt", "true", "materials.m.kt: expected a number (got True)"),
]


@pytest.mark.parametrize(("path", "literal", "message"), CASES)
def test_a_set_value_is_refused_as_the_file_refuses_it(tmp_path, path, literal, message):
    on_file = _file_outcome(tmp_path, path, literal)
    on_set = _set_outcome(tmp_path, path, literal)
    assert on_file[0] is None and on_set[0] is None
    assert message in on_set[1]
    assert on_set[1] == on_file[1]


def test_whole_tables_are_strict_too_and_an_unknown_key_is_named(tmp_path):
    base = tmp_path / "base.toml"
    base.write_text(BASE, encoding="utf-8")
    scene = load_scene(base)
    with pytest.raises(SceneError, match=r"^--set: render\.caustics\.bogus: unknown key "
                                         r"\(known: photons, passes, radius, alpha\)$"):
        apply_overrides(scene, [("render.caustics", "{bogus=1}")])
    with pytest.raises(SceneError, match=r"render\.caustics\.photons: expected an integer"):
        apply_overrides(scene, [("render.caustics", "{photons=true}")])
    with pytest.raises(SceneError, match=r"^--set: objects\[0\]\.radus: unknown key \(did you "
                                         r"mean 'radius'\?\)$"):
        apply_overrides(scene.model_copy(update={"objects": [scene.objects[0]]})
                        if scene.objects else _with_sphere(scene),
                        [("objects[0]", '{type="sphere", radus=1}')])
    # what the file takes, --set takes: a whole number for a real, a list for a vector
    new = apply_overrides(scene, [("camera.aperture", "1"), ("camera.position", "[1, 2, 3]"),
                                  ("render.caustics", "{photons=100}")])
    assert new.camera.aperture == 1.0 and new.camera.position == (1.0, 2.0, 3.0)
    assert new.render.caustics.photons == 100


def _with_sphere(scene):
    from whitted.scene.shapes import Sphere

    return scene.model_copy(update={"objects": [Sphere(center=(0, 0, 0), radius=1.0)]})


def test_render_set_true_photons_exits_2_with_one_line(tmp_path):
    one_line_error(run_main("render", "-q", "-W", "8", "-H", "6", "-o", "x.png", "--set",
                            "render.caustics.photons=true", cwd=tmp_path),
                   "--set: render.caustics.photons: expected an integer (got True)")
    assert not (tmp_path / "x.png").exists()


def test_a_sweep_value_the_file_refuses_is_refused_before_any_cell(tmp_path):
    one_line_error(run_main("sweep", "-o", "sheet.png", "-W", "8", "-H", "6", "--set",
                            "render.caustics.photons=100,true", cwd=tmp_path),
                   "render.caustics.photons: expected an integer (got True)")
    assert not (tmp_path / "sheet.png").exists()
    assert not (tmp_path / "sheet_cells").exists()


def _toml_literal(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):  # a TOML basic string: no raw DEL, no surrogate pairs
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    return "[" + ", ".join(_toml_literal(v) for v in value) + "]"


scalars = st.one_of(st.booleans(), st.integers(-10**20, 10**20),
                    st.floats(allow_nan=True, allow_infinity=True),
                    st.text(max_size=6), st.sampled_from(["aces", "clamp", "#336699"]))
values = st.one_of(scalars, st.lists(st.one_of(st.booleans(), st.integers(-5, 5),
                                               st.floats(-2, 2), st.text(max_size=2)),
                                     max_size=4))


@given(path=st.sampled_from(sorted(PATHS)), value=values)
def test_fuzz_set_follows_the_file(tmp_path_factory, path, value):
    """Whatever the value, --set takes it exactly when a scene file takes it (to the same
    value), and refuses it with the file's own message."""
    tmp = tmp_path_factory.mktemp("fuzz")
    literal = _toml_literal(value)
    assert parse_value(literal) == value or value != value or isinstance(value, list)
    assert _set_outcome(tmp, path, literal) == _file_outcome(tmp, path, literal)
