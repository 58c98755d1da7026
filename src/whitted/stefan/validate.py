"""Validation against exact answers: the studies behind ``whitted stefan validate``, the tests
and the table in ``docs/stefan.md``.

Every study returns plain rows (dicts) so the CLI prints them, the tests assert on them and the
docs quote them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import exact
from .properties import Properties
from .solver import Air, EnthalpySolver, Faces

AXES = ("x", "y", "z")
#: Published similarity constants to check the root-finding against (one phase: lambda for
#: each Stefan number; two phase: +10 °C wall, -10 °C ice, front after 1 h)
QUOTED_ONE_PHASE = {0.1: 0.220016, 1.0: 0.620063}
QUOTED_TWO_PHASE = {"lambda": 0.2089, "front_mm": 9.14}  # +10 °C wall, -10 °C ice, 1 h


def line_shape(n: int, axis: int, width: int = 1) -> tuple[int, int, int]:
    """A grid of n cells along ``axis`` and ``width`` across (1: a 1-D run)."""
    shape = [width, width, width]
    shape[axis] = n
    return tuple(shape)  # type: ignore[return-value]


@dataclass
class NeumannRun:
    dx: float
    cells: int
    steps: int
    front: float  # m, computed (melted length)
    exact: float  # m
    far_change: float  # °C: how much the far end's temperature moved
    energy_error: float  # J/m² relative to the heat in
    solver: EnthalpySolver

    @property
    def error(self) -> float:
        return (self.front - self.exact) / self.exact


def neumann_run(props: Properties, wall: float, initial: float, t_end: float, dx: float,
                axis: int = 2, width: int = 1, reach_tolerance: float = 1e-6,
                dt: float | None = None) -> NeumannRun:
    """Melt a half space from a wall at ``wall`` °C into ice at ``initial`` °C (0: one phase)
    on a line of cells along ``axis``; the far end sits beyond the thermal wave."""
    if initial < 0.0:
        length = 1.05 * exact.wave_reach(props, t_end, reach_tolerance)
        lam = exact.two_phase_lambda(props, wall, initial)
    else:
        stefan = props.water.capacity * wall / props.latent_per_volume
        lam = exact.one_phase_lambda(stefan)
        length = 1.5 * float(exact.front(lam, props, t_end)) + 4 * dx
    n = int(math.ceil(length / dx))
    shape = line_shape(n, axis, width)
    H = np.full(shape, props.enthalpy(initial, liquid=False))
    kind = np.ones(shape, dtype=np.uint8)
    faces = Faces.adiabatic().set(("x-", "y-", "z-")[axis], math.inf, wall)
    solver = EnthalpySolver(H, kind, dx, props, faces=faces, dt=dt)
    solver.advance(t_end)
    front = solver.melted_length(axis)
    far = [slice(None)] * 3
    far[axis] = -1
    t_far = float(np.max(np.abs(solver.temperature()[tuple(far)] - initial)))
    return NeumannRun(dx, n, solver.steps, front, float(exact.front(lam, props, t_end)), t_far,
                      solver.energy_error() / solver.heat_in, solver)


def lambda_rows(props: Properties | None = None) -> list[dict]:
    """The similarity constants, root-found, beside the quoted values."""
    props = props or Properties()
    rows = []
    for st, quoted in QUOTED_ONE_PHASE.items():
        lam = exact.one_phase_lambda(st)
        rows.append({"case": f"one phase, St = {st:g}", "lambda": lam, "quoted": quoted,
                     "difference": lam - quoted})
    lam = exact.two_phase_lambda(props, 10.0, -10.0)
    front = float(exact.front(lam, props, 3600.0)) * 1e3
    quoted = QUOTED_TWO_PHASE["lambda"]
    rows.append({"case": "two phase, +10 / -10 °C", "lambda": lam, "quoted": quoted,
                 "difference": lam - quoted})
    rows.append({"case": "two phase front after 1 h (mm)", "lambda": front,
                 "quoted": QUOTED_TWO_PHASE["front_mm"],
                 "difference": front - QUOTED_TWO_PHASE["front_mm"]})
    return rows


def convergence_rows(props: Properties | None = None, t_end: float = 3600.0,
                     cells_mm: tuple[float, ...] = (1.0, 0.5, 0.25), wall: float = 10.0,
                     initial: float = -10.0, axis: int = 2) -> list[dict]:
    """Front error against cell size (1-D runs), with the observed order between rows."""
    props = props or Properties()
    rows: list[dict] = []
    for mm in cells_mm:
        run = neumann_run(props, wall, initial, t_end, mm * 1e-3, axis=axis)
        row = {"dx_mm": mm, "cells": run.cells, "steps": run.steps, "front_mm": run.front * 1e3,
               "exact_mm": run.exact * 1e3, "error_pct": 100 * run.error,
               "far_change": run.far_change, "energy_rel": run.energy_error, "order": None}
        if rows:
            prev = rows[-1]
            row["order"] = math.log(abs(prev["error_pct"]) / abs(row["error_pct"])) / math.log(
                prev["dx_mm"] / mm)
        rows.append(row)
    return rows


#: Three further independent 1-D cases: (wall °C, initial ice °C); 0 °C ice is the one-phase case
MORE_CASES = ((25.0, -3.0), (3.0, -20.0), (15.0, 0.0))


def more_case_rows(props: Properties | None = None, t_end: float = 600.0,
                   cells_mm: tuple[float, ...] = (0.5, 0.25)) -> list[dict]:
    """The three further Neumann cases (``MORE_CASES``) at each cell size: front, exact front
    (its similarity constant root-found), error and observed order."""
    props = props or Properties()
    rows: list[dict] = []
    for wall, initial in MORE_CASES:
        for i, row in enumerate(convergence_rows(props, t_end=t_end, cells_mm=cells_mm,
                                                 wall=wall, initial=initial)):
            row["case"] = f"{wall:+g} °C wall, {initial:+g} °C ice" if i == 0 else ""
            rows.append(row)
    return rows


def axis_rows(props: Properties | None = None, t_end: float = 600.0, dx: float = 0.5e-3,
              wall: float = 10.0, initial: float = -10.0) -> list[dict]:
    """The same 1-D case along x, y and z, and as a 3-D block (4 x 4 across, adiabatic
    sides) along z, all with the 3-D grid's time step: every front equal to the first
    (``vs_first``, m; zero when bit-identical)."""
    props = props or Properties()
    block = neumann_run(props, wall, initial, t_end, dx, axis=2, width=4)
    rows = []
    base = None
    for axis in range(3):
        run = neumann_run(props, wall, initial, t_end, dx, axis=axis, dt=block.solver.dt)
        base = run.front if base is None else base
        rows.append({"run": f"1-D along {AXES[axis]}", "front_mm": run.front * 1e3,
                     "error_pct": 100 * run.error, "vs_first": run.front - base})
    front = block.solver.liquid_fraction().sum(axis=2) * dx
    rows.append({"run": "3-D (4 x 4 x n) along z", "front_mm": float(front.mean()) * 1e3,
                 "error_pct": 100 * block.error, "vs_first": float(np.abs(front - base).max())})
    return rows


def convective_slab(props: Properties | None = None, h: float = 20.0, air: float = 20.0,
                    t_end: float = 3000.0, dx: float = 1e-3, cells: int = 40) -> dict:
    """A slab of ice at 0 °C with air on one face: it recedes at h dT / (rho_i L)."""
    props = props or Properties()
    shape = (1, 1, cells)
    H = np.zeros(shape)
    kind = np.ones(shape, dtype=np.uint8)
    faces = Faces.adiabatic().set("z+", h, air, drain=True)
    solver = EnthalpySolver(H, kind, dx, props, faces=faces, air=Air(air, h))
    solver.advance(t_end)
    ice = float(((1.0 - solver.liquid_fraction()) * (solver.kind == 1)).sum()) * dx
    receded = cells * dx - ice
    expected = h * (air - 0.0) * t_end / props.latent_per_volume
    return {"receded_mm": receded * 1e3, "expected_mm": expected * 1e3,
            "error_pct": 100 * (receded / expected - 1.0),
            "energy_rel": solver.energy_error() / solver.heat_in}


def sphere_roundness(props: Properties | None = None, radius_cells: float = 9.0,
                     h: float = 20.0, air: float = 20.0, t_end: float = 2400.0,
                     dx: float = 1e-3) -> dict:
    """A sphere of ice at 0 °C in uniform air: the spread of its surface radius (marching
    cubes on the ice fraction) stays within one cell, its mean radius recedes at
    h dT / (rho_i L)."""
    from skimage.measure import marching_cubes

    props = props or Properties()
    n = int(2 * radius_cells + 4)
    c = (n - 1) / 2
    x = np.arange(n) - c
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    kind = (np.sqrt(X * X + Y * Y + Z * Z) <= radius_cells).astype(np.uint8)
    solver = EnthalpySolver(np.zeros(kind.shape), kind, dx, props, air=Air(air, h))

    def radii() -> np.ndarray:
        occ = np.pad(np.where(solver.kind == 1, 1.0 - solver.liquid_fraction(), 0.0), 1)
        verts = marching_cubes(occ, 0.5)[0] - 1 - c
        return np.linalg.norm(verts, axis=1)

    r0 = radii()
    solver.advance(t_end)
    r1 = radii()
    rate = h * air / props.latent_per_volume
    ice = float(((1.0 - solver.liquid_fraction()) * (solver.kind == 1)).sum())
    r_volume = (3.0 * ice / (4.0 * math.pi)) ** (1.0 / 3.0) * dx
    r_volume0 = (3.0 * float(kind.sum()) / (4.0 * math.pi)) ** (1.0 / 3.0) * dx
    return {"spread_start_cells": float(r0.max() - r0.min()),
            "receded_mm": (r_volume0 - r_volume) * 1e3, "receded_exact_mm": rate * t_end * 1e3,
            "spread_end_cells": float(r1.max() - r1.min()),
            "mean_radius_start_mm": float(r0.mean()) * dx * 1e3,
            "mean_radius_end_mm": float(r1.mean()) * dx * 1e3,
            "expected_end_mm": (float(r0.mean()) * dx - rate * t_end) * 1e3,
            "energy_rel": solver.energy_error() / solver.heat_in}


#: de Vahl Davis (1983), "Natural convection of air in a square cavity: a bench mark numerical
#: solution", Int. J. Numer. Methods Fluids 3, 249-264: the mean Nusselt number Nu of a
#: square cavity with differentially heated side walls (Pr = 0.71), accurate to better than
#: 1 % at Ra = 1e6 and to 0.1 % at 1e3 (the paper's estimate).
DE_VAHL_DAVIS_NU = ((1.0e3, 1.118), (1.0e4, 2.243), (1.0e5, 4.519), (1.0e6, 8.800))
DE_VAHL_DAVIS_PR = 0.71


def enclosure_rows() -> list[dict]:
    """The cavity's Nusselt law (Catton's enclosure correlation, ``convection.nusselt_enclosure``)
    against de Vahl Davis's benchmark for the square cavity it is a correlation of: the model's
    Nu (1 below Catton's range), the correlation's formula itself, the benchmark, the errors
    and whether Ra Pr / (0.2 + Pr) is in Catton's range (> 10^3)."""
    from .convection import nusselt_enclosure

    pr = DE_VAHL_DAVIS_PR
    rows = []
    for ra, nu in DE_VAHL_DAVIS_NU:
        x = pr / (0.2 + pr) * ra
        formula = 0.18 * x ** 0.29
        model = nusselt_enclosure(ra, pr)
        rows.append({"ra": ra, "benchmark": nu, "model": model, "formula": formula,
                     "error_pct": 100.0 * (model / nu - 1.0),
                     "formula_error_pct": 100.0 * (formula / nu - 1.0),
                     "in_range": x > 1.0e3})
    return rows


def flow_cavity_rows(grids: tuple[int, ...] = (32,), ras: tuple[float, ...] = (1e3, 1e4, 1e5, 1e6),
                     progress=None) -> list[dict]:
    """The flow solver (:mod:`whitted.stefan.flow`) on de Vahl Davis's square cavity at each
    Ra and grid: mean Nusselt number and the centre lines' velocity maxima and where they
    are, against the benchmark, their errors; with two grids or more, the Richardson
    extrapolation of the last two (second order: (4 f_fine - f_coarse) / 3) as a row of its own."""
    from .flow import DE_VAHL_DAVIS, heated_cavity

    rows = []
    for ra in ras:
        ref = DE_VAHL_DAVIS[ra]
        found = []
        for n in grids:
            r = heated_cavity(ra, n)
            if progress is not None:
                progress(ra, n, r)
            found.append(r)
            rows.append(_cavity_row(ra, f"{n}²", r.nu, r.u_max, r.v_max, ref, r.steps,
                                    r.seconds, r.y_umax, r.x_vmax))
        if len(found) >= 2 and found[-1].cells == 2 * found[-2].cells:
            a, b = found[-2], found[-1]
            ext = [(4.0 * getattr(b, q) - getattr(a, q)) / 3.0
                   for q in ("nu", "u_max", "v_max", "y_umax", "x_vmax")]
            rows.append(_cavity_row(ra, f"{a.cells}²/{b.cells}² extrapolated", *ext[:3], ref,
                                    None, None, *ext[3:]))
    return rows


def cube_rows(grids: tuple[int, ...] = (24,), ras: tuple[float, ...] = (1e4, 1e5),
              progress=None) -> list[dict]:
    """The flow solver on the differentially heated cube (3-D, :data:`flow.CUBE_NU`): the
    hot wall's mean Nusselt number against the reference, its error, and the velocity
    maxima on the mid-plane z = 1/2 (no reference: see ``CUBE_NU``); with two grids or more
    the Richardson extrapolation of the last two (second order, when the cell halves; for
    another ratio r, f_fine + (f_fine - f_coarse) / (r² - 1))."""
    from .flow import CUBE_NU, heated_cavity

    rows = []
    for ra in ras:
        ref = CUBE_NU[ra]
        found = []
        for n in grids:
            r = heated_cavity(ra, n, dims=3)
            if progress is not None:
                progress(ra, n, r)
            found.append(r)
            rows.append(_cube_row(ra, f"{n}³", r.nu_wall, r.u_max, r.v_max, ref, r.steps,
                                  r.seconds, r.cell_updates_per_s))
        if len(found) >= 2:
            a, b = found[-2], found[-1]
            k = (b.cells / a.cells) ** 2 - 1.0
            ext = [getattr(b, q) + (getattr(b, q) - getattr(a, q)) / k
                   for q in ("nu_wall", "u_max", "v_max")]
            rows.append(_cube_row(ra, f"{a.cells}³/{b.cells}³ extrapolated", *ext, ref,
                                  None, None, None))
    return rows


def _cube_row(ra, grid, nu, u_max, v_max, ref, steps, seconds, rate) -> dict:
    return {"ra": ra, "grid": grid, "nu": nu, "nu_ref": ref,
            "nu_error_pct": 100.0 * (nu / ref - 1.0), "u_max": u_max, "v_max": v_max,
            "steps": steps, "seconds": seconds, "cell_updates_per_s": rate}


def _cavity_row(ra, grid, nu, u_max, v_max, ref, steps, seconds, y_umax, x_vmax) -> dict:
    """One row: each quantity, its reference and the error (relative for the maxima, the
    difference in units of L for their positions)."""
    return {"ra": ra, "grid": grid, "nu": nu, "nu_ref": ref["nu"],
            "nu_error_pct": 100.0 * (nu / ref["nu"] - 1.0), "u_max": u_max,
            "u_ref": ref["u_max"], "u_error_pct": 100.0 * (u_max / ref["u_max"] - 1.0),
            "y_umax": y_umax, "y_ref": ref["y_umax"], "y_error": y_umax - ref["y_umax"],
            "v_max": v_max, "v_ref": ref["v_max"],
            "v_error_pct": 100.0 * (v_max / ref["v_max"] - 1.0),
            "x_vmax": x_vmax, "x_ref": ref["x_vmax"], "x_error": x_vmax - ref["x_vmax"],
            "steps": steps, "seconds": seconds}


def energy_balance(cells: int = 16, t_end: float = 600.0) -> dict:
    """The default case on a small grid: enthalpy change against boundary heat minus the
    enthalpy that drained, in joules."""
    from .case import Case
    from .geometry import initial_state

    case = Case.model_validate({"grid": {"cells": cells},
                                "table": {"contact": "conducting"}})
    H, kind, _, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                            faces=case.solver_faces(), air=case.solver_air(),
                            convection=case.solver_convection())
    solver.advance(t_end)
    change = solver.enthalpy() - solver.initial_enthalpy
    return {"enthalpy_change_J": change, "heat_in_J": solver.heat_in,
            "drained_J": solver.drained, "imbalance_J": solver.energy_error(),
            "relative": solver.energy_error() / solver.heat_in}


