"""bench/rays.py, the ray-casting core ``whitted bench --compare embree`` times: camera rays in
the render's tile order, nearest hits and shadow tests, worked out for one sphere. Run as
plain Python (``NUMBA_DISABLE_JIT=1``, in a fresh process) so that every kernel line is the
one measured; the compiled kernels are checked against Embree by tests/test_bench.py."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.python_kernels

SCRIPT = """
import json, numpy as np
from whitted.scene import Camera, Scene, Sphere
from whitted.compile.params import render_params
from whitted.compile.scene import compile_scene
from whitted.kernels.tiles import BVH_STACK
from whitted.bench.rays import camera_rays, nearest_hits, occluded

scene = Scene(camera=Camera(position=(0, 0, 5), look_at=(0, 0, 0), fov=60),
              objects=[Sphere(radius=1)], render={"width": 3, "height": 3})
compiled = compile_scene(scene)
params = render_params(scene, compiled, scene.render)
origins, directions = np.empty((9, 3)), np.empty((9, 3))
camera_rays(params, origins, directions)
stack = np.empty(BVH_STACK, np.int32)
t = np.empty(9)
nearest_hits(compiled.geometry, origins, directions, t, stack)
s_o = np.array([[0, 0, 3.0], [0, 0, 3.0], [0, 3.0, 0]])
s_d = np.array([[0, 0, -1.0], [0, 0, -1.0], [1.0, 0, 0]])
blocked = np.empty(3, np.int32)
occluded(compiled.geometry, compiled.materials, s_o, s_d, np.array([10, 1.5, 10.0]), blocked,
         stack)
print(json.dumps({"origins": origins.tolist(), "directions": directions.tolist(),
                  "t": [x if np.isfinite(x) else None for x in t.tolist()],
                  "blocked": blocked.tolist()}))
"""


def test_camera_rays_hits_and_shadows_of_one_sphere():
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NUMBA_DISABLE_JIT="1")
    run = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=600, check=True)
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["origins"] == [[0.0, 0.0, 5.0]] * 9
    # pixel centres of a 3 x 3 image at 60 degrees: offsets of ±(2/3)·tan 30° off the axis
    s = 2 / 3 * math.tan(math.radians(30))
    for k, d in enumerate(out["directions"]):
        row, col = divmod(k, 3)
        expected = [(col - 1) * s, (1 - row) * s, -1.0]
        norm = math.sqrt(sum(c * c for c in expected))
        assert d == pytest.approx([c / norm for c in expected], abs=1e-12), k
    # only the centre ray meets the sphere: 5 - 1 along the axis (the others pass 1.8 and
    # 2.4 units from its centre)
    assert out["t"][:4] == [None] * 4 and out["t"][5:] == [None] * 4
    assert out["t"][4] == pytest.approx(4.0, abs=1e-9)
    # from z = 3 down the axis the sphere is 2 away: blocked within 10, not within 1.5;
    # along x from (0, 3, 0) nothing is in the way
    assert out["blocked"] == [1, 0, 0]
