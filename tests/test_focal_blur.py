"""Focal blur: the blur circle of a point out of focus has the thin lens's diameter, the
plane in focus is as sharp as through a pinhole, and the samples are deterministic."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

import whitted
from whitted.scene import Camera, Disk, Material, Rectangle, Scene, Sphere

WHITE = Material(color=(1, 1, 1), ka=1.0, kd=0.0, ks=0.0)


def _scene(objects, camera, size=128, samples=64):
    return Scene.model_validate({
        "render": {"width": size, "height": size, "samples": samples, "transfer": "linear",
                   "threads": 1},
        "camera": camera.model_dump(exclude_none=True),
        "background": {"color": (0.0, 0.0, 0.0)},
        "lights": [{"type": "ambient", "intensity": 1.0}],
        "objects": [o.model_dump(exclude_none=True) for o in objects],
    })


def test_blur_circle_has_the_thin_lens_diameter():
    # a disk of radius 0.3 facing the camera 10 units ahead, the lens (diameter 2) focused
    # at 5: a point of it is spread over a circle of diameter A·|d - f| / d = 1 on the plane
    # in focus, and the disk's own image there is 2·0.3·f/d = 0.3 across: 1.3 in all. That
    # plane is 2·5·tan(20°) units high over 128 pixels (35.16 pixels per unit): 45.7 pixels
    d, f, aperture, rho = 10.0, 5.0, 2.0, 0.3
    target = Disk(center=(0, 0, -d), normal=(0, 0, 1), radius=rho, material=WHITE)
    camera = Camera(position=(0, 0, 0), look_at=(0, 0, -1), fov=40.0, aperture=aperture,
                    focal_distance=f)
    image = whitted.render(_scene([target], camera, samples=256)).pixels[..., 0]
    per_unit = 128 / (2 * f * math.tan(math.radians(20)))
    expected = (aperture * abs(d - f) + 2 * rho * f) / d * per_unit
    lit = image > 0
    rows = np.flatnonzero(lit.any(axis=1))
    cols = np.flatnonzero(lit.any(axis=0))
    for extent in (rows[-1] - rows[0] + 1, cols[-1] - cols[0] + 1):
        assert abs(extent - expected) <= 1.5
    # centred on the axis
    assert (rows[0] + rows[-1]) / 2 == pytest.approx(63.5, abs=1.0)
    # through a pinhole the disk is 2·0.3/10 / (2·tan(20°)) · 128 = 10.5 pixels across
    pinhole = whitted.render(_scene([target], Camera(position=(0, 0, 0), look_at=(0, 0, -1),
                                                     fov=40.0), samples=16)).pixels[..., 0]
    cols = np.flatnonzero((pinhole > 0).any(axis=0))
    assert abs(cols[-1] - cols[0] + 1 - 10.5) <= 1.5


def test_the_plane_in_focus_is_as_sharp_as_through_a_pinhole():
    # a checkered wall exactly at the focal distance: every lens ray meets the wall where the
    # pinhole ray does, so the pictures agree to rounding
    wall = Rectangle(corner=(-3, -3, -4), edge1=(6, 0, 0), edge2=(0, 6, 0),
                     material=Material(color=(1, 1, 1), ka=1.0, kd=0.0, ks=0.0,
                                       texture={"type": "checker", "checks": 6.0}))
    lens = Camera(position=(0, 0, 0), look_at=(0, 0, -1), aperture=0.8, focal_distance=4.0)
    pin = Camera(position=(0, 0, 0), look_at=(0, 0, -1))
    a = whitted.render(_scene([wall], lens, size=64, samples=16)).pixels
    b = whitted.render(_scene([wall], pin, size=64, samples=16)).pixels
    assert np.mean(np.abs(a - b) < 1e-6) > 0.999
    # and the focal_point form focuses at the same plane
    by_point = Camera(position=(0, 0, 0), look_at=(0, 0, -1), aperture=0.8,
                      focal_point=(1.0, 2.0, -4.0))
    c = whitted.render(_scene([wall], by_point, size=64, samples=16)).pixels
    assert np.array_equal(a, c)


def test_focal_blur_is_the_same_on_any_number_of_threads():
    camera = Camera(position=(0, 0, 0), look_at=(0, 0, -1), aperture=1.0, focal_distance=3.0)
    scene = _scene([Sphere(center=(0.5, 0, -6), radius=1.0, material=WHITE)], camera,
                   size=48, samples=4)
    one = whitted.render(scene, threads=1).pixels
    two = whitted.render(scene, threads=2).pixels
    assert np.array_equal(one, two)
    assert (one > 0).sum() > 0


@pytest.mark.parametrize("fields", [
    {"aperture": -1.0},
    {"aperture": math.nan},
    {"focal_distance": 0.0},
    {"focal_distance": 1.0, "focal_point": (0.0, 0.0, -1.0)},
    {"focal_point": (0.0, 0.0, 5.0)},  # behind the camera
])
def test_bad_lens_settings_are_refused(fields):
    with pytest.raises(ValidationError):
        Camera(position=(0, 0, 0), look_at=(0, 0, -1), **fields)
