"""The kernels run as plain Python (``NUMBA_DISABLE_JIT=1``) give the compiled kernels' image.

Each scene is rendered at a tiny size twice: once in this process and once in a fresh process
with the other mode (plain Python if this one compiles, compiled if this one runs with
``NUMBA_DISABLE_JIT=1``, as ``make coverage`` does, so that coverage sees every kernel line).
The two images must agree: the kernels' Python semantics (integer widths, NumPy scalar
promotion) are the compiled ones. The scenes between them reach every kind of shape, light,
texture, medium and mesh path."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import whitted

ROOT = Path(__file__).resolve().parents[1]
JIT_OFF = os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0")

pytestmark = pytest.mark.python_kernels

SCENES = [
    # (scene file, width, height, extra render settings)
    ("examples/lecture_rectangles.toml", 8, 8, {}),  # (an odd size puts a column on edges)
    ("examples/lecture_reflection.toml", 8, 6, {}),
    (None, 8, 6, {}),  # the built-in default scene: spheres, glass, the cones mesh
    ("examples/ice_water.toml", 6, 6, {}),  # water inside ice: nested media, absorption
    ("examples/textured.toml", 8, 6, {}),  # image, checker and gradient textures
    ("examples/soft_shadows.toml", 6, 5, {"shadow_samples": 2}),  # disk lights
    ("tests/scenes/cows_instanced.toml", 8, 6, {}),  # a mesh stored once, instanced
    # caustics: photons traced, the grid built and gathered (docs/caustics.md)
    ("examples/ice_water.toml", 6, 6, {"caustics": {"photons": 3000, "passes": 2,
                                                  "radius": 0.3}}),
]

RENDER = """
import sys, numpy as np, whitted
path, width, height, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
extra = eval(sys.argv[5])
scene = whitted.default_scene() if path == "-" else whitted.load_scene(path)
image = whitted.render(scene, width=width, height=height, samples=1, threads=1, **extra)
np.save(out, image.pixels)
"""


def _render_here(path, width, height, extra) -> np.ndarray:
    scene = whitted.default_scene() if path is None else whitted.load_scene(ROOT / path)
    return whitted.render(scene, width=width, height=height, samples=1, threads=1,
                          **extra).pixels


def _render_other_mode(path, width, height, extra, tmp_path) -> np.ndarray:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    env["NUMBA_DISABLE_JIT"] = "0" if JIT_OFF else "1"
    out = tmp_path / "other.npy"
    subprocess.run([sys.executable, "-c", RENDER, "-" if path is None else str(ROOT / path),
                    str(width), str(height), str(out), repr(extra)], env=env, check=True,
                   timeout=600)
    return np.load(out)


@pytest.mark.parametrize(("path", "width", "height", "extra"), SCENES,
                         ids=[(Path(s[0]).stem if s[0] else "default")
                              + ("_caustics" if "caustics" in s[3] else "") for s in SCENES])
def test_python_and_compiled_kernels_give_the_same_image(tmp_path, path, width, height,
                                                         extra):
    here = _render_here(path, width, height, extra)
    other = _render_other_mode(path, width, height, extra, tmp_path)
    assert here.shape == other.shape == (height, width, 3)
    assert np.isfinite(here).all() and here.max() > 0  # a picture, not a black frame
    # fast-math reorders sums in the compiled kernels: the same image to within rounding
    assert np.allclose(here, other, rtol=1e-4, atol=1e-5), np.abs(here - other).max()
