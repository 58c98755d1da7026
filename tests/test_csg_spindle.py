"""A spindle torus (minor radius above the major) in CSG: the lemon-shaped region around its
centre, where the tube overlaps itself, is inside the solid, as in POV-Ray 3.7. Checked
against POV-Ray's own pixels for whitted's export (stored here, rendered again when povray
is installed)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from whitted import render
from whitted.export.pov import scene_to_pov
from whitted.scene import Scene

REFERENCE = Path(__file__).parent / "scenes" / "spindle_torus_povray.npz"
SIZE = 32
RED = {"color": [1.0, 0.2, 0.1], "ka": 0.1, "kd": 0.9, "ks": 0.0}
TORUS = {"type": "torus", "major_radius": 0.6, "minor_radius": 0.9}
BALL = {"type": "sphere", "center": [0, 0, 0], "radius": 0.2}

CASES = {
    # the ball lies inside the lemon: inside the solid, so all of it is kept ...
    "intersection": ({"type": "csg", "operation": "intersection", "material": RED,
                      "objects": [BALL, TORUS]}, 0.45),
    # ... and all of it cut away
    "difference": ({"type": "csg", "operation": "difference", "material": RED,
                    "objects": [BALL, TORUS]}, 0.45),
    # the torus cut in half across its axis: the cut face is the tube's cross-section, two
    # discs of radius 0.9 around x = +-0.6, overlapping in the lemon, filled there too
    "half": ({"type": "csg", "operation": "difference", "material": RED,
              "objects": [TORUS, {"type": "box", "min": [-3, -3, 0], "max": [3, 3, 3]}]},
             3.2),
}


def scene_of(name: str) -> Scene:
    obj, height = CASES[name]
    return Scene.model_validate({
        "render": {"width": SIZE, "height": SIZE, "transfer": "linear", "max_depth": 2},
        "camera": {"position": [0.0, 0.0, 6.0], "look_at": [0, 0, 0],
                   "projection": "orthographic", "ortho_height": height},
        "background": {"color": [0.0, 0.0, 0.0]},
        "lights": [{"type": "point", "position": [2.0, 3.0, 8.0], "intensity": 1.0,
                    "falloff": "none"}],
        "objects": [obj],
    })


def povray_image(scene: Scene, tmp_path: Path) -> np.ndarray:
    """POV-Ray's linear image of whitted's export, from a 16-bit PPM."""
    pov = tmp_path / "s.pov"
    pov.write_text(scene_to_pov(scene))
    out = tmp_path / "s.ppm"
    subprocess.run(["povray", f"+I{pov}", f"+O{out}", f"+W{SIZE}", f"+H{SIZE}", "-A", "-D",
                    "-P", "+FP16", "+WT1", "-V", "File_Gamma=1.0"], capture_output=True,
                   check=True, timeout=120)
    data = out.read_bytes()
    header, pos = [], 0
    while len(header) < 4:  # P6, width, height, maxval, with '#' comment lines between
        end = data.index(b"\n", pos)
        header += data[pos:end].split(b"#")[0].split()
        pos = end + 1
    pixels = np.frombuffer(data[pos:pos + SIZE * SIZE * 6], ">u2").reshape(SIZE, SIZE, 3)
    return pixels / 65535.0


def reference(name: str, tmp_path: Path) -> np.ndarray:
    if shutil.which("povray") is not None:
        return povray_image(scene_of(name), tmp_path)
    return np.load(REFERENCE)[name] / 65535.0


@pytest.mark.parametrize("name", list(CASES))
def test_spindle_torus_in_csg_matches_povray(name, tmp_path):
    mine = render(scene_of(name)).pixels.astype(np.float64)
    pov = reference(name, tmp_path)
    covered = pov.max(axis=2) > 0.0
    assert (mine.max(axis=2) > 0.0).sum() == pytest.approx(covered.sum(), abs=2)
    if name == "difference":
        assert not covered.any()  # the ball is inside the torus: nothing is left
    else:
        assert covered.sum() > 150
    # the same pixels, to 8-bit precision, but for a few on the silhouette
    differ = np.abs(np.round(mine * 255) - np.round(pov * 255)).max(axis=2) > 1
    assert differ.sum() <= 2
    if name == "half":  # the middle of the cut face lies in the lemon: filled, and lit
        assert mine[SIZE // 2, SIZE // 2].max() > 0.2
