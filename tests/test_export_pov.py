"""The POV-Ray exporter: axes, camera, lights, materials, every shape, and (when POV-Ray is
installed) that POV-Ray parses and renders what it writes."""

from __future__ import annotations

import math
import re
import shutil
import subprocess

import numpy as np
import pytest
from typer.testing import CliRunner

from whitted.cli.main import app
from whitted.export.pov import export_pov, matrix_keyword, mirrored, scene_to_pov
from whitted.scene import (
    AmbientLight,
    Box,
    Camera,
    CheckerTexture,
    Cone,
    Cylinder,
    DirectionalLight,
    Disk,
    DiskLight,
    GradientTexture,
    ImageTexture,
    Material,
    Mesh,
    Plane,
    PointLight,
    Rectangle,
    Scene,
    Sphere,
    Transform,
    Triangle,
)
from whitted.scene.default import default_scene

POVRAY = shutil.which("povray")


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)]


def _vector_after(keyword: str, text: str) -> np.ndarray:
    m = re.search(re.escape(keyword) + r"\s*<([^>]*)>", text)
    assert m, f"no {keyword} in the SDL"
    return np.array(_numbers(m.group(1)))


def every_shape_scene(tmp_path) -> Scene:
    """One of each shape, light and texture kind, with transforms."""
    from PIL import Image

    pixels = np.zeros((8, 8, 3), np.uint8)
    pixels[:4, :, 0] = 255
    Image.fromarray(pixels).save(tmp_path / "stripes.png")
    tetra = Mesh(
        vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
        faces=[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        uvs=[[0, 0], [1, 0], [0, 1], [1, 1]],
        smooth=True,
        material="water",
        transform=Transform(scale=0.8, translate=(0.5, 0.0, 1.5)),
    )
    scene = Scene(
        camera=Camera(position=(0, 3, 9), look_at=(0, 0.8, 0)),
        background={"gradient": {"top": [0.2, 0.3, 0.6], "bottom": [0.8, 0.8, 0.9]}},
        lights=[
            AmbientLight(intensity=0.2),
            PointLight(position=(-4, 6, 5), intensity=30, falloff="inverse_square"),
            DirectionalLight(direction=(0.3, -1, -0.2), intensity=0.3),
            DiskLight(center=(2, 5, 2), radius=0.8, samples=16, falloff="linear",
                      dist_scale=5.0),
        ],
        objects=[
            Plane(material=Material(texture=CheckerTexture(checks=1.0))),
            Sphere(center=(-2.5, 1, 0), radius=1,
                   material=Material(texture=ImageTexture(file="stripes.png", scale=(2, 2)))),
            Box(corner=(-0.5, 0, -0.5), edges=((1, 0, 0), (0.2, 1, 0), (0, 0, 1)),
                material=Material(ks=0.5, specular_model="phong"),
                transform=Transform(rotate=(0, 30, 0), translate=(0, 0, -1))),
            Box(min=(3, 0, 1), max=(4, 1, 2), material="ice"),
            Cylinder(base=(2, 0, 0), top=(2, 1.5, 0), radius=0.4, material="glass"),
            Cone(base=(3.2, 0, -1), top=(3.2, 1.5, -1), radius=0.5, top_radius=0.1,
                 capped=False, material="plastic"),
            Disk(center=(0, 2.5, -2), normal=(0, 0, 1), radius=0.6,
                 material=Material(texture=GradientTexture(axis="v"))),
            Rectangle(corner=(-4, 0, -3), edge1=(2, 0, 0), edge2=(0, 2, 0),
                      material=Material(kr=0.1, ambient_color=(1.0, 0.0, 0.0))),
            Triangle(vertices=((1, 2, -2), (2, 2, -2), (1.5, 3, -2)), material="mirror"),
            tetra,
        ],
    )
    scene.render.width, scene.render.height, scene.render.max_depth = 32, 24, 4
    return scene.with_base_dir(tmp_path)


def test_points_and_transforms_are_mirrored_in_z():
    assert mirrored((1.0, 2.0, 3.0)) == "<1, 2, -3>"
    m = Transform(scale=(1, 2, 3), rotate=(10, 20, 30), translate=(1, -2, 3)).matrix()
    values = _numbers(matrix_keyword(m))
    rows = np.array(values).reshape(4, 3)  # POV-Ray: p' = [x y z 1] · rows
    p = np.array([0.3, -0.7, 1.1])
    ours = (m @ np.append(p, 1.0))[:3]
    flip = np.array([1.0, 1.0, -1.0])
    theirs = np.append(p * flip, 1.0) @ rows
    np.testing.assert_allclose(theirs, ours * flip, atol=1e-9)


def test_default_scene_camera_lights_and_materials():
    scene = default_scene()
    sdl = scene_to_pov(scene)
    assert len(re.findall(r"^sphere \{", sdl, re.M)) == 15
    assert len(re.findall(r"^plane \{", sdl, re.M)) == 1
    assert sdl.count("light_source") == 2
    assert "max_trace_level 6" in sdl and "adc_bailout 0.01" in sdl
    np.testing.assert_allclose(_vector_after("ambient_light rgb", sdl), [0.25] * 3)
    # the camera: mirrored position, unit forward, right/up spanning the image plane
    np.testing.assert_allclose(_vector_after("location", sdl), [0, 2.6, -9])
    forward = _vector_after("direction", sdl)
    right = _vector_after("right", sdl)
    up = _vector_after("up", sdl)
    assert abs(np.linalg.norm(forward) - 1) < 1e-9
    half_height = math.tan(math.radians(scene.camera.fov) / 2)
    assert abs(np.linalg.norm(up) - 2 * half_height) < 1e-6
    assert abs(np.linalg.norm(right) / np.linalg.norm(up) - 809 / 817) < 1e-6
    # left-handed frame as POV-Ray's default: up x direction points along right
    np.testing.assert_allclose(np.cross(up, forward) / np.linalg.norm(np.cross(up, forward)),
                               right / np.linalg.norm(right), atol=1e-9)
    # glass: transmitted through the filter, Fresnel reflection, ior in the interior
    assert "rgbf <1, 1, 1, 0.95>" in sdl
    assert "reflection { 0.05, 1 fresnel on } conserve_energy" in sdl
    assert "interior { ior 1.5 }" in sdl
    assert "sky_sphere" in sdl


def test_falloff_and_absorption_match_ours(tmp_path):
    scene = Scene(
        camera=Camera(position=(0, 0, 10)),
        lights=[PointLight(position=(0, 4, 0), intensity=3.0, falloff="inverse_square"),
                PointLight(position=(0, 0, 4), intensity=2.0, falloff="linear", dist_scale=7)],
        objects=[Sphere(radius=1, material=Material(kt=0.9, ior=1.3,
                                                    attenuation=(0.5, 0.1, 0.0)))],
    )
    sdl = scene_to_pov(scene)
    lights = re.findall(r"light_source \{ <[^>]*> rgb <([^>]*)>\s*fade_distance (\S+) "
                        r"fade_power (\d)", sdl)
    assert len(lights) == 2
    for (colour, fade, power), expected in zip(
        lights, (lambda d: 3.0 / d**2, lambda d: 2.0 * 7 / d), strict=True
    ):
        c, f, p = _numbers(colour)[0], float(fade), int(power)
        for d in (0.5, 3.0, 40.0):  # POV-Ray: colour · 2 / (1 + (d/f)^p)
            assert c * 2 / (1 + (d / f) ** p) == pytest.approx(expected(d), rel=1e-3)
    m = re.search(r"fade_distance (\S+) fade_power 1001 fade_color <([^>]*)>", sdl)
    assert m
    distance, colour = float(m.group(1)), np.array(_numbers(m.group(2)))
    for depth in (0.1, 2.0):  # POV-Ray: exp(-(1 - fade_color) · depth / fade_distance)
        np.testing.assert_allclose(np.exp(-(1 - colour) * depth / distance),
                                   np.exp(-np.array([0.5, 0.1, 0.0]) * depth), rtol=1e-9)


def test_every_shape_light_and_texture_is_written(tmp_path):
    sdl = scene_to_pov(every_shape_scene(tmp_path))
    for keyword in ("plane {", "sphere {", "box { <0, 0, 0>, <1, 1, 1> matrix", "cylinder {",
                    "cone {", " open", "disc {", "mesh {", "mesh2 {", "uv_vectors",
                    "normal_vectors", "inside_vector", "area_light", "circular",
                    "area_illumination on", "parallel",
                    "fade_power 2", "fade_power 1 ", "uv_mapping image_map", "checker",
                    "gradient y", "phong 0.5 phong_size 32", "ambient rgb <0.25, 0, 0>",
                    "fade_power 1001"):
        assert keyword in sdl, keyword
    # a disk light of 16 samples: a 4 x 4 array over a disk of radius 0.8
    m = re.search(r"area_light <([^>]*)>, <([^>]*)>, (\d+), (\d+)", sdl)
    assert m and m.group(3) == m.group(4) == "4"
    assert np.linalg.norm(_numbers(m.group(1))) == pytest.approx(1.6)
    # an open cone / flat shapes get no interior, the glass cylinder does
    cone = sdl[sdl.index("cone {"):]
    assert "interior" not in cone[: cone.index("\n}")]
    cylinder = sdl[sdl.index("cylinder {"):]
    assert "interior" in cylinder[: cylinder.index("\n}")]


def test_mesh_from_a_model_file(tmp_path):
    (tmp_path / "quad.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", encoding="utf-8"
    )
    scene = Scene(objects=[Mesh(file="quad.obj", material="matte", solid=False)])
    sdl = scene_to_pov(scene.with_base_dir(tmp_path))
    assert "vertex_vectors { 4," in sdl and "face_indices { 2," in sdl
    assert "inside_vector" not in sdl


def test_export_command_writes_the_file(tmp_path, lecture_scene):
    out = tmp_path / "lecture.pov"
    result = CliRunner().invoke(app, ["export", str(lecture_scene), "-o", str(out),
                                      "--width", "40", "--height", "40"])
    assert result.exit_code == 0, result.output
    assert "povray" in result.output
    text = out.read_text()
    assert text.startswith("// POV-Ray 3.7") and "+W40 +H40" in text
    bad = CliRunner().invoke(app, ["export", str(lecture_scene), "--format", "obj"])
    assert bad.exit_code == 2


def test_povray_parses_and_renders_the_export(tmp_path):
    if POVRAY is None:
        message = "povray is not on PATH: the exported SDL was not checked by POV-Ray itself"
        print(message)
        pytest.skip(message)
    scene = every_shape_scene(tmp_path)
    pov = export_pov(scene, tmp_path / "every_shape.pov")
    image = tmp_path / "every_shape.png"
    run = subprocess.run(
        [POVRAY, f"+I{pov}", f"+O{image}", "+W32", "+H24", "-A", "-D", "+FN", "+WT1", "-P"],
        capture_output=True, text=True, timeout=120, cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert "Parse Error" not in run.stderr and image.stat().st_size > 0
    assert "Render Statistics" in run.stderr
