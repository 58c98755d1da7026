"""The lecture's worked numbers (spec digest, "golden values"), computed by the real renderer
from the example scene files. The lecture truncates at every step, so ±2 on 0..255."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import whitted

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
# 161x161 image: pixel centre (row 80, column 130) is the lecture's ray through (50, 0, 0)
ROW, COL = 80, 130


def pixel_255(scene: whitted.Scene) -> np.ndarray:
    image = whitted.render(scene)
    return image.pixels[ROW, COL] * 255.0


@pytest.fixture(scope="module")
def rectangles() -> whitted.Scene:
    return whitted.load_scene(EXAMPLES / "lecture_rectangles.toml")


def test_ray_through_pixel_hits_rectangle_2_at_lecture_point(rectangles):
    aov = whitted.render_aovs(rectangles)
    # direction (0.447, 0, -0.894) from the eye (0, 0, 100): t = 89.443 to (40, 0, 20)
    assert aov["depth"][ROW, COL] == pytest.approx(89.4427191, abs=1e-4)
    assert aov["id"][ROW, COL] == 1  # rectangle 2 (rectangle 1 is missed, u = 1.5)
    assert np.allclose(aov["normal"][ROW, COL], (0.0, 0.0, 1.0))


def test_shadowed_point_keeps_only_ambient(rectangles):
    # rectangle 1 blocks the shadow ray at (20, 0, 40): only ka·BA·colour = (10, 117, 10)
    assert pixel_255(rectangles) == pytest.approx([10, 117, 10], abs=2)


def test_without_rectangle_1_diffuse_and_blinn_specular(rectangles):
    scene = rectangles.model_copy(deep=True)
    del scene.objects[0]
    # ambient (10,117,10) + diffuse sh=30/56.57 -> (4,44,4) + Blinn specular (36,36,36)
    assert pixel_255(scene) == pytest.approx([50, 197, 50], abs=2)


def test_reflecting_rectangle_adds_half_the_red_wall():
    scene = whitted.load_scene(EXAMPLES / "lecture_reflection.toml")
    # (50,197,50) + 0.5 * (236,73,73) = (168,233,86)
    assert pixel_255(scene) == pytest.approx([168, 233, 86], abs=2)


def test_red_wall_colour_seen_by_the_reflected_ray():
    """The reflected ray from (40,0,20) along (0.447,0,0.894) meets the wall at (50,0,40);
    looking at that point directly from (40,0,20) gives the lecture's (236,73,73)."""
    scene = whitted.load_scene(EXAMPLES / "lecture_reflection.toml")
    cam = whitted.Camera(position=(40.0, 0.0, 20.0), look_at=(50.0, 0.0, 40.0), fov=1.0)
    scene = scene.model_copy(update={"camera": cam})
    scene = scene.with_settings(width=1, height=1, max_depth=0)
    value = whitted.render(scene).pixels[0, 0] * 255.0
    assert value == pytest.approx([236, 73, 73], abs=2)
