"""The room's radiation and condensation (against the quoted estimates and the handbooks'
numbers), the three further 1-D cases, thin grids on the serial kernel whatever their
orientation, and the film's measured absorption and anti-aliasing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whitted.scene import load_scene
from whitted.stefan import room
from whitted.stefan.case import case_from_dict
from whitted.stefan.properties import Properties
from whitted.stefan.scene import WATER_ABSORPTION_CM, still_life_scene
from whitted.stefan.solver import EnthalpySolver, Faces
from whitted.stefan.validate import convective_slab, more_case_rows


def test_saturation_pressure_matches_the_handbook():
    # CRC Handbook, vapour pressure of water: 0.6113 kPa at 0 °C, 3.1699 kPa at 25 °C
    assert room.saturation_pressure(0.0) == pytest.approx(611.3, rel=1e-3)
    assert room.saturation_pressure(25.0) == pytest.approx(3169.9, rel=2e-3)


def test_radiation_and_condensation_at_the_default_room():
    # a 0 °C surface in 25 °C surroundings receives about 128 W/m² by radiation
    # (eps sigma (298.15^4 - 273.15^4) with eps = 0.97) against 500 W/m² by convection (h 20)
    film = room.outer_film(25.0, 20.0, relative_humidity=0.0)
    assert film.radiation == pytest.approx(0.97 * 5.670374419e-8 * (298.15**4 - 273.15**4))
    assert film.radiation == pytest.approx(128.4, abs=0.5)
    # condensation: about +19 % of the convective heat at 30 % humidity, +62 % at 50 %
    for rh, share in ((0.3, 0.19), (0.5, 0.62)):
        q = room.outer_film(25.0, 20.0, relative_humidity=rh).condensation
        assert q / 500.0 == pytest.approx(share, rel=0.1)
    # the effective film carries the sum exactly into a surface at 0 °C
    f = room.outer_film(25.0, 20.0, relative_humidity=0.3)
    assert f.h * (f.temperature - 0.0) == pytest.approx(f.convection + f.radiation
                                                        + f.condensation, rel=1e-12)
    # dry, cold air: the ice sublimates/evaporates (negative), no radiation when eps = 0
    assert room.outer_film(-10.0, 10.0, relative_humidity=0.1).condensation < 0
    assert room.outer_film(25.0, 20.0, emissivity=0.0).radiation == 0.0


def test_a_slab_in_the_room_recedes_at_the_total_flux():
    # a slab of ice at 0 °C recedes at q t / (rho_i L) with q the three parts together
    case = case_from_dict({})
    air = case.solver_air()
    slab = convective_slab(h=air.h, air=air.temperature)
    q = 500.0 + 128.4 + room.condensation_flux(20.0, 25.0, 0.3)
    expected = q * 3000.0 / (917.0 * 333.6e3) * 1e3
    assert slab["expected_mm"] == pytest.approx(expected, rel=2e-3)
    assert slab["receded_mm"] == pytest.approx(expected, rel=1e-3)


def test_three_more_neumann_cases_converge():
    rows = more_case_rows(t_end=600.0, cells_mm=(0.5, 0.25))
    # exact fronts after 600 s (similarity constants root-found): 6.7523, 1.2957, 5.5566 mm
    exact = [r["exact_mm"] for r in rows[::2]]
    assert exact == pytest.approx([6.7523, 1.2957, 5.5566], abs=2e-4)
    for coarse, fine in zip(rows[::2], rows[1::2], strict=True):
        assert abs(fine["error_pct"]) < abs(coarse["error_pct"])
        assert 0.7 < fine["order"] < 1.6  # first order
        assert abs(fine["error_pct"]) < 4.0
        assert abs(fine["energy_rel"]) < 1e-12


@pytest.mark.parametrize("axis", [0, 1])
def test_a_line_along_x_or_y_runs_like_one_along_z(axis):
    props = Properties()
    results = {}
    for a in (axis, 2):
        shape = [1, 1, 1]
        shape[a] = 200
        H = np.full(shape, props.enthalpy(-10.0, False))
        faces = Faces.adiabatic().set(("x-", "y-", "z-")[a], math.inf, 10.0)
        solver = EnthalpySolver(H, np.ones(shape, np.uint8), 5e-4, props, faces=faces)
        assert not solver.parallel and solver._Hp.shape[2] == 202  # stored along z, serial
        solver.advance(60.0)
        assert solver.H.shape == tuple(shape)
        results[a] = solver.H.ravel().copy()
    assert np.array_equal(results[axis], results[2])  # the same bits


def test_the_film_scene_has_measured_absorption_and_four_samples(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(still_life_scene(None, None, 60.0))
    scene = load_scene(path)
    assert scene.render.samples >= 4
    text = path.read_text()
    assert "measured" in text and "exaggerated" not in text
    assert f"{WATER_ABSORPTION_CM[0]:.4g}" in text
    boosted = still_life_scene(None, None, 60.0, absorption_boost=3.0)
    assert "exaggerated x3" in boosted
    # caustics on by default (the light the ice focuses on the table), 5/3 photons
    # a pixel (480 x 360: 288,000; 400 x 300: 200,000), off with 0
    assert scene.render.caustics.photons == 288_000
    small = tmp_path / "small.toml"
    small.write_text(still_life_scene(None, None, 60.0, width=400, height=300))
    assert load_scene(small).render.caustics.photons == 200_000
    path.write_text(still_life_scene(None, None, 60.0, caustic_photons=0))
    assert load_scene(path).render.caustics.photons == 0


def test_condensed_water_joins_the_puddle():
    # a 0 °C surface in the default room (h 20, 25 °C): condensation brings its share s of the
    # heat; Q J of heat melt Q / (rho_w L) of water and condense s Q / (rho_w L_v)
    from whitted.stefan.room import L_VAPORISATION
    from whitted.stefan.run import condensed_volume, meltwater

    for rh, low, high in ((0.3, 0.012, 0.02), (0.7, 0.045, 0.07)):
        case = case_from_dict({"air": {"relative_humidity": rh}})
        film = room.outer_film(25.0, 20.0, emissivity=0.97, relative_humidity=rh)
        share = film.condensation / (film.convection + film.radiation + film.condensation)
        assert case.condensation_share() == pytest.approx(share, rel=1e-12)
        q = 1.0e4  # J
        melt = q / (1000.0 * 333.6e3)
        cond = condensed_volume(case, q)
        assert cond == pytest.approx(share * q / (1000.0 * L_VAPORISATION), rel=1e-12)
        # about 5 % more water at 70 % humidity (1.6 % at 30 %)
        assert low < cond / melt < high
        assert meltwater(case, (1e-5, 0.0), (1e-5 - melt * 1000 / 917, 0.0), cond) == \
            pytest.approx(melt + cond, rel=1e-9)
    dry = case_from_dict({"air": {"relative_humidity": 0.0}})
    assert condensed_volume(dry, 1.0e4) == 0.0
    auto = case_from_dict({"air": {"h": "auto", "relative_humidity": 0.7}})
    assert 0.0 < auto.condensation_share() < 1.0
