"""Small pieces with worked values: an error's one line without a file, Reinhard's tone map
on values that are not RGB triples (each value alone: x / (1 + x)), the PNG writer's bit
depths, and the assets package's lazy names."""

from __future__ import annotations

import io

import numpy as np
import pytest

import whitted.assets as assets
from whitted.errors import SceneError
from whitted.output.colour import tonemap
from whitted.output.png import write_png


def test_an_error_without_a_file_names_its_line():
    assert str(SceneError("bad", line=3, where="objects[0]")) == "line 3: objects[0]: bad"
    assert str(SceneError("bad", file="s.toml", where="camera")) == "s.toml: camera: bad"


def test_reinhard_on_values_that_are_not_rgb():
    out = tonemap(np.array([[0.0, 1.0], [3.0, 0.25]], np.float32), "reinhard")
    np.testing.assert_allclose(out, [[0.0, 0.5], [0.75, 0.2]], rtol=1e-6)
    # an RGB triple is scaled by its luminance instead (Rec. 709 weights)
    rgb = tonemap(np.array([0.0, 1.0, 3.0], np.float32), "reinhard")
    lum = 0.7152 + 3 * 0.0722
    np.testing.assert_allclose(rgb, [0.0, 1 / (1 + lum), 1.0], rtol=1e-4)


def test_png_bit_depths():
    with pytest.raises(ValueError, match="^PNG bit depth must be 8 or 16, not 12$"):
        write_png(io.BytesIO(), 1, 1, 12, None, 4)


def test_the_assets_packages_names():
    assert "load_mesh" in dir(assets) and "load_image" in dir(assets)
    with pytest.raises(AttributeError, match="^module 'whitted.assets' has no attribute "
                                             "'nothing'$"):
        assets.nothing  # noqa: B018
