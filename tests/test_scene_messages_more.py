"""scene/messages.py's helpers where they have nothing to say: no key, an index, a place the
model does not know, a table of more than twelve keys without a close match (no list too
long for one line); and the line finders when a key cannot be placed."""

from __future__ import annotations

from whitted.scene.messages import json_line, known_keys_hint, toml_line
from whitted.scene.scene import Scene

DATA = {"objects": [{"type": "sphere", "radus": 1}], "render": {"zzz": 1}, "camera": {"q": 1}}


def test_key_hints():
    assert known_keys_hint([], DATA, Scene) == ""
    assert known_keys_hint(["objects", 0], DATA, Scene) == ""  # an index, not a key
    assert known_keys_hint(["objects", 0, "radus"], DATA, Scene) == " (did you mean 'radius'?)"
    assert known_keys_hint(["nothing", "x"], DATA, Scene) == ""  # no such table
    assert known_keys_hint(["render", "zzz"], DATA, Scene) == ""  # over 12 keys, none close
    assert known_keys_hint(["camera", "q"], DATA, Scene) == (
        " (known: position, look_at, up, rotate, axis_angle, fov, fov_axis, projection, "
        "ortho_height, aperture, focal_distance, focal_point)")


def test_lines_of_keys():
    assert toml_line("a = 1\n", []) is None
    assert toml_line("a = 1\n", ["b"]) is None
    assert toml_line("[camera]\nfov = 3\n", ["camera", "fov"]) == 2
    assert toml_line("x = 1\n[[objects]]\nr = 1\n", ["x"]) == 1  # before the first header
    assert json_line('{"a": 1}', ["b"], {"a": 1}) is None
    assert json_line("[1]", [0], [1]) is None  # no key names a line
    assert json_line('{"a": {\n"b": 2}}', ["a", "b"], {"a": {"b": 2}}) == 2
