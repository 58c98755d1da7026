"""Natural convection: the air's h per face (``air.h = "auto"``) and the cavity
water's effective conductivity (``cavity.convection``), each against numbers worked by hand
from the published correlation (docs/stefan.md, "Natural convection")."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from whitted.stefan import convection as cv
from whitted.stefan.case import CaseError, case_from_dict
from whitted.stefan.properties import Properties
from whitted.stefan.solver import Air, EnthalpySolver


def test_auto_h_of_the_default_block_by_hand():
    # 4 cm block, surface 0 °C, air 25 °C: film 12.5 °C = 285.65 K; Incropera Table A.4
    # between 250 K (nu 11.44e-6, k 22.3e-3, alpha 15.9e-6, Pr 0.720) and 300 K (15.89e-6,
    # 26.3e-3, 22.5e-6, 0.707), weight 0.713: nu 14.613e-6, k 25.152e-3, alpha 20.606e-6,
    # Pr 0.7107. Ra_L = 9.80665 (25/285.65) 0.04³ / (nu alpha) = 1.824e5.
    ra, pr, k = cv.rayleigh_air(0.0, 25.0, 0.04)
    assert ra == pytest.approx(1.824e5, rel=2e-3)
    assert pr == pytest.approx(0.7107, abs=1e-4) and k == pytest.approx(25.152e-3, rel=1e-4)
    # Churchill & Chu: psi = (1 + (0.492/0.7107)^(9/16))^(8/27) = 1.1928,
    # Nu = (0.825 + 0.387 Ra^(1/6) / psi)² = 10.68, h = Nu k / L = 6.72 W/m²K
    assert cv.nusselt_vertical(1.824e5, 0.7107) == pytest.approx(10.68, rel=3e-3)
    h = cv.face_coefficients((0.04, 0.04, 0.04), 25.0)
    assert h[0] == h[1] == h[4] == h[5] == pytest.approx(6.72, rel=3e-3)
    # top (a cold plate's upper face, stable): L = A/P = 0.01 m, Ra = 1.824e5 / 64 = 2850,
    # Nu = 0.52 Ra^(1/5) = 2.553, h = 6.42; the bottom (its rising side, under overhangs):
    # Nu = 0.54 Ra^(1/4) = 3.946, h = 9.92 W/m²K
    assert h[3] == pytest.approx(6.42, rel=3e-3)
    assert h[2] == pytest.approx(9.92, rel=3e-3)
    # a warm plate swaps them; no temperature difference, no convection
    warm = cv.face_coefficients((0.04, 0.04, 0.04), 0.0, t_surface=25.0)
    assert warm[3] == pytest.approx(h[2], rel=0.02) and warm[2] == pytest.approx(h[3], rel=0.02)
    assert cv.face_coefficients((0.04, 0.04, 0.04), 5.0, t_surface=5.0) == (0.0,) * 6


def test_still_air_gives_the_sides_less_heat_than_the_old_h_20():
    # docs/stefan.md, "Why still air melts the block later": into ice at 0 °C in the default
    # room (25 °C, eps 0.97, 30 % humidity) the auto sides get 6.72 x 25 = 168 W/m² by
    # convection, 128.4 by radiation, 30.5 by condensation (h_m follows h): 327 W/m²; h = 20
    # gets 500 + 128.4 + 90.8 = 719; the first round's h = 20 alone 500. The hand estimate of
    # the breach, (3.9 + 0.19) mm x rho_i L / q: 41.7, 29.0 and 63.8 min.
    from whitted.stefan.room import outer_film

    side = cv.face_coefficients((0.04, 0.04, 0.04), 25.0)[0]
    fluxes = {}
    for name, h, eps, rh in (("old", 20.0, 0.0, 0.0), ("h20", 20.0, 0.97, 0.3),
                             ("auto", side, 0.97, 0.3)):
        f = outer_film(25.0, h, emissivity=eps, relative_humidity=rh)
        fluxes[name] = f.convection + f.radiation + f.condensation
        assert f.h * (f.temperature - 0.0) == pytest.approx(fluxes[name], rel=1e-12)
    assert fluxes["old"] == pytest.approx(500.0, rel=1e-12)
    assert fluxes["h20"] == pytest.approx(719.2, abs=0.3)
    assert fluxes["auto"] == pytest.approx(326.9, abs=0.3)
    # at 70 % humidity the three parts are of one size, as Neufeld, Goldstein & Worster (2010)
    # found for ice melting in warm still air: 168 convection, 167 condensation, 128 radiation
    humid = outer_film(25.0, side, relative_humidity=0.7)
    assert humid.condensation == pytest.approx(humid.convection, rel=0.01)
    assert humid.radiation == pytest.approx(128.4, abs=0.1)
    minutes = {k: 4.09e-3 * 917.0 * 333.6e3 / q / 60.0 for k, q in fluxes.items()}
    assert [round(minutes[k], 1) for k in ("old", "h20", "auto")] == [41.7, 29.0, 63.8]


def test_lloyd_moran_switches_to_the_turbulent_law_above_1e7():
    assert cv.nusselt_horizontal(1e6, rising=True) == pytest.approx(0.54 * 1e6 ** 0.25)
    assert cv.nusselt_horizontal(1e9, rising=True) == pytest.approx(0.15 * 1e3)


def test_kell_density_has_its_maximum_at_3_98_c():
    # Kell (1975): 999.8395 kg/m³ at 0 °C, the maximum 999.972 at 3.98 °C, 998.204 at 20 °C,
    # 958.365 at 100 °C (CRC Handbook: 999.84, 999.97, 998.21, 958.37)
    best = minimize_scalar(lambda t: -cv.water_density(t), bounds=(0.0, 10.0),
                           method="bounded", options={"xatol": 1e-6})
    assert best.x == pytest.approx(3.98, abs=0.01)
    assert cv.water_density(best.x) == pytest.approx(999.972, abs=1e-3)
    for t, rho in ((0.0, 999.8395), (20.0, 998.204), (100.0, 958.365)):
        assert cv.water_density(t) == pytest.approx(rho, abs=2e-3)
    # Vogel viscosity: 1.0016 mPa s at 20 °C, 1.7914 at 0 °C (CRC), within 1 %
    assert cv.water_viscosity(20.0) == pytest.approx(1.0016e-3, rel=0.01)
    assert cv.water_viscosity(0.0) == pytest.approx(1.7914e-3, rel=0.015)


def test_catton_enclosure_nusselt_and_the_density_inversion():
    # Catton: Nu = 0.18 (Pr/(0.2+Pr) Ra)^0.29; Ra = 1e6, Pr = 7: 0.18 (9.722e5)^0.29 = 9.81
    assert cv.nusselt_enclosure(1e6, 7.0) == pytest.approx(9.81, rel=2e-3)
    assert cv.nusselt_enclosure(500.0, 7.0) == 1.0  # below its range: conduction
    # the default cavity (24 mm, water 20 °C, walls 0 °C): the densest water present (3.98 °C)
    # against the bulk, Delta rho / rho = (999.972 - 998.204) / 999.3 = 1.769e-3 (the wall's
    # 0 °C water alone: 1.636e-3, Ra 1.28e6), nu = 1.3e-6 at 10 °C, alpha = 0.56 / 4.22e6:
    # Ra = 1.38e6, Nu = 0.18 (0.972 Ra)^0.29 = 10.80
    ra, pr = cv.rayleigh_water(20.0, 0.024, 0.56, 4.22e6)
    assert ra == pytest.approx(1.38e6, rel=0.01)
    assert cv.nusselt_enclosure(ra, pr) == pytest.approx(10.80, rel=0.01)


def test_the_sphere_mapping_gives_the_correlations_wall_coefficient():
    # Catton's Nu is a wall-to-wall flux over k dT / L; the bulk halfway between: h = 2 Nu k / L,
    # 2 x 10.80 x 0.56 / 0.024 = 504 W/m²K in the default cavity (493 with the 0 °C wall's
    # density difference alone)
    h = cv.wall_coefficient(20.0, 0.024, 0.56, 4.22e6)
    assert h == pytest.approx(504.0, rel=0.01)
    # a conducting sphere's mean temperature decays in its slowest mode at pi² alpha / R²:
    # rho c V dT/dt = -h A T gives h = (R / 3) pi² k / R² = (2 pi² / 3) k / D
    k_eff = cv.water_conductivity(20.0, 0.024, 0.56, 4.22e6)
    assert 2.0 * np.pi ** 2 / 3.0 * k_eff / 0.024 == pytest.approx(h, rel=1e-12)
    assert k_eff == pytest.approx(0.56 * 3.0 * 10.80 / np.pi ** 2, rel=0.01)  # 1.84 W/mK
    # the old mapping (k_eff = k Nu = 5.91 W/mK) gave (2 pi²/3) k Nu / D = 1621 W/m²K, 3.3x
    assert 2.0 * np.pi ** 2 / 3.0 * 0.56 * 10.56 / 0.024 == pytest.approx(1621.0, rel=0.01)
    # weak convection never falls below conduction (k_eff >= k)
    assert cv.water_conductivity(0.3, 0.024, 0.56, 4.22e6) == 0.56


def test_the_density_maximum_leaves_no_false_zero():
    # rho(0 °C) = rho(bulk) at 8.14 °C: |rho(wall) - rho(bulk)| vanished there; the 3.98 °C
    # water between them is denser than both by 0.132 kg/m³, and that drives the flow
    zero = minimize_scalar(lambda t: abs(cv.water_density(t) - cv.water_density(0.0)),
                           bounds=(5.0, 10.0), method="bounded")
    assert zero.x == pytest.approx(8.14, abs=0.01)
    span = cv.density_span(0.0, zero.x)
    assert span == pytest.approx(cv.water_density(3.983) - cv.water_density(0.0), rel=1e-6)
    assert span == pytest.approx(0.132, abs=0.002)
    # the buoyancy never vanishes between 0.5 and 20 °C: k_eff above k all along from 2 °C
    temps = np.linspace(0.5, 20.0, 400)
    drho = np.array([cv.density_span(0.0, t) for t in temps])
    assert (drho > 0.0).all()
    assert np.all(np.diff(drho) >= 0.0)  # never falls as the bulk warms (flat from 3.98 to 8.14)
    k = np.array([cv.water_conductivity(t, 0.024, 0.56, 4.22e6) for t in temps])
    assert (k[temps >= 2.0] > 0.56).all()
    assert cv.water_conductivity(zero.x, 0.024, 0.56, 4.22e6) > 0.8  # was k (0.56) exactly
    # below 4 °C the range holds no maximum: the plain difference (the wall's water rises)
    assert cv.density_span(0.0, 3.0) == pytest.approx(cv.water_density(3.0)
                                                      - cv.water_density(0.0), rel=1e-12)


def test_catton_against_de_vahl_davis_benchmark():
    # de Vahl Davis (1983): the square cavity with differentially heated sides, Pr = 0.71,
    # mean Nu 1.118, 2.243, 4.519, 8.800 at Ra = 1e3 ... 1e6 (to 1 % or better). Catton's
    # formula 0.18 (Pr/(0.2 + Pr) Ra)^0.29 by hand: Ra Pr/(0.2 + Pr) = 7802, 78 022, 780 220
    # -> Nu 2.421, 4.721, 9.205: +7.9, +4.5, +4.6 %; at Ra = 1e3 (x = 780, below Catton's
    # 10^3) the model conducts (Nu 1, -10.6 %) where the formula would give 1.242 (+11.1 %).
    from whitted.stefan.validate import enclosure_rows

    rows = enclosure_rows()
    assert [r["ra"] for r in rows] == [1e3, 1e4, 1e5, 1e6]
    assert [r["in_range"] for r in rows] == [False, True, True, True]
    assert [round(r["error_pct"], 1) for r in rows] == [-10.6, 7.9, 4.5, 4.6]
    assert rows[0]["model"] == 1.0
    assert rows[0]["formula_error_pct"] == pytest.approx(11.06, abs=0.01)
    assert [round(r["model"], 3) for r in rows[1:]] == [2.421, 4.721, 9.205]
    # within its range the correlation is within 10 % of the benchmark, and above it
    assert all(0.0 < r["error_pct"] < 10.0 for r in rows if r["in_range"])


def _column(air: Air, t_end: float = 1200.0, cells: int = 20):
    """A line of ice at 0 °C along y with two air cells on top: only its y+ face meets air."""
    kind = np.ones((1, cells + 2, 1), dtype=np.uint8)
    kind[0, -2:, 0] = 0
    solver = EnthalpySolver(np.zeros(kind.shape), kind, 1e-3, Properties(), air=air)
    solver.advance(t_end)
    return solver


def test_the_air_film_is_chosen_per_face_direction():
    # only the y+ film acts on a column whose top meets the air: the same bits as a uniform
    # film of the y+ values, whatever the other directions carry (the time step given alike)
    uniform = _column(Air(20.0, 10.0))
    faces = ((50.0, 40.0), (50.0, 40.0), (50.0, 40.0), (10.0, 20.0), (50.0, 40.0), (50.0, 40.0))
    kind = np.ones((1, 22, 1), dtype=np.uint8)
    kind[0, -2:, 0] = 0
    per_face = EnthalpySolver(np.zeros(kind.shape), kind, 1e-3, Properties(),
                              air=Air(20.0, 50.0, faces), dt=uniform.dt)
    per_face.advance(1200.0)
    assert np.array_equal(per_face.H, uniform.H)
    # and it recedes at h dT t / (rho_i L) = 10 * 20 * 1200 / (917 * 333.6e3) = 0.7846 mm
    melted = float(uniform.liquid_fraction().sum() + (uniform.kind[0, :20, 0] == 0).sum())
    assert melted * 1e-3 == pytest.approx(10 * 20 * 1200 / (917 * 333.6e3), rel=2e-3)


def test_auto_h_and_convection_keys():
    auto = case_from_dict({"air": {"h": "auto"}, "grid": {"cells": 16}})
    air = auto.solver_air()
    hs = cv.face_coefficients(auto.block.size, 25.0)
    assert air.faces is not None and air.h == max(f[0] for f in air.faces)
    # each face's film is the room's (radiation, condensation) around its own h
    from whitted.stefan.room import outer_film

    film = outer_film(25.0, hs[3], relative_humidity=0.3)
    assert air.faces[3] == pytest.approx((film.h, film.temperature))
    # a number keeps the uniform film; convection off keeps the conduction-only water
    plain = case_from_dict({"cavity": {"convection": False}, "grid": {"cells": 16}})
    assert plain.solver_air().faces is None and plain.solver_convection() is None
    assert plain.solver_properties() == plain.properties
    on = case_from_dict({"grid": {"cells": 16}})
    assert on.solver_properties().water.k == pytest.approx(
        cv.largest_conductivity(20.0, 0.024, 0.56, 4.22e6))
    # "auto" in air at 0 °C without radiation: no film at all, and no division by zero
    still = case_from_dict({"air": {"h": "auto", "temperature": 0.0, "emissivity": 0.0},
                            "grid": {"cells": 16}})
    assert still.solver_air().h == 0.0
    with pytest.raises(CaseError, match='air.h.*use a number .* or "auto"'):
        case_from_dict({"air": {"h": "automatic"}})
    for bad in ({"air": {"h": True}}, {"air": {"h": 0.0}}, {"air": {"h": float("nan")}},
                {"cavity": {"convection": "yes"}}, {"cavity": {"convection": 1}}):
        with pytest.raises(CaseError):
            case_from_dict(bad)


def test_convection_keeps_the_energy_balance_and_melts_the_cavity_faster():
    # the default cavity's 20 °C water gives its heat to the wall: with k_eff (3 Nu / pi² about
    # 3.3 times k) in about a minute, by conduction alone in minutes (r²/(pi² alpha) = 110 s)
    from whitted.stefan.geometry import initial_state

    grown = {}
    for on in (False, True):
        case = case_from_dict({"grid": {"cells": 16}, "cavity": {"convection": on}})
        H, kind, cavity, _ = initial_state(case)
        solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                                faces=case.solver_faces(), air=case.solver_air(),
                                convection=case.solver_convection())
        solver.advance(20.0)
        grown[on] = float((solver.liquid_fraction() * ~cavity).sum())
        if on:
            t_mean, length, k_eff = solver.convection.last
            assert length == pytest.approx(0.024, rel=0.15)
            assert 0.56 < k_eff <= case.solver_properties().water.k
            assert 0.0 < t_mean < 20.0
        solver.advance(240.0)
        assert abs(solver.energy_error()) < 1e-9 * solver.heat_in
        if on:  # the water is near 0 °C: weak convection (measured 0.75 °C, k_eff 0.56)
            assert solver.convection.last[0] < 1.5 and solver.convection.last[2] < 1.0
        grown[on, "end"] = float((solver.liquid_fraction() * ~cavity).sum())
    # at 16 cells: more than twice the wall melted after 20 s, about the same after 260 s:
    # the water's heat is the same, convection gives it sooner
    assert grown[True] > 2.0 * grown[False]
    assert grown[True, "end"] == pytest.approx(grown[False, "end"], rel=0.1)
