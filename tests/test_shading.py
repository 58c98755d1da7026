"""Shading against analytic values: Lambert and Phong/Blinn terms, energy bounds, falloff,
soft shadows, and determinism across thread counts."""

from __future__ import annotations

import math

import numpy as np
import pytest

import whitted

WHITE_LAMBERT = whitted.Material(color=(1, 1, 1), ka=0, kd=1, ks=0)


def _sphere_scene(light, material=WHITE_LAMBERT, size=64, **settings) -> whitted.Scene:
    return whitted.Scene(
        render=whitted.RenderSettings(width=size, height=size, **settings),
        camera=whitted.Camera(position=(0, 0, 5), look_at=(0, 0, 0), fov=30),
        lights=[light],
        objects=[whitted.Sphere(center=(0, 0, 0), radius=1, material=material)],
    )


def test_lambert_sphere_equals_n_dot_l_everywhere():
    """Under a directional light every visible pixel is exactly kd·max(0, n·l)."""
    light_dir = np.array([-1.0, -1.0, -1.0]) / math.sqrt(3)
    scene = _sphere_scene(whitted.DirectionalLight(direction=tuple(light_dir)))
    image = whitted.render(scene).pixels
    aov = whitted.render_aovs(scene)
    hit = aov["id"] == 0
    expected = np.clip(aov["normal"] @ -light_dir, 0, None)
    assert hit.sum() > 1000
    assert np.allclose(image[..., 0][hit], expected[hit], atol=1e-5)
    assert np.all(image[~hit] == 0)


def test_energy_white_lambert_never_exceeds_the_light():
    scene = _sphere_scene(whitted.PointLight(position=(0, 0, 5)), size=96)
    image = whitted.render(scene).pixels
    assert image.max() <= 1.0 + 1e-6
    assert image.max() > 0.99  # the point facing the light gets all of it


def test_blinn_and_phong_highlight_peak_values():
    """Light and eye both on +z: at the sphere's front point n = l = v, so both models give
    kd + ks exactly; away from it Phong falls faster (r·v = cos 2a vs n·h = cos a)."""
    mat = dict(color=(1, 1, 1), ka=0, kd=0.3, ks=0.6, shininess=20)
    for model in ("phong", "blinn"):
        scene = _sphere_scene(whitted.PointLight(position=(0, 0, 5)),
                              whitted.Material(specular_model=model, **mat), size=65)
        image = whitted.render(scene).pixels
        assert image[32, 32, 0] == pytest.approx(0.9, abs=2e-3)


def test_linear_and_inverse_square_falloff():
    base = dict(position=(0, 0, 5))
    none = whitted.render(_sphere_scene(whitted.PointLight(**base), size=33)).pixels[16, 16, 0]
    lin = whitted.render(_sphere_scene(
        whitted.PointLight(falloff="linear", dist_scale=2.0, **base), size=33)).pixels[16, 16, 0]
    inv = whitted.render(_sphere_scene(
        whitted.PointLight(falloff="inverse_square", **base), size=33)).pixels[16, 16, 0]
    dist = 4.0  # light at z = 5, nearest surface point at z = 1
    assert lin == pytest.approx(none * 2.0 / dist, rel=1e-3)
    assert inv == pytest.approx(none / dist**2, rel=1e-3)


def _soft_shadow_scene(samples=16, seed=0, size=48) -> whitted.Scene:
    floor = whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0), material=WHITE_LAMBERT)
    ball = whitted.Sphere(center=(0, 1, 0), radius=0.5, material=WHITE_LAMBERT)
    return whitted.Scene(
        render=whitted.RenderSettings(width=size, height=size, samples=samples, seed=seed),
        camera=whitted.Camera(position=(0, 3, 4), look_at=(0, 0.5, 0), fov=50),
        lights=[whitted.DiskLight(center=(0, 4, 0), radius=1.0, samples=16)],
        objects=[floor, ball],
    )


def test_disk_light_penumbra_is_between_umbra_and_lit():
    scene = _soft_shadow_scene().with_settings(width=1, height=1, samples=1)
    # look straight down at points on the floor at increasing distance from the shadow centre
    values = []
    for x in (0.0, 0.55, 3.0):
        cam = whitted.Camera(position=(x, 0.2, 0.0001), look_at=(x, 0.0, 0.0), fov=0.01)
        values.append(whitted.render(scene.model_copy(update={"camera": cam})).pixels[0, 0, 0])
    umbra, penumbra, lit = values
    assert umbra == pytest.approx(0.0, abs=1e-6)
    assert 0.05 < penumbra < lit
    # fully lit point: average of cos over the disk samples, close to the disk-centre value
    centre_cos = 4.0 / math.hypot(3.0, 4.0)
    assert lit == pytest.approx(centre_cos, rel=0.05)


def test_same_seed_same_image_whatever_the_thread_count():
    scene = _soft_shadow_scene(samples=4, seed=7)
    one = whitted.render(scene, threads=1).pixels
    two = whitted.render(scene, threads=2).pixels
    again = whitted.render(scene, threads=2).pixels
    assert one.tobytes() == two.tobytes() == again.tobytes()


def test_different_seed_changes_the_noise():
    a = whitted.render(_soft_shadow_scene(samples=4, seed=1)).pixels
    b = whitted.render(_soft_shadow_scene(samples=4, seed=2)).pixels
    assert not np.array_equal(a, b)
    assert np.abs(a - b).mean() < 0.02  # same picture, different noise


def test_default_scene_deterministic_across_threads():
    scene = whitted.default_scene().with_settings(width=96, height=96)
    assert (whitted.render(scene, threads=1).pixels.tobytes()
            == whitted.render(scene, threads=2).pixels.tobytes())
