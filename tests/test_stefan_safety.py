"""The Stefan run's safety: the run folder is whitted's only when whitted made it, estimates
before work, strict types, resume after 10,000 saves, the drain-mode film to the end of the
run, the shell and cavity measures; and fuzzing of case files."""

from __future__ import annotations

import csv
import math
import string
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from whitted.cli.main import app
from whitted.errors import WhittedError
from whitted.stefan import budget, folder
from whitted.stefan.case import Case, CaseError, case_from_dict, load_case
from whitted.stefan.geometry import initial_state
from whitted.stefan.measures import measure
from whitted.stefan.run import _latest_state, film_frames, run_case, state_files
from whitted.stefan.solver import EnthalpySolver

REPO = Path(__file__).resolve().parents[1]
TINY = "[grid]\ncells = 12\n[time]\nend = 300.0\nsave_every = 300.0\n[surfaces]\nsmoothing = 2\n"


def _run(args: list[str]):
    return CliRunner().invoke(app, ["stefan", *args])


def _one_line_error(result, *words: str) -> str:
    assert result.exit_code == 2, result.output
    text = result.output.strip()
    assert "\n" not in text and "Traceback" not in text and "internal" not in text
    for w in words:
        assert w in text, text
    return text


# --- item 3: a run folder is whitted's only when whitted made it ---------------------------
@pytest.mark.parametrize("name", ["case.toml", "series.csv", "summary.json", "series.png"])
def test_a_folder_whitted_did_not_make_keeps_its_files(tmp_path, name):
    case = tmp_path / "tiny.toml"
    case.write_text(TINY)
    proj = tmp_path / "proj"
    proj.mkdir()
    (proj / name).write_text("the user's own")
    for fresh in ([], ["--fresh"]):
        _one_line_error(_run(["run", str(case), "-o", str(proj), "-q", *fresh]), name,
                        "did not write")
        assert (proj / name).read_text() == "the user's own"
        assert sorted(p.name for p in proj.iterdir()) == [name]  # nothing written


def test_fresh_removes_only_what_whitted_wrote(tmp_path):
    case = tmp_path / "tiny.toml"
    case.write_text(TINY)
    proj = tmp_path / "proj"
    assert _run(["run", str(case), "-o", str(proj), "-q"]).exit_code == 0
    assert folder.is_marked(proj)
    mine = {proj / "scenes" / "my_scene.toml": "mine", proj / "fields" / "notes.txt": "mine",
            proj / "surfaces" / "keep.ply": "mine", proj / "README": "mine"}
    for path, text in mine.items():
        path.write_text(text)
    (proj / "scenes" / "sub").mkdir()  # a folder of the user's: IsADirectoryError before
    (proj / "scenes" / "sub" / "x.toml").write_text("mine")
    result = _run(["run", str(case), "-o", str(proj), "-q", "--fresh"])
    assert result.exit_code == 0, result.output
    assert "resumed" not in result.output
    for path, text in mine.items():
        assert path.read_text() == text
    assert (proj / "scenes" / "sub" / "x.toml").read_text() == "mine"
    assert [p.name for p in state_files(proj / "fields")] == ["state_0000.npz",
                                                               "state_0001.npz"]


def test_a_folder_in_the_way_of_a_file_the_run_writes_is_an_error(tmp_path):
    case = tmp_path / "tiny.toml"
    case.write_text(TINY)
    proj = tmp_path / "proj"
    assert _run(["run", str(case), "-o", str(proj), "-q"]).exit_code == 0
    (proj / "scenes" / "frame_0000.toml").unlink()
    (proj / "scenes" / "frame_0000.toml").mkdir()
    _one_line_error(_run(["run", str(case), "-o", str(proj), "-q", "--fresh"]),
                    "frame_0000.toml", "in the way")
    assert (proj / "fields" / "state_0001.npz").exists()  # nothing removed


