"""Animated scenes: paths, interpolation, rotations, validation, at_frame, --set, frames."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from whitted.animation import (
    Animation,
    PathError,
    Track,
    apply_overrides,
    frame_seed,
    get_value,
    parse_path,
    parse_values,
    set_value,
)
from whitted.animation.frames import read_frame_digest, render_frame
from whitted.errors import SceneError
from whitted.scene.interpolate import (
    euler_to_quaternion,
    interpolate_rotation,
    interpolate_scalar,
    quaternion_matrix,
)
from whitted.scene.types import Transform

SCENE = """\
[render]
width = 24
height = 16

[camera]
position = [0, 1, 6]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[lights]]
name = "soft"
type = "disk"
center = [-2, 4, 2]
radius = 0.8
samples = 4

[materials.glass]
preset = "glass"

[[objects]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "glass"

[[objects]]
name = "cube"
type = "box"
min = [1, 0, -1]
max = [2, 1, 0]
material = "glass"

[[objects]]
type = "plane"

[animation]
frames = 10
fps = 12

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 1, 6]], [9, [6, 1, 0]]]
interpolation = "smooth"

[[animation.tracks]]
path = "objects[ball].material.kt"
keys = [[0, 1.0], [9, 0.0]]
"""


@pytest.fixture
def scene_file(tmp_path: Path) -> Path:
    path = tmp_path / "anim.toml"
    path.write_text(SCENE)
    return path


def _with(tmp_path: Path, old: str, new: str) -> Path:
    assert old in SCENE
    path = tmp_path / "bad.toml"
    path.write_text(SCENE.replace(old, new))
    return path


# ------------------------------------------------------------------------------ interpolation


def test_step_linear_smooth_values_at_and_between_keys():
    t, v = [0.0, 4.0, 10.0], [1.0, 3.0, -3.0]
    for mode in ("step", "linear", "smooth", "spline"):  # every mode passes through its keys
        assert [interpolate_scalar(t, v, k, mode) for k in t] == v
        assert interpolate_scalar(t, v, -5, mode) == 1.0  # held before the first key
        assert interpolate_scalar(t, v, 99, mode) == -3.0  # and after the last
    assert interpolate_scalar(t, v, 3.9, "step") == 1.0
    assert interpolate_scalar(t, v, 7.0, "step") == 3.0
    assert interpolate_scalar(t, v, 1.0, "linear") == pytest.approx(1.5)
    assert interpolate_scalar(t, v, 7.0, "linear") == pytest.approx(0.0)
    # smooth: 3s^2 - 2s^3 of the way; at s = 1/4: 5/32
    assert interpolate_scalar(t, v, 1.0, "smooth") == pytest.approx(1 + 2 * 5 / 32)
    assert interpolate_scalar(t, v, 2.0, "smooth") == pytest.approx(2.0)


def test_smooth_has_zero_slope_at_every_key():
    t, v = [0.0, 4.0, 10.0], [1.0, 3.0, -3.0]
    h = 1e-4
    for key in (4.0,):
        left = (interpolate_scalar(t, v, key, "smooth")
                - interpolate_scalar(t, v, key - h, "smooth")) / h
        right = (interpolate_scalar(t, v, key + h, "smooth")
                 - interpolate_scalar(t, v, key, "smooth")) / h
        assert abs(left) < 1e-3 and abs(right) < 1e-3
    # while linear has slope 0.5 then -1 there
    assert (interpolate_scalar(t, v, 4 + h, "linear") - 3.0) / h == pytest.approx(-1.0)


def test_spline_is_catmull_rom_with_continuous_slope():
    t, v = [0.0, 1.0, 2.0], [0.0, 1.0, 0.0]
    # slopes 1, 0, -1 at the keys; at s = 1/2: h10 = 1/8, h01 = 1/2, h11 = -1/8
    assert interpolate_scalar(t, v, 0.5, "spline") == pytest.approx(0.125 + 0.5)
    assert interpolate_scalar(t, v, 1.5, "spline") == pytest.approx(0.5 + 0.125)
    h = 1e-5
    left = (1.0 - interpolate_scalar(t, v, 1 - h, "spline")) / h
    right = (interpolate_scalar(t, v, 1 + h, "spline") - 1.0) / h
    assert left == pytest.approx(0.0, abs=1e-4) and right == pytest.approx(0.0, abs=1e-4)
    # two keys: a straight line
    assert interpolate_scalar([0, 10], [0, 5], 3, "spline") == pytest.approx(1.5)


def _matrix(angles) -> np.ndarray:
    return Transform(rotate=tuple(angles)).matrix()[:3, :3]


def _axis_angle_matrix(axis, degrees) -> np.ndarray:
    from whitted.scene.types import AxisAngle

    return Transform(axis_angle=AxisAngle(axis=axis, angle=degrees)).matrix()[:3, :3]


def test_euler_quaternion_round_trip_matches_transform_matrix():
    rng = np.random.default_rng(3)
    for angles in rng.uniform(-180, 180, (50, 3)):
        q = euler_to_quaternion(angles)
        np.testing.assert_allclose(quaternion_matrix(q), _matrix(angles), atol=1e-12)
        back = interpolate_rotation([0, 1], [angles, angles], 0.5, "linear")
        np.testing.assert_allclose(_matrix(back), _matrix(angles), atol=1e-9)


@pytest.mark.parametrize("mode", ["linear", "smooth", "spline"])
def test_slerp_through_180_degrees_turns_about_one_axis_without_a_flip(mode):
    times, keys = [0, 10], [(0, 0, 0), (0, 180, 0)]
    frames = [interpolate_rotation(times, keys, k, mode) for k in range(11)]
    previous = None
    for k, angles in enumerate(frames):
        m = _matrix(angles)
        # a rotation about y only: y stays fixed, and the angle grows monotonically
        np.testing.assert_allclose(m @ [0, 1, 0], [0, 1, 0], atol=1e-9)
        turned = math.degrees(math.atan2(m[0, 2], m[0, 0]) % (2 * math.pi))
        if k == 10:
            turned = 180.0 if abs(turned) < 1e-6 else turned
        if previous is not None:
            assert turned > previous  # never back, never a jump to the other side
        previous = turned
    assert frames[5] == (0.0, 90.0, 0.0)  # read back near the keyed angles
    assert interpolate_rotation(times, keys, 5, "linear") == (0.0, 90.0, 0.0)


def test_rotation_goes_the_short_way_round():
    # 350 -> 10 degrees about z is a turn of 20 degrees through 0, not 340 back
    times, keys = [0, 4], [(0, 0, 350), (0, 0, 10)]
    for k in range(5):
        angles = interpolate_rotation(times, keys, k, "linear")
        np.testing.assert_allclose(_matrix(angles), _axis_angle_matrix((0, 0, 1), -10 + 5 * k),
                                   atol=1e-9)
    # and about a slanted axis, slerp keeps the axis: halfway is half the angle
    a = (30, 40, 50)
    q = euler_to_quaternion(a)
    axis = q[1:] / np.linalg.norm(q[1:])
    angle = math.degrees(2 * math.acos(q[0]))
    mid = interpolate_rotation([0, 2], [(0, 0, 0), a], 1, "linear")
    np.testing.assert_allclose(_matrix(mid), _axis_angle_matrix(tuple(axis), angle / 2),
                               atol=1e-9)


# ------------------------------------------------------------------------------ paths, --set


def test_paths_read_and_replace_values_by_name_and_index(scene_file):
    scene = whitted.load_scene(scene_file)
    assert parse_path('objects["ball"].material.kt') == parse_path("objects[ball].material.kt")
    assert get_value(scene, "objects[ball].material.kt") == pytest.approx(0.95)
    assert get_value(scene, "lights[soft].radius") == 0.8
    new = set_value(scene, "objects[ball].material.kt", 0.25)
    assert new.objects[0].material.kt == 0.25
    assert new.objects[0].material.ior == 1.5  # the rest of the named material is kept
    assert new.objects[1].material == "glass"  # the other user of "glass" is untouched
    assert scene.objects[0].material == "glass"  # and the original scene too
    moved = set_value(scene, "objects[2].transform.rotate", [0, 45, 0])
    assert moved.objects[2].transform.rotate == (0.0, 45.0, 0.0)
    assert set_value(scene, "background", "#ff0000").background.color == (1.0, 0.0, 0.0)
    assert set_value(scene, "materials.glass.kt", 0.5).materials["glass"].kt == 0.5


@pytest.mark.parametrize(("path", "value", "message"), [
    ("camera.positon", [0, 0, 1], "camera.positon: unknown key 'positon' (did you mean "
                                   "'position'?)"),
    ("objects[bal].radius", 1, "objects[bal]: unknown name 'bal' (did you mean 'ball'?)"),
    ("objects[7].radius", 1, "objects[7]: index 7 is out of range (there are 3)"),
    ("objects[ball].material.kt", 2, "objects[ball].material.kt: input should be less than "
                                     "or equal to 1"),
    ("camera.position", 3, "camera.position: expected a list of 3 numbers"),
    ("camera.position.x", 3, "camera.position.x: camera.position is a value (a list of 3), "
                             "it has no parts"),
    ("camera[0]", 3, "camera[0]: camera is not a list"),
    ("objects.ball", 3, "objects is a list: pick an item with [index] or [name]"),
])
def test_bad_paths_and_values_are_one_line_errors(scene_file, path, value, message):
    scene = whitted.load_scene(scene_file)
    with pytest.raises(PathError) as info:
        set_value(scene, path, value)
    assert str(info.value).startswith(message)
    assert "\n" not in str(info.value)


def test_set_overrides_values_and_the_tracks_of_the_same_value(scene_file):
    scene = whitted.load_scene(scene_file)
    new = apply_overrides(scene, [("render.max_depth", "3"),
                                  ("objects[ball].material.kt", "0.5"),
                                  ("render.tonemap", "aces")])
    assert new.render.max_depth == 3 and new.render.tonemap == "aces"
    assert [t.path for t in new.animation.tracks] == ["camera.position"]  # kt track dropped
    assert new.at_frame(9).objects[0].material.kt == 0.5
    with pytest.raises(SceneError, match=r"^--set: objects\[ball\]\.material\.kt: input "):
        apply_overrides(scene, [("objects[ball].material.kt", "7")])


def test_sweep_values():
    assert parse_values("1:0:-0.2") == [1.0, 0.8, 0.6, 0.4, 0.2, 0.0]
    assert parse_values("0:1:0.25") == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert parse_values("1:5:2") == [1, 3, 5]
    assert parse_values("[0, 1, 9],[0, 2, 9]") == [[0, 1, 9], [0, 2, 9]]
    assert parse_values("glass,mirror") == ["glass", "mirror"]
    with pytest.raises(SceneError, match="goes away"):
        parse_values("0:1:-0.5")


# ------------------------------------------------------------------------------ validation


@pytest.mark.parametrize(("old", "new", "line", "message"), [
    ("path = \"objects[ball].material.kt\"", "path = \"objects[bal].material.kt\"", 50,
     "animation.tracks[1].path: objects[bal]: unknown name 'bal' (did you mean 'ball'?)"),
    ("[9, 0.0]]", "[12, 0.0]]", 51,
     "animation.tracks[1].keys[1]: frame 12 is outside 0..9 (frames = 10)"),
    ("[9, 0.0]]", "[9, [0.0, 1.0]]]", 51,
     "animation.tracks[1].keys[1]: objects[ball].material.kt: expected a number"),
    ("[9, [6, 1, 0]]]", "[9, [6, 1]]]", 46,
     "animation.tracks[0].keys[1]: camera.position: expected a list of 3 numbers"),
    ("[9, 0.0]]", "[4, 1.0], [8, 0.2]]\ninterpolation = \"spline\"", None,
     "animation.tracks[1]: at frame 1 the spline between keys gives objects[ball].material.kt:"
     " input should be less than or equal to 1"),
    ("[9, 0.0]]", "[0, 0.0]]", 51, "animation.tracks[1].keys: two keys at frame 0"),
    ("frames = 10", "frames = 0", 41, "animation.frames: input should be greater than"),
])
def test_track_errors_name_file_line_and_track(tmp_path, old, new, line, message):
    path = _with(tmp_path, old, new)
    with pytest.raises(SceneError) as info:
        whitted.load_scene(path)
    text = str(info.value)
    head = f"{path}:{line}: " if line else f"{path}:"
    assert text.startswith(head), text
    assert message in text, text
    assert "\n" not in text


def test_cli_reports_a_bad_track_in_one_line_with_status_2(tmp_path):
    path = _with(tmp_path, "camera.position", "camera.positon")
    result = subprocess.run([sys.executable, "-m", "whitted", "render", str(path), "-o",
                             str(tmp_path / "x.png")], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"error: {path}:45: animation.tracks[0].path: camera.positon: unknown key 'positon' "
        "(did you mean 'position'?)"]


# ------------------------------------------------------------------------------ at_frame


def test_at_frame_is_pure_and_gives_a_plain_still(scene_file):
    scene = whitted.load_scene(scene_file)
    before = scene.model_dump()
    still = scene.at_frame(3)
    assert scene.model_dump() == before  # the animated scene is unchanged
    assert still.animation is None and still.frame_count == 1 and scene.frame_count == 10
    # smooth camera: 3s^2 - 2s^3 at s = 1/3 is 7/27
    np.testing.assert_allclose(still.camera.position, [6 * 7 / 27, 1, 6 - 6 * 7 / 27])
    assert still.objects[0].material.kt == pytest.approx(1 - 3 / 9)
    assert still.objects[1].material == "glass"
    assert still.base_dir == scene.base_dir
    assert still.render.seed == frame_seed(0, 3) != 0
    assert scene.at_frame(0).render.seed == 0  # frame 0 keeps the scene's seed
    with pytest.raises(SceneError, match=r"frame 10 is outside 0\.\.9"):
        scene.at_frame(10)


def test_tracks_from_python(scene_file):
    scene = whitted.load_scene(scene_file).model_copy(update={"animation": None})
    anim = Animation(frames=5).track("lights[0].intensity", {0: 1.0, 4: 0.0}, "linear")
    anim = anim.track("objects[2].transform.rotate", [(0, [0, 0, 0]), (4, [0, 90, 0])])
    animated = scene.with_animation(anim.frames, tracks=anim.tracks)
    assert animated.at_frame(1).lights[0].intensity == pytest.approx(0.75)
    assert animated.at_frame(2).objects[2].transform.rotate == (0.0, 45.0, 0.0)
    with pytest.raises(ValueError, match=r"tracks\[0\]\.path: camera\.fob: unknown key"):
        scene.with_animation(3, tracks=[Track("camera.fob", {0: 30})])
    saved = animated.save(scene_file.with_name("saved.toml"))
    assert whitted.load_scene(saved).animation == animated.animation
    assert "    [4, [0, 90, 0]],\n" in saved.read_text()  # one key per line


def test_mesh_sequence_names_each_frames_file(tmp_path):
    for k in range(3):
        (tmp_path / f"tri_{k:03d}.obj").write_text(
            f"v 0 0 0\nv 1 0 0\nv 0 {1 + k} 0\nf 1 2 3\n")
    text = SCENE.replace('[[objects]]\ntype = "plane"',
                         '[[objects]]\ntype = "mesh"\nfile = "tri_{frame:03d}.obj"')
    text = text.replace("frames = 10", "frames = 3").replace("[9, ", "[2, ")
    path = tmp_path / "seq.toml"
    path.write_text(text)
    scene = whitted.load_scene(path)
    assert scene.at_frame(2).objects[2].file == "tri_002.obj"
    compiled = __import__("whitted.compile.scene", fromlist=["x"]).compile_scene(
        scene.at_frame(2))
    assert compiled.bounds_max[1] == pytest.approx(3.0)  # frame 2's triangle is 3 high
    path.write_text(text.replace("frames = 3", "frames = 4").replace("[2, ", "[3, "))
    with pytest.raises(SceneError) as info:
        whitted.load_scene(path)
    assert "objects[2].file: no such file: 'tri_003.obj'" in str(info.value)


# ------------------------------------------------------------------------------ frames


def test_frame_alone_equals_frame_of_the_film_at_any_thread_count(scene_file, tmp_path):
    scene = whitted.load_scene(scene_file)
    one = render_frame(scene, 4, tmp_path / "a.png", threads=1)
    two = render_frame(scene, 4, tmp_path / "b.png", threads=2)
    assert one.rendered and two.rendered and one.digest == two.digest
    a = whitted.Image.load(tmp_path / "a.png").to_srgb8()
    b = whitted.Image.load(tmp_path / "b.png").to_srgb8()
    still = whitted.render(scene.at_frame(4), threads=2).to_srgb8()
    assert np.array_equal(a, b) and np.array_equal(a, still)
    # the disk light's samples change with the frame's seed: frame 4 with frame 5's seed
    # differs from frame 4
    other = whitted.render(scene.at_frame(4), seed=frame_seed(0, 5), threads=1).to_srgb8()
    assert not np.array_equal(other, a)


def test_a_current_frame_is_not_rendered_again(scene_file, tmp_path):
    scene = whitted.load_scene(scene_file)
    first = render_frame(scene, 2, tmp_path / "f.png")
    again = render_frame(scene, 2, tmp_path / "f.png")
    assert first.rendered and not again.rendered
    assert read_frame_digest(tmp_path / "f.png") == first.digest
    changed = render_frame(scene, 2, tmp_path / "f.png", samples=2)  # other settings
    assert changed.rendered and changed.digest != first.digest


def test_cyclic_animation_runs_from_the_last_key_back_to_the_first(scene_file):
    scene = whitted.load_scene(scene_file).model_copy(update={"animation": None})
    tracks = [Track("lights[0].intensity", {0: 0.0, 6: 0.6})]
    plain = scene.with_animation(12, tracks=tracks)
    loop = plain.model_copy(update={"animation": plain.animation.model_copy(
        update={"cyclic": True})})
    assert plain.at_frame(9).lights[0].intensity == 0.6  # held after the last key
    assert loop.at_frame(9).lights[0].intensity == pytest.approx(0.3)  # on its way back
    assert loop.at_frame(3).lights[0].intensity == pytest.approx(0.3)


def test_cyclic_spline_orbit_is_symmetric_round_the_loop():
    scene = whitted.load_scene(Path(__file__).parents[1] / "examples" / "camera_orbit.toml")
    assert scene.animation.cyclic
    radius = [math.hypot(p[0], p[2]) for p in
              (scene.at_frame(k).camera.position for k in range(48))]
    assert max(abs(r - 9) for r in radius) < 0.02  # keys every 30 degrees: nearly a circle
    a, b = scene.at_frame(3).camera.position, scene.at_frame(45).camera.position
    assert a[0] == pytest.approx(-b[0]) and a[2] == pytest.approx(b[2])  # mirror images
    assert radius[2] == pytest.approx(radius[46]) == pytest.approx(radius[14])


# ------------------------------------------------------------------------------ properties

_keys = st.lists(st.tuples(st.integers(0, 60), st.floats(-100, 100)), min_size=1, max_size=8,
                 unique_by=lambda k: k[0]).map(sorted)


@settings(max_examples=60, deadline=None)
@given(_keys, st.floats(0, 60))
def test_every_mode_passes_through_its_keys_and_linear_smooth_stay_between(keys, t):
    times = [float(k[0]) for k in keys]
    values = [k[1] for k in keys]
    for mode in ("step", "linear", "smooth", "spline"):
        for k, v in zip(times, values, strict=True):
            assert interpolate_scalar(times, values, k, mode) == pytest.approx(v, abs=1e-9)
    for mode in ("linear", "smooth"):
        x = interpolate_scalar(times, values, t, mode)
        assert min(values) - 1e-9 <= x <= max(values) + 1e-9


def _angle_between(a, b) -> float:
    r = _matrix(a).T @ _matrix(b)
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2))))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-179, 179), min_size=3, max_size=3),
       st.lists(st.floats(-179, 179), min_size=3, max_size=3),
       st.sampled_from(["linear", "smooth"]))
def test_rotations_turn_steadily_the_short_way(a, b, mode):
    total = _angle_between(a, b)  # the short way, 0..180 degrees
    steps = 8
    frames = [interpolate_rotation([0, steps], [a, b], k, mode) for k in range(steps + 1)]
    np.testing.assert_allclose(_matrix(frames[-1]), _matrix(b), atol=1e-9)
    turned = sum(_angle_between(frames[k], frames[k + 1]) for k in range(steps))
    # no detour, no flip (either would add degrees; arccos near 1 costs ~1e-5 of rounding)
    assert turned == pytest.approx(total, abs=1e-4)


_names = st.text(st.characters(whitelist_categories=("L", "N"), whitelist_characters=" _-"),
                 min_size=1, max_size=12).filter(lambda s: s.strip() == s and not s.isdigit())


@settings(max_examples=60, deadline=None)
@given(_names, st.integers(0, 999), st.sampled_from(["kt", "color", "rotate"]))
def test_paths_read_back_as_written(name, index, leaf):
    from whitted.scene.paths import format_path

    for text in (f"objects[{name}].material.{leaf}", f"lights[{index}].{leaf}"):
        steps = parse_path(text)
        assert format_path(steps) == text and parse_path(format_path(steps)) == steps
