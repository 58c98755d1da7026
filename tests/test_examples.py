"""Every shipped example loads, renders (small) to a finite, non-black image, and the default
scene is the shipped transparent_sphere example."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import whitted
from whitted.scene.default import default_scene_text

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_example_renders(path: Path):
    scene = whitted.load_scene(path)
    image = whitted.render(scene, width=48, height=36, samples=1)
    pixels = image.pixels
    assert pixels.shape == (36, 48, 3)
    assert np.all(np.isfinite(pixels))
    assert pixels.max() > 0.05
    assert image.meta["stats"].rays["primary"] == 48 * 36


def test_default_scene_is_the_transparent_sphere_example():
    shipped = (EXAMPLES / "transparent_sphere.toml").read_text()
    assert shipped == default_scene_text()
    assert whitted.default_scene() == whitted.load_scene(EXAMPLES / "transparent_sphere.toml")
