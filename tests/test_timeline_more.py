"""scene/timeline.py: file patterns of mesh sequences that cannot name a frame (each refused
in one line), and a track's value at a frame, for a number and for a whole table."""

from __future__ import annotations

import pytest

import whitted
from whitted.scene.timeline import sequence_file, track_value


@pytest.mark.parametrize(("pattern", "problem"), [
    ("ice_{frame:04d.ply", "unmatched '{' in format spec"),
    ("ice_{name}.ply", "only {frame} may be used (for example ice_{frame:04d}.ply)"),
    ("ice_{frame:c}.ply", "{frame:c} is not a number format (use for example {frame:04d})"),
    ("a_{frame:04d}}.ply", "Single '}' encountered in format string"),
    ("a_{frame:.2d}.ply", "Precision not allowed in integer format specifier"),
])
def test_patterns_that_cannot_name_a_frame(pattern, problem):
    with pytest.raises(ValueError) as info:
        sequence_file(pattern, 7)
    assert str(info.value) == f"file pattern {pattern!r}: {problem}"


def test_patterns_that_can():
    assert sequence_file("a_{frame:,d}_{frame:x}.ply", 1234) == "a_1,234_4d2.ply"
    assert sequence_file("plain.ply", 3) == "plain.ply"


def test_a_tracks_value_for_a_number_and_a_whole_table():
    scene = whitted.Scene(objects=[whitted.Sphere(radius=1, name="b")], animation={
        "frames": 10, "tracks": [
            {"path": "objects[b].radius", "keys": [[0, 1], [9, 2]]},
            {"path": "camera", "keys": [[0, {"fov": 30}], [9, {"fov": 60}]]}]})
    assert track_value(scene, 0, 4.5) == 1.5
    assert track_value(scene, scene.animation.tracks[0], 9) == 2.0
    camera = track_value(scene, 1, 3)  # the whole table, every field: fov 30 + 30·3/9
    assert camera["fov"] == pytest.approx(40.0) and camera["position"] == [0.0, 0.0, 5.0]
    assert camera["projection"] == "perspective" and camera["look_at"] is None