def test_unmarked_subfolders_and_a_file_as_folder_are_refused(tmp_path):
    case = tmp_path / "tiny.toml"
    case.write_text(TINY)
    proj = tmp_path / "proj"
    (proj / "scenes").mkdir(parents=True)
    (proj / "scenes" / "frame_0000.toml").write_text("mine")
    _one_line_error(_run(["run", str(case), "-o", str(proj), "--fresh", "-q"]), "scenes")
    assert (proj / "scenes" / "frame_0000.toml").read_text() == "mine"
    afile = tmp_path / "afile"
    afile.write_text("x")
    _one_line_error(_run(["run", str(case), "-o", str(afile), "-q"]), "not a folder")
    # the case file inside the output folder as case.toml: never written over
    inside = tmp_path / "inside"
    inside.mkdir()
    (inside / "case.toml").write_text(TINY)
    _one_line_error(_run(["run", str(inside / "case.toml"), "-o", str(inside), "-q"]),
                    "case.toml")


# --- item 11: estimates before work ---------------------------------------------------------
@pytest.mark.parametrize(("text", "key", "words"), [
    ("[grid]\ncells = 512\n", "grid.cells", ["limit"]),
    ("[time]\nend = 1e7\n", "time.end", ["steps", "limit", "--allow-large"]),
    ("[time]\nend = 3600.0\nsave_every = 0.001\n", "time.save_every", ["saved times"]),
    ("[ice]\nrho = 1e-300\nc = 2100.0\nk = 2.14\n", "ice.rho", ["documented range"]),
    ("latent_heat = 1e-300\n", "latent_heat", ["documented range"]),
    ("[ice]\nrho = 1e308\nc = 1e308\nk = 1e308\n", "ice.rho", ["documented range"]),
    ("[ice]\nrho = 917.0\nc = 2100.0\nk = 2.14e6\n", "ice.k", ["documented range"]),
    ("[block]\nsize = [4e-5, 4e-5, 4e-5]\nedge_radius = 0.0\n[cavity]\nradius = 1e-5\n",
     "block.size[0]", ["greater than or equal"]),
])
def test_runaway_cases_are_refused_before_any_work(tmp_path, text, key, words):
    path = tmp_path / "big.toml"
    path.write_text(text)
    out = tmp_path / "o"
    message = _one_line_error(_run(["run", str(path), "-o", str(out), "-q"]), f"{key}: ",
                              *words)
    assert message.startswith(f"error: {path}") or str(path) in message
    assert not out.exists()


def test_the_estimate_of_the_default_case_and_the_allow_large_option(tmp_path):
    case = load_case(REPO / "examples" / "stefan" / "hollow_ice.toml")
    e = budget.estimate(case)
    assert e.shape == (50, 50, 50) and e.cells == 125_000
    # dt = 0.9 x the limit of 0.833 mm cells, C dx² / (6 a): with cavity.convection the
    # water's largest effective conductivity (3 Nu k / pi² of 20 °C water, 1.84 W/mK) is below
    # ice's 2.14, so an ice cell's faces (a = k_i; to water 2 k_i k_eff / (k_i + k_eff) = 1.98)
    # set the step, as without convection
    k_eff = case.solver_properties().water.k
    assert k_eff == pytest.approx(1.84, rel=0.01)
    assert e.dt == pytest.approx(0.9 * 917 * 2100 * (0.04 / 48) ** 2 / (6 * 2.14), rel=0.02)
    plain = case.model_copy(update={"cavity": case.cavity.model_copy(
        update={"convection": False})})
    assert budget.estimate(plain).dt == pytest.approx(e.dt, rel=1e-12)
    assert e.steps == math.ceil(3600 / e.dt) and e.saves == 31
    long = case.model_copy(update={"time": case.time.model_copy(update={"end": 1e7})})
    with pytest.raises(CaseError, match="time.end"):
        budget.check(long)
    assert budget.check(long, allow_large=True).steps > budget.SOFT_LIMITS["steps"]
    huge = case.model_copy(update={"grid": case.grid.model_copy(update={"cells": 20000})})
    with pytest.raises(CaseError, match="grid.cells.*memory"):
        budget.check(huge, allow_large=True)  # the machine's memory is a hard limit


