"""A quick look at a model (``whitted render model.obj``) and the framing behind it
(``whitted.framed``): every point of the objects inside the picture with the margin, the model
centred, a shadow on the ground, a turntable around it, and one clear line for a model with
nothing to show."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import whitted
from cli_run import run_main
from whitted.errors import ArgumentError, SceneError
from whitted.studio.bounds import world_points
from whitted.studio.framing import AZIMUTH, ELEVATION, MARGIN, view_direction

W, H = 64, 48

PYRAMID = """v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v 0 1.5 0
f 1 2 5
f 2 3 5
f 3 4 5
f 4 1 5
f 1 4 3 2
"""


def project(scene: whitted.Scene, points: np.ndarray) -> np.ndarray:
    """Points in the picture as fractions of its half width and height from the centre."""
    cam = scene.camera
    pos, target = np.asarray(cam.position), np.asarray(cam.look_at)
    fwd = (target - pos) / np.linalg.norm(target - pos)
    right = np.cross(fwd, cam.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    tx, ty = cam.half_extents(scene.render.width, scene.render.height)
    rel = points - pos
    depth = rel @ fwd
    assert np.all(depth > 0)
    return np.column_stack([(rel @ right) / depth / tx, (rel @ up) / depth / ty])


@pytest.mark.parametrize("shape", [
    whitted.Sphere(center=[3, 1, -2], radius=0.5),
    whitted.Box(min=[-4, 0, -1], max=[4, 0.2, 1]),  # long and flat
    whitted.Cylinder(base=[0, 0, 0], top=[0, 10, 0], radius=0.3),  # tall and thin
])
def test_framed_puts_every_point_inside_with_the_margin(shape):
    scene = whitted.Scene(render=whitted.RenderSettings(width=W, height=H), objects=[
        shape, whitted.Plane()])  # the plane is unbounded: left out of the framing
    framed = whitted.framed(scene)
    xy = project(framed, world_points(shape))
    assert np.max(np.abs(xy)) == pytest.approx(1 - MARGIN, abs=1e-9)  # as near as it can be
    middle = (xy.max(axis=0) + xy.min(axis=0)) / 2
    assert np.all(np.abs(middle) < 0.02)  # in the middle of the picture
    cam = framed.camera
    back = np.asarray(cam.position) - np.asarray(cam.look_at)
    back /= np.linalg.norm(back)
    assert back == pytest.approx(view_direction(AZIMUTH, ELEVATION))  # three-quarter, above
    assert math.degrees(math.asin(back[1])) == pytest.approx(ELEVATION)
    assert framed.objects == scene.objects and framed.lights == scene.lights


def test_framed_takes_a_target_and_refuses_nonsense():
    a = whitted.Sphere(name="a", radius=1)
    b = whitted.Sphere(name="b", center=[50, 0, 0], radius=1)
    scene = whitted.Scene(objects=[a, b])
    one = whitted.framed(scene, "a")
    assert one.camera.look_at == pytest.approx((0, 0, 0), abs=0.5)  # aimed at a's middle
    assert whitted.framed(scene, [1]).camera.look_at == pytest.approx((50, 0, 0), abs=0.5)
    assert whitted.framed(scene, b).camera.look_at == pytest.approx((50, 0, 0), abs=0.5)
    with pytest.raises(ArgumentError, match="no object named 'c'"):
        whitted.framed(scene, "c")
    with pytest.raises(ArgumentError, match="no bounded object"):
        whitted.framed(whitted.Scene(objects=[whitted.Plane()]))
    with pytest.raises(ArgumentError, match="margin"):
        whitted.framed(scene, margin=float("nan"))
    with pytest.raises(ArgumentError, match="elevation"):
        whitted.framed(scene, elevation=90)


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_model_stands_centred_in_frame_and_casts_a_shadow(tmp_path):
    scene = whitted.model_scene(write(tmp_path, "pyramid.obj", PYRAMID), width=W, height=H)
    ids = whitted.render_aovs(scene)["id"]
    model = ids == 0
    ys, xs = np.nonzero(model)
    assert model.sum() > 0.1 * W * H  # big in the picture
    # inside the frame with a margin on every side, and centred
    assert xs.min() >= 2 and xs.max() <= W - 3 and ys.min() >= 2 and ys.max() <= H - 3
    assert abs((xs.min() + xs.max()) / 2 - (W - 1) / 2) < 0.1 * W
    assert abs((ys.min() + ys.max()) / 2 - (H - 1) / 2) < 0.1 * H
    assert np.all(ids[~model] == 1)  # the rest is ground, up to the top of the picture
    # the shadow: ground pixels darker than with the model left out of the shadow rays' way
    lit = whitted.render(scene).pixels
    empty = scene.model_copy()
    empty.objects = [scene.objects[1]]
    bare = whitted.render(empty).pixels
    ground = ~model
    darker = (bare.sum(axis=2) - lit.sum(axis=2))[ground]
    assert np.count_nonzero(darker > 0.15) > 0.02 * W * H  # a shadow of some size
    assert np.count_nonzero(darker < -1e-6) == 0  # the model only takes light away
    # the studio rig: a soft key light, fill and rim, an ambient
    kinds = [light.type for light in scene.lights]
    assert kinds.count("disk") == 3 and "ambient" in kinds
    assert scene.objects[1].point[1] == pytest.approx(0.0, abs=1e-3)  # ground under it


def test_the_file_materials_or_a_neutral_clay(tmp_path):
    from whitted.studio.model import CLAY

    plain = whitted.model_scene(write(tmp_path, "p.obj", PYRAMID), width=W, height=H)
    assert plain.objects[0].material == CLAY
    write(tmp_path, "red.mtl", "newmtl red\nKd 0.9 0.1 0.1\n")
    red = whitted.model_scene(write(tmp_path, "r.obj", "mtllib red.mtl\nusemtl red\n" + PYRAMID),
                              width=W, height=H)
    assert red.objects[0].material is None  # the file's own
    rgb = whitted.render(red).pixels[whitted.render_aovs(red)["id"] == 0].mean(axis=0)
    assert rgb[0] > 2 * rgb[1] and rgb[0] > 2 * rgb[2]


def test_up_axis_z(tmp_path):
    tall = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 5\nf 1 2 4\nf 2 3 4\nf 3 1 4\nf 1 3 2\n"
    scene = whitted.model_scene(write(tmp_path, "t.obj", tall), up="z", width=W, height=H)
    lo, hi = world_points(scene.objects[0], scene).min(axis=0), \
        world_points(scene.objects[0], scene).max(axis=0)
    assert hi[1] - lo[1] == pytest.approx(5.0)  # the file's z is up now
    with pytest.raises(ArgumentError):
        whitted.model_scene(tmp_path / "t.obj", up="w")


@pytest.mark.parametrize(("name", "text", "size"), [
    ("one_triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 1.0),
    ("sheet.obj", "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3 4\n", 2.0),
    ("wide.obj", "\n".join(  # the pyramid a million times bigger, far from the origin
        " ".join([w[0], *(f"{float(c) * 1e6 + 3e6:g}" for c in w[1:])]) if w[0] == "v"
        else line for line in PYRAMID.splitlines() if (w := line.split())), 2e6),
])
def test_degenerate_models_still_give_a_picture(tmp_path, name, text, size):
    scene = whitted.model_scene(write(tmp_path, name, text), width=W, height=H)
    ids = whitted.render_aovs(scene)["id"]
    ys, xs = np.nonzero(ids == 0)
    assert len(xs) > 20, name
    assert xs.min() >= 1 and xs.max() <= W - 2 and ys.min() >= 1 and ys.max() <= H - 2
    assert np.all(np.isfinite(whitted.render(scene).pixels))


@pytest.mark.parametrize(("text", "message"), [
    ("", "the model has no triangles to show"),
    ("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n", "no extent"),
    ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
    ("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n", ""),
])
def test_models_with_nothing_to_show_say_so_in_one_line(tmp_path, text, message):
    path = write(tmp_path, "bad.obj", text)
    with pytest.raises(SceneError) as info:
        whitted.model_scene(path)
    assert message in str(info.value) and "\n" not in str(info.value)
    assert str(info.value).startswith(str(path))


def test_turntable_goes_once_around_at_one_distance(tmp_path):
    scene = whitted.model_scene(write(tmp_path, "p.obj", PYRAMID), width=W, height=H)
    film = whitted.turntable(scene, 8)
    assert film.frame_count == 8 and film.animation.cyclic
    centre = np.asarray(scene.camera.look_at)
    distance = np.linalg.norm(np.asarray(scene.camera.position) - centre)
    positions = [np.asarray(film.at_frame(k).camera.position) for k in range(8)]
    assert positions[0] == pytest.approx(scene.camera.position)
    for k, p in enumerate(positions):
        assert np.linalg.norm(p - centre) == pytest.approx(distance)
        assert p[1] == pytest.approx(scene.camera.position[1])
        turn = math.degrees(math.atan2(p[0] - centre[0], p[2] - centre[2]))
        assert (turn - AZIMUTH - 45 * k + 180) % 360 == pytest.approx(180, abs=1e-6)
    for bad in (0, -1, True, 2.5):
        with pytest.raises(ArgumentError):
            whitted.turntable(scene, bad)


def run_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "whitted", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=600)


def test_render_a_model_file_from_the_command_line(tmp_path):
    write(tmp_path, "pyramid.obj", PYRAMID)
    done = run_cli("render", "pyramid.obj", "-W", "40", "-H", "30", "-o", "p.png", "-q",
                   cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    from PIL import Image

    assert Image.open(tmp_path / "p.png").size == (40, 30)
    write(tmp_path, "empty.stl", "")
    done = run_cli("render", "empty.stl", "-o", "e.png", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert done.stderr.startswith("error: empty.stl") and not (tmp_path / "e.png").exists()
    done = run_cli("render", "pyramid.obj", "--turntable", "0", cwd=tmp_path)
    assert done.returncode == 2 and "--turntable" in done.stderr
    done = run_cli("render", "pyramid.obj", "--turntable", "3", "-o", "t.png", cwd=tmp_path)
    assert done.returncode == 2 and "film" in done.stderr and done.stderr.count("\n") == 1


def test_one_side_of_a_model_picture_keeps_the_default_shape(tmp_path):
    """-W alone or -H alone: the other side follows the default 4:3 picture."""
    from PIL import Image

    write(tmp_path, "pyramid.obj", PYRAMID)
    for option, value, size in (("-W", 40, (40, 30)), ("-H", 30, (40, 30)),
                                ("-W", 1, (1, 1))):
        code, _, err = run_main("render", "pyramid.obj", option, value, "-o", "p.png", "-q",
                                cwd=tmp_path)
        assert code == 0, err
        assert Image.open(tmp_path / "p.png").size == size


def test_turntable_film_from_the_command_line(tmp_path):
    write(tmp_path, "pyramid.obj", PYRAMID)
    done = run_cli("render", "pyramid.obj", "--turntable", "4", "-W", "32", "-H", "24",
                   "-o", "spin.gif", "-q", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    from PIL import Image

    with Image.open(tmp_path / "spin.gif") as film:
        assert film.n_frames == 4 and film.size == (32, 24)
    frames = sorted((tmp_path / "spin_frames").glob("*.png"))
    assert len(frames) == 4
    a, b = (np.asarray(Image.open(f), float) for f in frames[:2])
    assert np.abs(a - b).mean() > 1  # the view turned


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

coordinate = st.floats(-1e6, 1e6, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(points=st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=1, max_size=12),
       azimuth=st.floats(-720, 720), elevation=st.floats(-89, 89),
       margin=st.floats(0, 0.85), aspect=st.sampled_from([(64, 48), (48, 64), (100, 10)]))
def test_framing_fuzz_every_point_inside(points, azimuth, elevation, margin, aspect):
    """Any cloud of points (one point, a line, a plane, 1e6 apart), any view: every point in
    front of the camera and inside the picture with the margin."""
    from whitted.studio.framing import camera_for

    pts = np.array(points, float)
    width, height = aspect
    camera = camera_for(pts, whitted.Camera(), width, height, azimuth, elevation, margin)
    scene = whitted.Scene(render=whitted.RenderSettings(width=width, height=height),
                          camera=camera)
    xy = project(scene, pts)
    assert np.all(np.isfinite(xy))
    assert np.max(np.abs(xy)) <= 1 - margin + 1e-6


@pytest.mark.parametrize("suffix", [".ply", ".stl", ".off", ".glb", ".gltf"])
def test_every_model_format_gets_its_quick_look(tmp_path, suffix):
    """An icosphere written by trimesh in each format, framed in the picture; glTF's red
    material kept, the others (no material in the file) in clay."""
    import trimesh

    from whitted.studio.model import CLAY

    mesh = trimesh.creation.icosphere(subdivisions=2, radius=2.0)
    mesh.apply_translation([5.0, 3.0, -1.0])
    if suffix in (".glb", ".gltf"):
        mesh.visual = trimesh.visual.TextureVisuals(
            material=trimesh.visual.material.PBRMaterial(baseColorFactor=[230, 30, 30, 255]))
    path = tmp_path / f"ball{suffix}"
    mesh.export(path)
    scene = whitted.model_scene(path, width=W, height=H)
    ids = whitted.render_aovs(scene)["id"]
    ys, xs = np.nonzero(ids == 0)
    assert len(xs) > 0.1 * W * H
    assert xs.min() >= 2 and xs.max() <= W - 3 and ys.min() >= 2 and ys.max() <= H - 3
    assert scene.objects[1].point[1] == pytest.approx(1.0, abs=1e-3)  # ground under the ball
    if suffix in (".glb", ".gltf"):
        rgb = whitted.render(scene).pixels[ids == 0].mean(axis=0)
        assert rgb[0] > 2 * rgb[1], rgb
    else:
        assert scene.objects[0].material == CLAY


def test_a_turntable_keeps_a_long_model_in_frame_from_every_side(tmp_path):
    """A bar eight times longer than wide: framed for the turntable, every frame holds it."""
    bar = "\n".join(f"v {x} {y} {z}" for x in (-4, 4) for y in (0, 1) for z in (-0.5, 0.5))
    faces = "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n"
    scene = whitted.model_scene(write(tmp_path, "bar.obj", bar + "\n" + faces), width=W,
                                height=H, all_around=True)
    film = whitted.turntable(scene, 12)
    pts = world_points(scene.objects[0], scene)
    for k in range(12):
        xy = project(film.at_frame(k), pts)
        assert np.max(np.abs(xy)) <= 1 - MARGIN + 1e-9, k
    look = np.asarray(scene.camera.look_at)
    assert look[0] == pytest.approx(0) and look[2] == pytest.approx(0)  # on the bar's axis
