"""The Stefan case file, the surfaces and ``whitted stefan run`` end to end: one-line errors
naming the key (exit 2), outputs, resume after an interruption, breach handling."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from typer.testing import CliRunner

from whitted.cli.main import app
from whitted.scene import load_scene
from whitted.stefan.case import Case, CaseError, case_from_dict, load_case
from whitted.stefan.geometry import initial_state
from whitted.stefan.run import condensed_volume, run_case
from whitted.stefan.surfaces import extract_surfaces

REPO = Path(__file__).resolve().parents[1]
SMALL = """
[grid]
cells = 12
[time]
end = 600.0
save_every = 300.0
[surfaces]
smoothing = 5
"""


def test_the_example_case_loads():
    case = load_case(REPO / "examples" / "stefan" / "hollow_ice.toml")
    assert case.grid.cells == 48
    assert case.properties.latent_per_volume == pytest.approx(917.0 * 333.6e3)


@pytest.mark.parametrize(("text", "where", "words"), [
    ("[ice]\nrho = 917.0\nc = 2100.0\nk = -2.14\n", "ice.k", "greater than 0"),
    ("[cavity]\ncenter = [0.015, 0.0, 0.0]\n", "cavity.center", "outside the block"),
    ("[cavity]\nradius = 0.03\n", "cavity.radius", "outside the block"),
    ("[air]\ntemperature = -5.0\n[cavity]\ntemperature = 0.0\n", "air.temperature",
     "nothing melts"),
    ("[grid]\ncells = 8\n[cavity]\nradius = 0.0175\n", "grid.cells", "too coarse"),
    ("[time]\ndt = 5.0\n", "time.dt", "stability limit"),
    ("[block]\ntemperature = 3.0\n", "block.temperature", "less than or equal to 0"),
    ("[air]\nhh = 3.0\n", "air.hh", "unknown key"),
])
def test_unphysical_values_are_one_line_errors_naming_the_key(tmp_path, text, where, words):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(CaseError) as info:
        load_case(path)
    message = str(info.value)
    assert "\n" not in message
    assert f"{where}: " in message and words in message
    assert message.startswith(str(path) + ":")  # file and line
    result = CliRunner().invoke(app, ["stefan", "run", str(path), "-o", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert not (tmp_path / "o").exists()


def test_surfaces_are_closed_and_nested():
    case = case_from_dict({"grid": {"cells": 16}})
    H, kind, cavity, frame = initial_state(case)
    outer, inner = extract_surfaces(H, kind, case.properties, frame, smoothing=10)
    assert outer.is_watertight and inner.is_watertight
    assert outer.volume > 0 and inner.volume > 0
    # volumes near the cells' (a staircase smoothed, Taubin keeps volume)
    assert inner.volume == pytest.approx(cavity.sum() * case.dx ** 3, rel=0.15)
    assert outer.volume == pytest.approx(kind.sum() * case.dx ** 3, rel=0.1)
    # the inner surface lies inside the outer one
    assert outer.contains(inner.vertices[::7]).all()
    # the block stands on the table at y = 0
    assert outer.bounds[0][1] == pytest.approx(0.0, abs=case.dx)


def test_run_writes_everything_and_resumes(tmp_path):
    case_path = tmp_path / "small.toml"
    case_path.write_text(SMALL)
    out = tmp_path / "out"
    case = load_case(case_path)
    calls = {"n": 0}

    def stop_after_first_save() -> bool:  # what Ctrl-C does: stop between chunks
        calls["n"] += 1
        return calls["n"] > 1

    first = run_case(case, SMALL, out, should_stop=stop_after_first_save)
    assert first.interrupted and not first.finished
    kept = sorted(p.name for p in (out / "fields").glob("*.npz"))
    assert kept  # what was computed is kept
    result = CliRunner().invoke(app, ["stefan", "run", str(case_path), "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    assert "resumed at t = " in result.output
    fresh = tmp_path / "fresh"
    full = run_case(case, SMALL, fresh)
    assert full.finished
    for name in ("state_0001.npz", "state_0002.npz"):
        with np.load(out / "fields" / name) as a, np.load(fresh / "fields" / name) as b:
            assert float(a["time"]) == float(b["time"])
            # the resumed run re-estimates surface normals on its first step only
            np.testing.assert_allclose(a["H"], b["H"], rtol=0, atol=1e-3 * 3.06e8)
    rows = list(csv.DictReader((out / "series.csv").open()))
    assert [float(r["time_s"]) for r in rows] == [0.0, 300.0, 600.0]
    assert float(rows[-1]["ice_volume_cm3"]) < float(rows[0]["ice_volume_cm3"])
    # heat in and heat drained are columns; their difference is the enthalpy gained
    heat_in = [float(r["heat_in_J"]) for r in rows]
    assert heat_in[0] == 0.0 and heat_in[1] > 0.0 and heat_in[2] > heat_in[1]
    assert all(float(r["heat_drained_J"]) >= 0.0 for r in rows)
    assert float(rows[-1]["condensed_cm3"]) == pytest.approx(
        1e6 * condensed_volume(case, heat_in[-1]), rel=1e-9)
    for i in range(3):
        mesh = trimesh.load(out / "surfaces" / f"outer_{i:04d}.ply")
        assert mesh.is_watertight
        scene = load_scene(out / "scenes" / f"frame_{i:04d}.toml")
        assert [o.name for o in scene.objects][-4:] == ["ice", "water", "void bubble",
                                                        "meltwater"]
    assert (out / "series.png").stat().st_size > 1000
    summary = json.loads((out / "summary.json").read_text())
    assert summary["breach_time_s"] is None
    assert abs(summary["energy_imbalance_J"]) < 1e-9 * summary["heat_in_J"]


@pytest.mark.parametrize("action", ["stop", "drain"])
def test_breach_stops_or_drains(tmp_path, action):
    # a thin shell (2 cells) and a hot cavity: it opens within minutes
    data = {"grid": {"cells": 12}, "cavity": {"radius": 0.0135, "temperature": 60.0},
            "air": {"h": 30.0, "temperature": 30.0}, "time": {"end": 2400.0,
            "save_every": 600.0}, "breach": {"action": action}}
    case = Case.model_validate(data)
    result = run_case(case, "", tmp_path / action)
    assert result.breach_time is not None and result.breach_time < 2400.0
    rows = list(csv.DictReader((tmp_path / action / "series.csv").open()))
    assert rows[0]["breach_time_s"] == ""
    assert float(rows[-1]["breach_time_s"]) == pytest.approx(result.breach_time)
    if action == "stop":
        assert result.end_time == pytest.approx(result.breach_time)
    else:
        assert result.end_time == pytest.approx(2400.0)
        with np.load(sorted((tmp_path / action / "fields").glob("*.npz"))[-1]) as z:
            f, kind = z["liquid_fraction"], z["kind"]
            assert not ((kind == 1) & (f >= 1.0)).any()  # the cavity water has drained


def test_film_renders_one_frame_per_saved_time_with_the_time_in_it(tmp_path):
    import imageio.v3 as iio

    case_path = tmp_path / "tiny.toml"
    case_path.write_text("[grid]\ncells = 12\n[time]\nend = 600.0\nsave_every = 300.0\n")
    film = tmp_path / "melt.gif"
    result = CliRunner().invoke(app, ["stefan", "film", str(case_path), "-o", str(film),
                                      "-W", "96", "-H", "72", "-q"])
    assert result.exit_code == 0, result.output
    frames = iio.imread(film, index=None)
    assert frames.shape[:3] == (3, 72, 96)
    # the void's bubble is keyed per frame: its radius from the series (cavity less water)
    import tomllib

    text = tomllib.loads((tmp_path / "melt_stefan" / "film.toml").read_text())
    tracks = {t["path"]: [k[1] for k in t["keys"]] for t in text["animation"]["tracks"]}
    radii = tracks["objects[void bubble].radius"]
    rows = list(csv.DictReader((tmp_path / "melt_stefan" / "series.csv").open()))
    for r, row in zip(radii, rows, strict=True):
        void = float(row["cavity_volume_cm3"]) - float(row["water_volume_cm3"])
        assert r == pytest.approx(max(1e-4, (3 * void / (4 * math.pi)) ** (1 / 3)), abs=1e-5)
    assert radii[0] == 1e-4 and radii[-1] > 0.1  # none at first, then 9 % of the melt
    # the meltwater's disc, 2.7 mm thick: pi (R² - 2²) 0.27 cm = the water that left the
    # block, (917/1000) (ice lost) - (cavity water gained), and the water condensed on it
    puddle = tracks["objects[meltwater].radius"]
    ice0, w0 = float(rows[0]["ice_volume_cm3"]), float(rows[0]["water_volume_cm3"])
    assert puddle[0] == 1e-4
    for r, row in list(zip(puddle, rows, strict=True))[1:]:
        water = (0.917 * (ice0 - float(row["ice_volume_cm3"]))
                 - (float(row["water_volume_cm3"]) - w0) + float(row["condensed_cm3"]))
        assert float(row["condensed_cm3"]) > 0.0
        assert math.pi * (r * r - 4.0) * 0.27 == pytest.approx(water, rel=1e-3)
    assert puddle[-1] > puddle[1] > 2.0
    raw = iio.imread(tmp_path / "melt_stefan" / "frames" / "0000.png")
    # the stamped time differs from the raw render in the top-left corner only
    diff = np.abs(frames[0][..., :3].astype(int) - raw[..., :3].astype(int)).sum(axis=2)
    assert diff[:16, :60].max() > 150  # white text
    assert diff[40:, 60:].mean() < 10  # only GIF palette quantisation there
