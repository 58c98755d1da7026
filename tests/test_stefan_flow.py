"""The water's flow: the projection leaves no divergence, de Vahl Davis's square cavity on a
coarse grid against the published numbers, and the flow coupled to the melt (energy kept,
the top of the cavity melting faster above 4 °C, the bottom below it)."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.stefan.case import CaseError, case_from_dict
from whitted.stefan.flow import DE_VAHL_DAVIS, Flow, Poisson, heated_cavity
from whitted.stefan.geometry import initial_state
from whitted.stefan.solver import EnthalpySolver


@pytest.mark.parametrize("shape", [(12, 10, 1), (8, 9, 10)])
def test_the_projection_leaves_no_divergence(shape):
    rng = np.random.default_rng(4)
    flow = Flow(shape, 0.1, 1.0)
    flow.u[1:-1] = rng.normal(size=flow.u[1:-1].shape)
    flow.v[:, 1:-1] = rng.normal(size=flow.v[:, 1:-1].shape)
    if shape[2] > 1:
        flow.w[:, :, 1:-1] = rng.normal(size=flow.w[:, :, 1:-1].shape)
    assert flow.max_divergence() > 1.0
    flow.project(0.01)
    assert flow.max_divergence() < 1e-10
    # the cosine transform solves the Neumann problem exactly: a known solution comes back
    p = Poisson(shape, 0.1)
    phi = rng.normal(size=shape)
    phi -= phi.mean()
    pad = np.pad(phi, 1, mode="edge")  # mirror ghosts: no flux through the walls
    lap = sum(np.roll(pad, s, axis=a) for a in range(3) for s in (1, -1))[1:-1, 1:-1, 1:-1]
    lap = (lap - 6.0 * phi) / 0.01  # (one layer: its z neighbours are itself, adding 0)
    np.testing.assert_allclose(p.solve(lap), phi, atol=1e-10)


@pytest.mark.parametrize("ra, nu_tol, vel_tol", [(1e3, 0.005, 0.006), (1e4, 0.015, 0.01)])
def test_de_vahl_davis_square_cavity_at_32_cells(ra, nu_tol, vel_tol):
    # measured at 32²: Ra 1e3 Nu 1.1199 (+0.17 %), u_max 3.663 (+0.39 %), v_max 3.711
    # (+0.38 %); Ra 1e4 Nu 2.268 (+1.1 %), u_max 16.188 (+0.06 %), v_max 19.708 (+0.46 %)
    r = heated_cavity(ra, 32)
    ref = DE_VAHL_DAVIS[ra]
    assert r.nu == pytest.approx(ref["nu"], rel=nu_tol)
    assert r.nu_wall == pytest.approx(r.nu, rel=1e-3)  # steady: the wall's flux is the mean
    assert r.u_max == pytest.approx(ref["u_max"], rel=vel_tol)
    assert r.v_max == pytest.approx(ref["v_max"], rel=vel_tol)


def test_the_case_key_chooses_the_model():
    assert case_from_dict({"cavity": {"convection": "flow"}}).cavity.model == "flow"
    assert case_from_dict({"cavity": {"convection": True}}).cavity.model == "effective"
    assert case_from_dict({"cavity": {"convection": "off"}}).cavity.model == "off"
    with pytest.raises(CaseError) as err:
        case_from_dict({"cavity": {"convection": "fast"}})
    assert "\n" not in str(err.value) and "convection" in str(err.value)


def _melt(temperature: float, t_end: float = 20.0):
    case = case_from_dict({"grid": {"cells": 16}, "cavity": {"convection": "flow",
                                                             "temperature": temperature}})
    H, kind, cavity, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                            faces=case.solver_faces(), air=case.solver_air(),
                            flow=case.solver_flow(H, kind))
    solver.advance(t_end, chunk=50)
    grown = solver.liquid_fraction() * ~cavity
    ny = grown.shape[1]
    return solver, grown[:, ny // 2:].sum(), grown[:, :ny // 2].sum()


def test_the_flow_keeps_the_energy_and_melts_where_it_goes():
    # 20 °C water: the warm water rises (above 4 °C), so the cavity's top melts first
    solver, top, bottom = _melt(20.0)
    assert abs(solver.energy_error()) < 1e-9 * abs(solver.heat_in) + 1e-9
    assert solver.flow.speed() > 1e-4  # m/s: it moves
    assert top > 2.0 * bottom
    # 3 °C water: the 0 °C water at the wall is lighter and rises, the 3 °C water sinks:
    # the bottom melts first
    solver, top, bottom = _melt(3.0)
    assert abs(solver.energy_error()) < 1e-9 * abs(solver.heat_in) + 1e-9
    assert bottom > top
