"""--set values and sweeps on the cases the command tests do not reach: zero steps written as
whole or decimal numbers, lists over the limit, tracks on an overridden value dropped and
tracks left naming what an override removed, an axis without values, sliced cells, labels of
list values, and a contact sheet of no images."""

from __future__ import annotations

import pytest

import whitted
from whitted.animation.overrides import MAX_VALUES, apply_overrides, parse_values
from whitted.animation.sweep import contact_sheet, format_value, short_name, sweep_cells
from whitted.errors import SceneError


def _film() -> whitted.Scene:
    return whitted.Scene(objects=[whitted.Sphere(radius=1, name="ball")], animation={
        "frames": 10, "tracks": [{"path": "objects[ball].radius", "keys": [[0, 1], [9, 2]]},
                                 {"path": "camera.fov", "keys": [[0, 40]]}]})


@pytest.mark.parametrize("text", ["0:1:0", "1:2:0.0"])
def test_a_zero_step(text):
    with pytest.raises(SceneError) as info:
        parse_values(text)
    assert str(info.value) == f"--set: range '{text}': the step must not be 0"


def test_a_list_over_the_limit():
    with pytest.raises(SceneError) as info:
        parse_values(",".join(["1"] * (MAX_VALUES + 1)))
    assert str(info.value).endswith(f" has {MAX_VALUES + 1} values (at most {MAX_VALUES})")
    assert len(parse_values(",".join(["1"] * MAX_VALUES))) == MAX_VALUES


def test_tracks_on_an_overridden_value_are_dropped():
    scene = apply_overrides(_film(), [("objects[ball].radius", 3)])
    assert scene.objects[0].radius == 3.0
    assert [t.path for t in scene.animation.tracks] == ["camera.fov"]


def test_a_track_left_naming_what_an_override_removed():
    with pytest.raises(SceneError) as info:
        apply_overrides(_film(), [("objects", [])])
    assert str(info.value) == ("after --set: animation.tracks[0].path: objects[ball]: "
                               "unknown name 'ball'")


def test_sweep_axes_cells_and_labels():
    with pytest.raises(SceneError) as info:
        sweep_cells(_film(), [("camera.fov", [])])
    assert str(info.value) == "--set: an axis of the sweep has no values"
    cells = sweep_cells(_film(), [("camera.fov", [30, 40, 50]),
                                  ("background.color", [[0, 0, 0], [1, 0.5, 0]])])
    assert len(cells) == 6
    assert [c.label for c in cells[4:]] == ["fov = 40, color = [1, 0.5, 0]",
                                            "fov = 50, color = [1, 0.5, 0]"]
    assert [c.index for c in cells[::-2]] == [5, 3, 1]
    assert format_value([1.5, "a", [2, 0.25]]) == "[1.5, a, [2, 0.25]]"
    assert short_name("objects[[bad") == "objects[[bad"  # no path: itself


def test_a_contact_sheet_of_no_images():
    with pytest.raises(ValueError, match="^no images$"):
        contact_sheet([], [], 2)