# --- item 12: strict types ------------------------------------------------------------------
@pytest.mark.parametrize(("text", "key"), [
    ("[air]\nh = true\n", "air.h"),
    ('[ice]\nrho = "917"\nc = 2100.0\nk = 2.14\n', "ice.rho"),
    ('[grid]\ncells = "16"\n', "grid.cells"),
    ("[grid]\ncells = 16.0\n", "grid.cells"),
    ("[grid]\ncells = true\n", "grid.cells"),
    ("[block]\nsize = [0.04, true, 0.04]\n", "block.size[1]"),
    ('[time]\nend = "600"\n', "time.end"),
    ("[surfaces]\nsmoothing = 2.5\n", "surfaces.smoothing"),
])
def test_case_values_are_typed_strictly(tmp_path, text, key):
    path = tmp_path / "typed.toml"
    path.write_text(text)
    with pytest.raises(CaseError) as info:
        load_case(path)
    assert f"{key}: " in str(info.value)


def test_integers_are_still_numbers():
    case = case_from_dict({"air": {"h": 20, "temperature": 25}, "time": {"end": 600}})
    assert case.air.h == 20.0 and isinstance(case.air.h, float)


# --- item 17: resume after more than 10,000 saves -------------------------------------------
def test_the_newest_save_is_found_by_number(tmp_path):
    fields = tmp_path / "fields"
    fields.mkdir()
    for index in (9998, 9999, 10000, 10001):
        np.savez(fields / f"state_{index:04d}.npz", digest="abc", index=index)
    (fields / "state_10002.npz").write_bytes(b"damaged")  # skipped
    np.savez(fields / "state_10003.npz", digest="other", index=10003)  # another case
    assert _latest_state(fields, "abc").name == "state_10001.npz"
    assert [p.name for p in state_files(fields)][-3:] == ["state_10001.npz",
                                                          "state_10002.npz",
                                                          "state_10003.npz"]


# --- item 18: drain mode films to the end ---------------------------------------------------
def test_drain_mode_film_goes_on_after_the_breach_with_the_outer_surface(tmp_path):
    # a 2-cell shell (under check()'s minimum, as test_breach_stops_or_drains) opens early
    case = Case.model_validate({"grid": {"cells": 12}, "cavity": {"radius": 0.0135,
                           "temperature": 60.0}, "air": {"h": 30.0, "temperature": 30.0},
                           "time": {"end": 1800.0, "save_every": 600.0},
                           "breach": {"action": "drain"}, "surfaces": {"smoothing": 2}})
    out = tmp_path / "drain"
    result = run_case(case, "", out)
    assert result.breach_time is not None and result.breach_time < 1800.0
    frames = film_frames(out)
    # to the end of the run (at 2400 s this block would be gone: 0 cm3 of ice, no surface)
    assert [f.time for f in frames] == [0.0, 600.0, 1200.0, 1800.0]
    assert frames[0].inner is not None
    after = [f for f in frames if f.time > result.breach_time]
    assert after and all(f.inner is None for f in after)  # the cavity has drained


