"""``whitted sweep``: one image per value, a labelled contact sheet."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image as PILImage

import whitted
from whitted.animation.sweep import contact_sheet, short_name, sweep_cells
from whitted.errors import SceneError

SCENE = """\
[render]
width = 20
height = 14

[camera]
position = [0, 1, 6]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
name = "glass sphere"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.6
material = { color = [0.5, 0.7, 0.9], kd = 0.6, kt = 0.9, ior = 1.5 }

[[objects]]
type = "plane"
material = { color = [0.8, 0.3, 0.2] }
"""


def test_cells_cover_every_combination(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE)
    scene = whitted.load_scene(path)
    cells = sweep_cells(scene, [("objects[glass sphere].material.kt", [1.0, 0.5, 0.0]),
                                ("objects[glass sphere].material.kr", [0.0, 1.0])])
    assert len(cells) == 6
    assert [(c.row, c.column) for c in cells] == [(r, c) for r in range(2) for c in range(3)]
    assert cells[4].scene.objects[0].material.kt == 0.5
    assert cells[4].scene.objects[0].material.kr == 1.0
    assert cells[4].label == "kt = 0.5, kr = 1"
    assert scene.objects[0].material.kt == 0.9  # the scene itself is unchanged
    assert short_name("objects[glass sphere].material.kt") == "kt"
    with pytest.raises(SceneError, match="at most 2"):
        sweep_cells(scene, [("render.samples", [1, 2])] * 3)


def test_contact_sheet_places_each_image_in_its_cell():
    images = [np.full((10, 16, 3), 40 * k, np.uint8) for k in range(5)]
    sheet = contact_sheet(images, [f"v{k}" for k in range(5)], columns=3, title="t", gap=6)
    rows, cols = 2, 3
    size = max(11, min(24, 16 // 14))
    label_h, title_h = size + 12, size + 18
    assert sheet.shape == (title_h + rows * (10 + label_h) + 6, cols * 16 + 4 * 6, 3)
    for k in range(5):
        r, c = divmod(k, cols)
        y, x = title_h + 6 + r * (10 + label_h), 6 + c * (16 + 6)
        assert np.all(sheet[y:y + 10, x:x + 16] == 40 * k)


def test_sweep_command_writes_one_image_per_value_and_a_sheet(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE)
    sheet = tmp_path / "sheet.png"
    result = subprocess.run(
        [sys.executable, "-m", "whitted", "sweep", str(path), "-o", str(sheet),
         "--set", "objects[glass sphere].material.kt=1:0:-0.2", "--set", "render.max_depth=3"],
        capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    cells = sorted((tmp_path / "sheet_cells").iterdir())
    assert [c.name for c in cells] == [f"{k}.png" for k in range(6)]
    labels = [line.split(" (")[0] for line in result.stdout.strip().splitlines()[:-1]]
    assert labels == ["kt = 1", "kt = 0.8", "kt = 0.6", "kt = 0.4", "kt = 0.2", "kt = 0"]
    first, last = (np.asarray(PILImage.open(cells[k])) for k in (0, 5))
    assert not np.array_equal(first, last)  # transparency shows
    with PILImage.open(sheet) as im:  # six cells of 20 px in one row, 6 px apart
        assert im.size[0] == 6 * 20 + 7 * 6
    # each cell is the still a render with the same --set gives
    still = tmp_path / "still.png"
    subprocess.run([sys.executable, "-m", "whitted", "render", str(path), "-o", str(still),
                    "--set", "objects[glass sphere].material.kt=0.4", "--set",
                    "render.max_depth=3", "-q"], check=True)
    assert np.array_equal(np.asarray(PILImage.open(still)), np.asarray(PILImage.open(cells[3])))
    bad = subprocess.run([sys.executable, "-m", "whitted", "sweep", str(path), "-o",
                          str(sheet), "--set", "render.max_depth=3"], capture_output=True,
                         text=True)
    assert bad.returncode == 2 and bad.stderr.strip().startswith(
        "error: --set: nothing to sweep")
