"""Adaptive anti-aliasing: worked pixel values at an edge, smooth regions traced at the
corners only, the same image on any number of threads, settings checked, and no compile of
its own after a uniform render."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

import whitted
from whitted.scene.scene import Antialias, Scene


def _edge_scene(**antialias):
    # a white wall (ambient only) whose right edge runs down the image at x = 3.3 pixels of
    # an 8 x 4 orthographic view 8 units wide: one unit per pixel, black behind
    return Scene.model_validate({
        "render": {"width": 8, "height": 4, "transfer": "linear", "threads": 1,
                   "antialias": antialias},
        "camera": {"position": (4.0, -2.0, 5.0), "look_at": (4.0, -2.0, 0.0),
                   "projection": "orthographic", "ortho_height": 4.0},
        "background": {"color": (0.0, 0.0, 0.0)},
        "lights": [{"type": "ambient", "intensity": 1.0}],
        "objects": [{"type": "rectangle", "corner": (-10.0, -10.0, 0.0),
                     "edge1": (13.3, 0.0, 0.0), "edge2": (0.0, 20.0, 0.0),
                     "material": {"color": (1.0, 1.0, 1.0), "ka": 1.0, "kd": 0.0,
                                  "ks": 0.0}}],
    })


def test_levels_follow_the_sample_cap():
    assert [Antialias(max_samples=n).levels for n in (4, 8, 9, 24, 25, 81, 288, 289, 1089)] == \
        [0, 0, 1, 1, 2, 3, 3, 4, 5]


@pytest.mark.parametrize("max_samples, expected", [
    (4, 0.5),     # corners only: x = 3 white, x = 4 black
    (9, 0.25),    # split once: 3 white, 3.5 and 4 black: left quarters 0.5, right ones 0
    (25, 0.375),  # 3, 3.25 white; 3.5 .. 4 black: (1 + 0.5 + 0 + 0) / 4
    (81, 0.3125),  # 3 .. 3.25 white (3 of 9 columns): (1 + 1 + 0.5) / 8
])
def test_an_edge_pixel_has_the_worked_value(max_samples, expected):
    image = whitted.render(_edge_scene(threshold=0.1, max_samples=max_samples)).pixels
    assert image[1, 3, 0] == pytest.approx(expected, abs=1e-12)
    assert np.all(image[:, :3] == 1.0)  # left of the edge: white, from the corners alone
    assert np.all(image[:, 4:] == 0.0)


def test_smooth_regions_take_only_the_corners():
    # nothing but the edge column needs splitting: 9 x 5 corners, plus for each of the 4
    # edge pixels (grid columns 0..4 = x 3, 3.25, .. 4): its left half split twice, columns
    # 0, 1, 2 at all 5 rows (15 points), its right half once: column 4 at rows 0, 2, 4;
    # 18 points less the 4 corners = 14 each
    image = whitted.render(_edge_scene(threshold=0.1, max_samples=25))
    primary = image.meta["stats"].rays["primary"]
    assert primary == 9 * 5 + 4 * 14
    # a threshold above any difference: the corners only
    flat = whitted.render(_edge_scene(threshold=3.0, max_samples=25))
    assert flat.meta["stats"].rays["primary"] == 9 * 5


def test_the_same_image_on_any_number_of_threads():
    scene = whitted.load_scene("examples/soft_shadows.toml").with_settings(
        width=48, height=36, samples=1, antialias={"threshold": 0.05, "max_samples": 25})
    one = whitted.render(scene, threads=1).pixels
    two = whitted.render(scene, threads=2).pixels
    assert np.array_equal(one, two)


@pytest.mark.parametrize("tile_size", [1, 3, 5, 4096])
def test_the_same_image_whatever_the_tile_size(tile_size):
    # a sample's value depends only on its point of the finest grid: tiles of one pixel,
    # of odd sizes cut at the image's edges, and one tile bigger than the image (its lane's
    # corner memory then sized by the image) all give the 16-pixel tiles' image
    from whitted.render.api import RenderJob

    scene = whitted.load_scene("examples/soft_shadows.toml").with_settings(
        width=11, height=7, samples=1, antialias={"threshold": 0.05, "max_samples": 25})
    reference = RenderJob(scene, threads=1, tile_size=16).run().pixels
    image = RenderJob(scene, threads=1, tile_size=tile_size).run().pixels
    assert np.array_equal(image, reference)
    assert len(np.unique(reference.reshape(-1, 3), axis=0)) > 10  # not a blank picture


@pytest.mark.parametrize("antialias", [{"threshold": -0.1}, {"threshold": float("nan")},
                                       {"max_samples": 3}, {"max_samples": 10**6},
                                       {"max_samples": 2.5}, {"colour": 1}])
def test_bad_settings_are_refused(antialias):
    with pytest.raises(ValidationError):
        Scene.model_validate({"render": {"antialias": antialias}})


def test_samples_and_antialias_do_not_mix():
    with pytest.raises(ValidationError, match="leave samples at 1"):
        Scene.model_validate({"render": {"samples": 4, "antialias": {}}})


def test_an_adaptive_render_after_a_uniform_one_compiles_nothing():
    """Adaptive anti-aliasing is a run-time choice of the one render kernel (its levels and
    threshold are arguments): once a uniform render of a kind of geometry has run, an
    adaptive one of the same kind compiles and loads nothing, and its render kernel has the
    same signatures as before."""
    from numba.core.event import install_recorder

    from whitted.kernels.tiles import render_tiles

    adaptive = _edge_scene(threshold=0.1, max_samples=81)
    uniform = adaptive.model_copy(update={"render": adaptive.render.model_copy(
        update={"antialias": None})})
    assert whitted.render(uniform).pixels[1, 3, 0] == 0.0  # its centre, x = 3.5: black
    signatures = list(render_tiles.signatures)
    with install_recorder("numba:compile") as compiles:
        image = whitted.render(adaptive)
    assert compiles.buffer == []
    assert list(render_tiles.signatures) == signatures
    assert image.meta["stats"].compile_seconds == 0.0
    assert image.pixels[1, 3, 0] == pytest.approx(0.3125, abs=1e-12)  # adaptive indeed