# --- item 19: the shell and the cavity measure the physical quantities ----------------------
def test_shell_thins_and_cavity_grows_steadily_to_the_breach():
    data = tomllib.loads((REPO / "examples" / "stefan" / "hollow_ice.toml").read_text())
    data["grid"]["cells"] = 16
    case = case_from_dict(data)
    H, kind, cavity, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.properties, faces=case.solver_faces(),
                            air=case.solver_air())
    initial = float(cavity.sum()) * case.dx ** 3
    rows = []
    t = 0.0
    while not solver.breached and t < 3600.0:
        t += 60.0
        solver.advance(t)
        rows.append(measure(solver.H, solver.kind, solver.dx, case.properties, solver.time,
                            initial, solver.breached))
    assert solver.breached
    shells = [m.min_shell for m in rows if not m.breached]
    cavities = [m.cavity_volume for m in rows if not m.breached and m.time >= 600.0]
    assert len(shells) > 20
    # the thinnest ice between the cavity's water and the air only shrinks ...
    assert all(b <= a + 1e-12 for a, b in zip(shells, shells[1:], strict=False))
    # ... from about the 5 mm the geometry leaves (20 - 12 - 3 mm off centre) ...
    assert 0.0025 < shells[0] < 0.0055
    # ... to under a cell at the breach, in steps under a cell per minute
    assert shells[-1] < case.dx
    assert max(a - b for a, b in zip(shells, shells[1:], strict=False)) < 0.5 * case.dx
    # once the cavity water is at 0 °C it only melts its wall: the volume never falls
    assert all(b >= a - 1e-12 for a, b in zip(cavities, cavities[1:], strict=False))


# --- fuzzing: case files --------------------------------------------------------------------
KEYS = {
    "": ["latent_heat", "ice", "water", "block", "cavity", "air", "table", "grid", "time",
         "breach", "surfaces", "bogus"],
    "ice": ["rho", "c", "k"], "water": ["rho", "c", "k"],
    "block": ["size", "edge_radius", "temperature"],
    "cavity": ["shape", "radius", "size", "center", "temperature", "convection"],
    "air": ["temperature", "h", "emissivity", "relative_humidity"],
    "table": ["contact", "temperature", "h"],
    "grid": ["cells"], "time": ["end", "save_every", "dt", "cfl"], "breach": ["action"],
    "surfaces": ["smoothing", "keep"],
}
scalars = st.one_of(
    st.booleans(), st.integers(min_value=-2**70, max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, 1e300, 1e308, 917.0, 0.04, 0.012, 3600.0, 8, 12, 512]),
    st.text(alphabet=string.printable, max_size=8),
    st.sampled_from(["sphere", "box", "stop", "drain", "adiabatic", "conducting", "917",
                     "auto", "flow", "effective", "off"]))
values = st.one_of(scalars, st.lists(scalars, max_size=4))


@st.composite
def case_dicts(draw):
    data = {}
    for section in draw(st.lists(st.sampled_from(KEYS[""]), max_size=5, unique=True)):
        if section in KEYS:
            data[section] = {k: draw(values) for k in draw(st.lists(
                st.sampled_from(KEYS[section]), max_size=3, unique=True))}
        else:
            data[section] = draw(values)
    return data


FUZZ = settings(max_examples=250, deadline=None, database=None, derandomize=True,
                suppress_health_check=list(HealthCheck))


@FUZZ
@given(case_dicts())
def test_fuzz_case_dicts_load_or_give_one_line(data):
    try:
        case = case_from_dict(data, file="fuzz.toml")
    except CaseError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("fuzz.toml")
        return
    try:
        e = budget.check(case, allow_large=False)
    except CaseError as exc:
        assert "\n" not in str(exc) and "limit" in str(exc) or "memory" in str(exc)
        return
    assert e.cells > 0 and e.steps > 0 and e.dt > 0 and math.isfinite(e.dt)


@FUZZ
@given(st.text(alphabet=string.printable, max_size=120))
def test_fuzz_case_text_loads_or_gives_one_line(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "case.toml"
    path.write_text(text)
    try:
        load_case(path)
    except WhittedError as exc:
        assert "\n" not in str(exc)


def test_series_of_a_run_is_read_back(tmp_path):
    case = tmp_path / "tiny.toml"
    case.write_text(TINY)
    assert _run(["run", str(case), "-o", str(tmp_path / "p"), "-q"]).exit_code == 0
    rows = list(csv.DictReader((tmp_path / "p" / "series.csv").open()))
    assert float(rows[0]["min_shell_mm"]) > float(rows[-1]["min_shell_mm"]) > 0
