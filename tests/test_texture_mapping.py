"""Textures through the whole renderer: each shape's (u, v) mapping, checker values at known
pixels, textured materials from scene files, and bad texture or model files as one-line errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import whitted
from whitted.cli.main import app
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit
from whitted.kernels.layout import BVH_STACK
from whitted.kernels.uv import surface_uv

CHECKER = whitted.CheckerTexture(color1=(1, 1, 1), color2=(0, 0, 0), checks=1.0)


def _uv(shape, o, d):
    compiled = compile_scene(whitted.Scene(objects=[shape]))
    geo = compiled.geometry
    t, prim, tri, b1, b2 = closest_hit(geo, o, d, 0.0, math.inf, np.empty(BVH_STACK, np.int32))
    assert prim >= 0
    p = tuple(a + t * b for a, b in zip(o, d, strict=True))
    return surface_uv(geo, prim, tri, b1, b2, p)


def _flat(texture) -> whitted.Material:
    """Shows the texture as it is: ambient only, full weight."""
    return whitted.Material(ka=1.0, kd=0.0, texture=texture)


def test_checker_floor_pixels():
    """Seen straight down through an orthographic camera, each pixel of a checkered floor is
    the checker's colour at that pixel's centre: u = x, v = -z on a +y plane."""
    floor = whitted.Plane(material=_flat(CHECKER))
    scene = whitted.Scene(
        objects=[floor], lights=[whitted.AmbientLight(intensity=1.0)],
        camera=whitted.Camera(position=(0.3, 5, 0.2), rotate=(-90, 0, 0),
                              projection="orthographic", ortho_height=4.0),
        render=whitted.RenderSettings(width=40, height=40, transfer="linear"),
    )
    img = whitted.render(scene).pixels[..., 0]
    # camera looks down -y with +y up turned to -z: image x -> world +x, image y -> world +z
    xs = 0.3 + (np.arange(40) + 0.5) / 40 * 4.0 - 2.0
    zs = 0.2 + (np.arange(40) + 0.5) / 40 * 4.0 - 2.0
    u, v = np.meshgrid(xs, -zs)
    expect = np.where((np.floor(u) + np.floor(v)) % 2 == 0, 1.0, 0.0)
    np.testing.assert_allclose(img, expect, atol=1e-6)


def test_sphere_mapping_is_spherical_and_turns_with_the_sphere():
    s = whitted.Sphere(radius=2.0, center=(0, 0, 0))
    assert _uv(s, (0.0, 0.0, 10.0), (0.0, 0.0, -1.0)) == pytest.approx((0.5, 0.5))
    assert _uv(s, (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)) == pytest.approx((0.75, 0.5))
    assert _uv(s, (0.0, 10.0, 0.0), (0.0, -1.0, 0.0))[1] == pytest.approx(1.0)
    turned = s.model_copy(update={"transform": whitted.Transform(rotate=(0, 90, 0))})
    # the object's +z now faces world +x: the u = 0.5 meridian faces +x
    assert _uv(turned, (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)) == pytest.approx((0.5, 0.5))


def test_rectangle_disk_box_triangle_mappings():
    rect = whitted.Rectangle(corner=(0, 0, 0), edge1=(4, 0, 0), edge2=(0, 2, 0))
    assert _uv(rect, (1.0, 1.5, 5.0), (0.0, 0.0, -1.0)) == pytest.approx((0.25, 0.75))
    disk = whitted.Disk(center=(0, 0, 0), normal=(0, 0, 1), radius=2.0)
    assert _uv(disk, (1.0, -1.0, 5.0), (0.0, 0.0, -1.0)) == pytest.approx((0.75, 0.25))
    box = whitted.Box(min=(0, 0, 0), max=(2, 4, 1))
    assert _uv(box, (0.5, 1.0, 5.0), (0.0, 0.0, -1.0)) == pytest.approx((0.25, 0.25))
    tri = whitted.Triangle(vertices=[(0, 0, 0), (2, 0, 0), (0, 2, 0)],
                           uvs=[(0.2, 0.2), (0.6, 0.2), (0.2, 1.0)])
    # barycentric (b1, b2) = (0.25, 0.5) at (0.5, 1.0)
    assert _uv(tri, (0.5, 1.0, 5.0), (0.0, 0.0, -1.0)) == pytest.approx((0.3, 0.6))


def test_gradient_on_a_sphere_at_the_centre_pixel():
    grad = whitted.GradientTexture(color1=(0, 0, 0), color2=(1, 1, 1), axis="u")
    scene = whitted.Scene(
        objects=[whitted.Sphere(radius=1.0, material=_flat(grad))],
        lights=[whitted.AmbientLight(intensity=1.0)],
        render=whitted.RenderSettings(width=21, height=21, transfer="linear"),
    )
    img = whitted.render(scene).pixels
    assert img[10, 10, 0] == pytest.approx(0.5, abs=1e-6)
    assert img[10, 8, 0] < 0.5 < img[10, 12, 0]  # u grows to the right seen from +z


def test_texture_multiplies_the_colour_and_white_is_the_default():
    assert whitted.Material(texture=CHECKER).color == (1.0, 1.0, 1.0)
    tinted = whitted.Material(texture=CHECKER, color=(0.5, 0.25, 1.0))
    assert tinted.color == (0.5, 0.25, 1.0)


def test_image_texture_from_a_scene_file(tmp_path: Path):
    from PIL import Image as PILImage

    px = np.zeros((2, 2, 3), np.uint8)
    px[0, 0] = (255, 0, 0)  # top left: red
    px[0, 1] = (0, 255, 0)
    px[1, 0] = (0, 0, 255)  # bottom left: blue
    px[1, 1] = (255, 255, 255)
    PILImage.fromarray(px).save(tmp_path / "quad.png")
    (tmp_path / "scene.toml").write_text(
        '[render]\nwidth = 20\nheight = 20\ntransfer = "linear"\n'
        '[camera]\nposition = [0.5, 0.5, 5]\nprojection = "orthographic"\northo_height = 1.0\n'
        '[[lights]]\ntype = "ambient"\nintensity = 1.0\n'
        '[[objects]]\ntype = "rectangle"\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\n'
        'edge2 = [0, 1, 0]\nmaterial = { ka = 1.0, kd = 0.0, texture = { type = "image", '
        'file = "quad.png", filter = "nearest" } }\n'
    )
    img = whitted.render(whitted.load_scene(tmp_path / "scene.toml")).pixels
    np.testing.assert_allclose(img[2, 2], (1, 0, 0), atol=1e-6)  # v = 1 is the image's top
    np.testing.assert_allclose(img[17, 2], (0, 0, 1), atol=1e-6)
    np.testing.assert_allclose(img[2, 17], (0, 1, 0), atol=1e-6)


@pytest.mark.parametrize(
    "obj_text, expect",
    [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "bad.obj:4: vertex index 4 out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n", "bad.obj:3: invalid number 'x'"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj:3: face has 2 corners"),
    ],
)
def test_bad_model_is_one_error_line(tmp_path: Path, obj_text: str, expect: str):
    (tmp_path / "bad.obj").write_text(obj_text)
    (tmp_path / "scene.toml").write_text('[[objects]]\ntype = "mesh"\nfile = "bad.obj"\n')
    out = tmp_path / "out.png"
    result = CliRunner().invoke(app, ["render", str(tmp_path / "scene.toml"), "-o", str(out),
                                      "-W", "8", "-H", "8", "-q"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and expect in lines[0] and "Traceback" not in result.output
    assert not out.exists()


def test_missing_model_or_texture_names_the_scene_line(tmp_path: Path):
    (tmp_path / "scene.toml").write_text(
        '[[objects]]\ntype = "sphere"\nradius = 1\n\n'
        '[[objects]]\ntype = "mesh"\nfile = "nowhere.obj"\n'
    )
    result = CliRunner().invoke(app, ["render", str(tmp_path / "scene.toml"), "-q"])
    assert result.exit_code == 2
    assert "scene.toml:7: objects[1].file: no such file: 'nowhere.obj'" in result.output
    (tmp_path / "tex.toml").write_text(
        '[materials.m]\ntexture = { type = "image", file = "gone.png" }\n'
    )
    result = CliRunner().invoke(app, ["info", str(tmp_path / "tex.toml")])
    assert result.exit_code == 2
    assert "tex.toml:2: materials.m.texture.file: no such file: 'gone.png'" in result.output


def test_info_on_a_model_file(tmp_path: Path):
    (tmp_path / "quad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    result = CliRunner().invoke(app, ["info", str(tmp_path / "quad.obj")])
    assert result.exit_code == 0
    assert "vertices: 4" in result.output.splitlines()
    assert "triangles: 2" in result.output.splitlines()
