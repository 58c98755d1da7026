"""A closed mesh inside CSG exports as POV-Ray's ``mesh2`` (with ``inside_vector``), and
POV-Ray draws the same picture as whitted."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from PIL import Image

from whitted import render
from whitted.export.pov import export_pov, scene_to_pov
from whitted.scene import load_scene

OCTAHEDRON = """v 1.2 0 0
v -1.2 0 0
v 0 1.2 0
v 0 -1.2 0
v 0 0 1.2
v 0 0 -1.2
f 1 3 5
f 3 2 5
f 2 4 5
f 4 1 5
f 3 1 6
f 2 3 6
f 4 2 6
f 1 4 6
"""

SCENE = """[render]
width = 64
height = 48

[camera]
position = [2.5, 2.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov = 45.0

[background]
color = [0.1, 0.1, 0.2]

[[lights]]
type = "ambient"
intensity = 0.2

[[lights]]
type = "point"
position = [4.0, 6.0, 5.0]
intensity = 0.9

[[objects]]
type = "csg"
operation = "difference"
material = { color = [0.8, 0.3, 0.2], kd = 0.8, ka = 0.2 }

[[objects.objects]]
type = "box"
min = [-1, -1, -1]
max = [1, 1, 1]

[[objects.objects]]
type = "mesh"
file = "oct.obj"
transform = { translate = [0.7, 0.7, 0.7] }
material = { color = [0.2, 0.6, 0.9], kd = 0.8, ka = 0.2 }
"""


@pytest.fixture
def csg_mesh_scene(tmp_path):
    (tmp_path / "oct.obj").write_text(OCTAHEDRON, encoding="utf-8")
    (tmp_path / "csg.toml").write_text(SCENE, encoding="utf-8")
    return load_scene(tmp_path / "csg.toml")


def test_a_mesh_in_csg_is_a_closed_mesh2_with_its_childs_texture(csg_mesh_scene):
    sdl = scene_to_pov(csg_mesh_scene)
    block = sdl[sdl.index("difference {"):]
    assert "mesh2 {" in block and "vertex_vectors { 6," in block
    assert "face_indices { 8," in block and "inside_vector <0, 0, 1>" in block
    # the cutter's own material, and its placement mirrored into POV-Ray's left-handed axes
    mesh = block[block.index("mesh2 {"):]
    assert "matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0.7, 0.7, -0.7>" in mesh.replace(".0,", ",")


def test_povray_draws_the_csg_mesh_as_whitted_does(tmp_path, csg_mesh_scene):
    povray = shutil.which("povray")
    if povray is None:
        pytest.skip("povray is not on PATH")
    pov = export_pov(csg_mesh_scene, tmp_path / "csg.pov")
    run = subprocess.run([povray, f"+I{pov}", "+Opov.png", "+W64", "+H48", "-A", "-D", "+FN",
                          "+WT1", "-P"], capture_output=True, text=True, timeout=120,
                         cwd=tmp_path)
    assert run.returncode == 0, run.stderr[-2000:]
    theirs = np.asarray(Image.open(tmp_path / "pov.png").convert("RGB"), dtype=np.int16)
    ours = render(csg_mesh_scene).to_srgb8().astype(np.int16)
    # the cut's blue faces are there in both (a middle pixel of the hole)
    assert ours[24, 32, 2] > 150 and theirs[24, 32, 2] > 150
    differ = np.abs(ours - theirs).max(axis=2) > 8
    assert differ.mean() < 0.01, differ.mean()