def plot_front(path, props: Properties | None = None, dx: float = 0.25e-3,
               t_end: float = 3600.0, samples: int = 13) -> None:
    """Front position against time, computed (1-D, two-phase case) beside exact (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    props = props or Properties()
    lam = exact.two_phase_lambda(props, 10.0, -10.0)
    n = int(math.ceil(1.05 * exact.wave_reach(props, t_end) / dx))
    H = np.full((1, 1, n), props.enthalpy(-10.0, liquid=False))
    solver = EnthalpySolver(H, np.ones((1, 1, n), np.uint8), dx, props,
                            faces=Faces.adiabatic().set("z-", math.inf, 10.0))
    times = np.linspace(0.0, t_end, samples)
    fronts = [0.0]
    for t in times[1:]:
        solver.advance(float(t))
        fronts.append(solver.melted_length(2))
    fine = np.linspace(0.0, t_end, 200)
    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=110)
    ax.plot(fine / 60, exact.front(lam, props, fine) * 1e3, "k-", lw=1,
            label=f"exact (Neumann, lambda = {lam:.4f})")
    ax.plot(times / 60, np.array(fronts) * 1e3, "o", color="C0", ms=5,
            label=f"enthalpy method, dx = {dx * 1e3:g} mm")
    ax.set_xlabel("time (min)")
    ax.set_ylabel("front position (mm)")
    ax.set_title("Two-phase melt: +10 °C wall, ice at -10 °C")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


#: Gau & Viskanta (1986), "Melting and solidification of a pure metal on a vertical wall",
#: J. Heat Transfer 108, 174-181: gallium melting from a heated side wall of a cavity 8.89 cm
#: wide and 6.35 cm high. The measured melt front (distance from the hot wall over the width)
#: at the top, the middle and the bottom of the cavity against tau = Ste alpha t / W², as the
#: Lethe project digitised the paper's figure (github.com/chaos-polymtl/lethe,
#: examples/multiphysics/melting-cavity/melting-cavity.py, with Ste = 0.041 in its
#: dimensionless_number_calculator.py); tau maps to 2, 3, 4.5, 6, 8, 10, 12.5 and 15 minutes
#: with gallium's alpha below, which is how the experiment's photographs were timed.
GAU_VISKANTA = {
    "tau": (0.00853, 0.01279, 0.01931, 0.02575, 0.03428, 0.04298, 0.0536, 0.06438),
    "top": (0.11508, 0.18212, 0.28603, 0.31508, 0.38994, 0.50391, 0.61117, 0.72514),
    "middle": (0.11508, 0.16313, 0.20894, 0.23911, 0.29609, 0.36089, 0.45475, 0.52961),
    "bottom": (0.1095, 0.12849, 0.14078, 0.16425, 0.21117, 0.22346, 0.26592, 0.26592),
    # the melted fraction of the cavity, measured (the same file, its own tau values)
    "melted_tau": (0.00946, 0.01433, 0.02113, 0.02877, 0.03774, 0.04739, 0.05956, 0.07164,
                   0.08104, 0.09069),
    "melted": (0.11972, 0.16112, 0.20476, 0.22713, 0.2786, 0.34014, 0.43077, 0.5035, 0.56392,
               0.61664),
    "stefan": 0.041,
}
#: Gallium as the MOOSE framework's gallium-melting input gives it (idaholab/moose, read
#: through a code search whose index does not name the file's path): rho 6093 kg/m³,
#: c 381.5 J/kgK, k 32 W/mK, L 80160 J/kg, mu 1.81 mPa s, beta 1.2e-4 1/K; melting at
#: 302.93 K, the hot wall at 311.15 K, the cold wall and the initial solid at 301.15 K.
GALLIUM = {"rho": 6093.0, "c": 381.5, "k": 32.0, "latent": 80160.0, "mu": 1.81e-3,
           "beta": 1.2e-4, "t_melt": 302.93, "t_hot": 311.15, "t_cold": 301.15,
           "width": 0.0889, "height": 0.0635}


def gallium_rows(dx_mm: float = 2.0, last: int | None = None, progress=None,
                 changes: dict | None = None, mushy: float | None = None,
                 taus: tuple[float, ...] | None = None,
                 depth: float | None = None) -> list[dict]:
    """Gau & Viskanta's gallium melting in 2-D (the flow solver coupled to the enthalpy
    method, the enthalpy-porosity sink): the melted length along the top, middle and bottom
    rows of cells (liquid fraction summed, over the width) at the experiment's times, beside
    the measured front, and the melted fraction of the cavity beside the measured one
    (interpolated linearly to the same time). ``last``: only the first ``last`` times.
    ``changes``: values that replace :data:`GALLIUM`'s (a study of what the answer depends
    on); ``mushy``: the Carman-Kozeny constant (default Brent et al.'s); ``taus``: other
    times (tau) than the measured ones (then no measured front beside them). ``depth`` (m):
    a 3-D cavity that deep between adiabatic no-slip walls (the fronts then on its middle
    plane, the melted fraction of the whole, ``melted_plane`` that of the middle plane);
    None: 2-D."""
    from .flow import MeltFlow
    from .properties import Phase

    g = {**GALLIUM, **(changes or {})}
    phase = Phase(rho=g["rho"], c=g["c"], k=g["k"])
    props = Properties(ice=phase, water=phase, latent_heat=g["latent"])
    dx = dx_mm * 1e-3
    nx = int(round(g["width"] / dx))
    ny = int(round(g["height"] / dx))
    dx = g["width"] / nx  # the width exact; the height within half a cell
    nz = 1 if depth is None else max(1, int(round(depth / dx)))
    shape = (nx, ny, nz)
    t_cold = g["t_cold"] - g["t_melt"]
    H = np.full(shape, props.enthalpy(t_cold, liquid=False))
    kind = np.ones(shape, dtype=np.uint8)
    faces = (Faces.adiabatic().set("x-", math.inf, g["t_hot"] - g["t_melt"])
             .set("x+", math.inf, t_cold))
    flow = MeltFlow((slice(0, nx), slice(0, ny), slice(0, nz)), dx, props,
                    viscosity=g["mu"] / g["rho"], expansion=g["beta"], mushy=mushy)
    solver = EnthalpySolver(H, kind, dx, props, faces=faces, flow=flow)
    alpha = phase.diffusivity
    ref = GAU_VISKANTA
    measured = taus is None
    taus = ref["tau"][:last] if measured else tuple(taus)
    rows = []
    for i, tau in enumerate(taus):
        t = tau * g["width"] ** 2 / (ref["stefan"] * alpha)
        solver.advance(t)
        f3 = solver.liquid_fraction()
        f = f3[:, :, nz // 2]
        cells = f"{nx}x{ny}" + ("" if nz == 1 else f"x{nz}")
        row = {"minutes": t / 60.0, "tau": tau, "cells": cells, "dx_mm": dx * 1e3,
               "melted": float(f3.mean()), "melted_plane": float(f.mean()),
               "speed_mm_s": flow.speed() * 1e3,
               "energy_rel": solver.energy_error() / solver.heat_in,
               "melted_ref": float(np.interp(tau, ref["melted_tau"], ref["melted"],
                                               left=math.nan))}
        for name, j in (("top", ny - 1), ("middle", ny // 2), ("bottom", 0)):
            row[name] = float(f[:, j].sum()) / nx
            row[name + "_ref"] = ref[name][i] if measured else math.nan
        rows.append(row)
        if progress is not None:
            progress(row)
    return rows


#: Blais & Ilinca (2018), Comput. Fluids 172, 564-581: their 2-D computation's melted fraction
#: of the gallium cavity against tau, as the Lethe project tabulates it beside the experiment
#: (github.com/chaos-polymtl/lethe, examples/multiphysics/melting-cavity/
#: compare-melting-cavity.py; sorted by tau here). Their case, as Lethe's example of it sets
#: it up (melting-cavity.rst, its parameter file): Ra 10⁵ on the height, Pr 0.01818, Ste
#: 0.041, the walls at 38 and 28 °C, melting at 29.8 °C: a sixth of the experiment's Ra.
BLAIS_ILINCA = {
    "tau": (0.00094, 0.00262, 0.00457, 0.00685, 0.01116, 0.01801, 0.02473, 0.02964, 0.03401,
            0.03891, 0.04368, 0.04812, 0.05323, 0.05759, 0.06452, 0.07433, 0.08266, 0.08931,
            0.09597, 0.09899),
    "melted": (0.0372, 0.0670, 0.0856, 0.1079, 0.1423, 0.1898, 0.2344, 0.2614, 0.2874, 0.3163,
               0.3442, 0.3721, 0.4000, 0.4242, 0.4651, 0.5153, 0.5600, 0.5935, 0.6279,
               0.6437),
}


def gallium_ra_1e5_changes() -> dict:
    """:data:`GALLIUM` changed to Blais & Ilinca's case (:data:`BLAIS_ILINCA`): gallium's
    conductivity, density and heat capacity (so the same diffusivity and times), its
    viscosity and expansion set for Pr 0.01818 and Ra 10⁵ on the height, the latent heat for
    Ste 0.041, melting at 29.8 °C between walls at 38 and 28 °C."""
    g = GALLIUM
    alpha = g["k"] / (g["rho"] * g["c"])
    nu = 0.01818 * alpha
    d_t = 38.0 - 29.8
    beta = 1.0e5 * nu * alpha / (9.80665 * d_t * g["height"] ** 3)
    return {"mu": nu * g["rho"], "beta": beta, "t_melt": 273.15 + 29.8,
            "t_hot": 273.15 + 38.0, "t_cold": 273.15 + 28.0, "latent": g["c"] * d_t / 0.041}


def gallium_ra_1e5_rows(dx_mm: float = 4.0, progress=None) -> list[dict]:
    """Gallium at Blais & Ilinca's Ra 10⁵ (:func:`gallium_ra_1e5_changes`) at the measured
    times: the melted fraction beside their computation and the experiment's."""
    rows = gallium_rows(dx_mm, progress=progress, changes=gallium_ra_1e5_changes())
    for r in rows:
        r["melted_blais"] = float(np.interp(r["tau"], BLAIS_ILINCA["tau"],
                                            BLAIS_ILINCA["melted"]))
    return rows
