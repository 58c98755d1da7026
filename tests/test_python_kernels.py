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
    ("examples/soft_shadows.toml", 6, 5, {"samples": 1, "shadow_samples": 2}),  # disk lights
    ("tests/scenes/cows_instanced.toml", 8, 6, {}),  # a mesh stored once, instanced
    ("examples/die.toml", 8, 6, {"max_depth": 2}),  # CSG: intersection, difference, materials
    ("examples/hollow_ice.toml", 6, 6, {}),  # CSG as one body: water inside hollow ice
    ("tests/scenes/torus_blur_aa.toml", 8, 6, {}),  # torus, merge, focal blur, adaptive AA
    # caustics: photons traced, the grid built and gathered (docs/caustics.md)
    ("examples/ice_water.toml", 6, 6, {"caustics": {"photons": 3000, "passes": 2,
                                                  "radius": 0.3}}),
]

RENDER = """
import sys, numpy as np, whitted
path, width, height, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
extra = eval(sys.argv[5])
scene = whitted.default_scene() if path == "-" else whitted.load_scene(path)
image = whitted.render(scene, width=width, height=height, threads=1, **extra)
np.save(out, image.pixels)
"""


def _render_here(path, width, height, extra) -> np.ndarray:
    scene = whitted.default_scene() if path is None else whitted.load_scene(ROOT / path)
    return whitted.render(scene, width=width, height=height, threads=1, **extra).pixels


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


STEFAN = """
import sys, whitted
from whitted.stefan.case import Case
from whitted.stefan.run import run_case
case = Case.model_validate({"grid": {"cells": 12}, "cavity": {"radius": 0.0135,
                            "temperature": 60.0}, "air": {"h": 30.0, "temperature": 30.0},
                            "time": {"end": 240.0, "save_every": 120.0},
                            "surfaces": {"smoothing": 2}})
run_case(case, "", sys.argv[1])
"""


def test_python_and_compiled_stefan_kernels_give_the_same_melt(tmp_path):
    """The Stefan solver's kernels (stefan/kernels.py) as plain Python and compiled: the same
    time series (volumes, thinnest shell, energy balance) to within rounding."""
    import csv

    series = {}
    for mode in ("0", "1"):
        env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NUMBA_DISABLE_JIT=mode)
        out = tmp_path / f"jit_off_{mode}"
        subprocess.run([sys.executable, "-c", STEFAN, str(out)], env=env, check=True,
                       timeout=600)
        with (out / "series.csv").open(newline="") as fh:
            series[mode] = list(csv.DictReader(fh))
    compiled, plain = series["0"], series["1"]
    assert [r["time_s"] for r in compiled] == [r["time_s"] for r in plain] == \
        ["0.0", "120.0", "240.0"]
    for a, b in zip(compiled, plain, strict=True):
        for key in ("ice_volume_cm3", "cavity_volume_cm3", "water_volume_cm3", "min_shell_mm"):
            assert float(a[key]) == pytest.approx(float(b[key]), rel=1e-9, abs=1e-12), key
    assert float(compiled[-1]["ice_volume_cm3"]) < float(compiled[0]["ice_volume_cm3"])
