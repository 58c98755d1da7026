"""The render kernels as plain Python and compiled give the same image on the scenes of
tests/python_kernel_scenes.py (light types and falloffs, highlights, soft-shadow bundles, deep
transparent shadows, transparent mesh instances, textures on every shape): rendered here and
in one fresh process with the other JIT mode (plain Python when this run is compiled)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import python_kernel_scenes as scenes  # noqa: E402
from other_jit import in_other_jit_mode  # noqa: E402

pytestmark = pytest.mark.python_kernels


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    """(this process's images, the other JIT mode's images), by scene name."""
    here = scenes.render_all()
    out = tmp_path_factory.mktemp("python_kernels") / "other.npz"
    return here, in_other_jit_mode("python_kernel_scenes.py", out)


def test_python_and_compiled_aovs_agree(images):
    here, other = images
    aovs = sorted(k for k in here if k.startswith("aov_"))
    assert aovs == ["aov_depth", "aov_id", "aov_normal"]
    for key in aovs:
        assert np.array_equal(np.isinf(here[key]), np.isinf(other[key])), key
        assert np.allclose(here[key], other[key], rtol=1e-5, atol=1e-6), key
    ids = here["aov_id"]
    assert set(np.unique(ids)) == set(range(-1, 9))  # the sky and all 9 objects
    depth = here["aov_depth"]
    assert np.array_equal(np.isinf(depth), ids == -1)
    # the floor (object 0) faces up; the sky has no normal
    assert np.allclose(here["aov_normal"][ids == 0], [0.0, 1.0, 0.0], atol=1e-6)
    assert not here["aov_normal"][ids == -1].any()


@pytest.mark.parametrize("name", list(scenes.SCENES))
def test_python_and_compiled_kernels_give_the_same_image(images, name):
    here, other = images
    assert here[name].shape == other[name].shape
    assert np.isfinite(here[name]).all() and here[name].max() > 0
    # fast-math reorders sums in the compiled kernels: the same image to within rounding
    assert np.allclose(here[name], other[name], rtol=1e-4, atol=1e-5), \
        np.abs(here[name] - other[name]).max()


@pytest.mark.parametrize("name", ["glass_sheets", "glass_sheets_past_the_list_cap"])
def test_light_through_too_many_sheets_is_cut_off(images, name):
    """Each sheet passes 0.7 of the light: through 34 of them 0.7**34 = 5e-6 is left, under the
    1e-4 at which a shadow ray stops: the floor shows its ambient term alone,
    ka * ambient * colour = 0.2 * 0.2 * (0.8, 0.8, 0.75), in either mode."""
    assert 0.7**34 < 1e-4
    ambient = np.array([0.032, 0.032, 0.030], np.float32)
    for image in images:
        assert np.allclose(image[name], ambient, rtol=1e-6, atol=0), image[name]

