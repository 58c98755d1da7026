"""The water's flow: incompressible Navier-Stokes with buoyancy, by projection (Chorin), on a
box of the enthalpy solver's cubic cells; validated on the differentially heated square
cavity (de Vahl Davis 1983) and coupled to the melt.

A step: the predictor (advection, diffusion, buoyancy and the enthalpy-porosity sink,
``flow_kernels.predict``), then the pressure: div(grad phi) = div(u*) / dt with no flow
through the walls, solved exactly by the cosine transform (DCT-II diagonalises the cell-centred
Neumann Laplacian of a box: ``scipy.fft.dctn``, both cores), and u = u* - dt grad(phi), which
leaves every cell's outflow at round-off.

In the melt (:class:`MeltFlow`) the flow covers a box around the cavity, solid and liquid
alike (the enthalpy-porosity method: Voller & Prakash 1987, Int. J. Heat Mass Transfer 30,
1709; Brent, Voller & Reid 1988, Numer. Heat Transfer 13, 297): a cell of liquid fraction f
has the Carman-Kozeny sink a = C (1 - f)² / (f³ + 10⁻³) / ρ_w, C = 1.6 × 10⁶ kg/m³s (Brent et
al.'s value), which stops the ice and lets the mushy wall slip gradually. The buoyancy is
g (ρ(0 °C) − ρ(T)) / ρ(0 °C) per liquid cell (times f), ρ from Kell's equation of state with
its 3.98 °C maximum (:func:`whitted.stefan.convection.water_density`): warm water above
4 °C rises, water below 4 °C sinks, the two cells of a bulk between 0 and 8 °C included. The
liquid carries its sensible heat ρ_w c_w T across the faces (upwind), which melts the wall
where the flow brings it. There the pressure is solved on the fluid cells only, by
multigrid-preconditioned conjugate gradients (:mod:`whitted.stefan.multigrid`), and
incrementally (the last pressure in the predictor); the flow is stepped every
``FLOW_EVERY`` enthalpy steps, its predictor in parts within its explicit limits.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from . import flow_kernels as fk

#: de Vahl Davis (1983), Int. J. Numer. Methods Fluids 3, 249-264: the mean Nusselt number of
#: the square cavity (Pr 0.71), the largest horizontal velocity on the vertical centre line and
#: its height, the largest vertical velocity on the horizontal centre line and its distance
#: from the hot wall (units alpha / L and L). Read here: the Nusselt numbers, u_max and v_max
#: at every Ra from the benchmark column of Cardinal's verification page
#: (https://cardinal.cels.anl.gov/vv/square_cavity_natural_convection.html, its Table 2);
#: u_max 3.649 at y 0.813 (Ra 10³) from a public simulation input that quotes the paper
#: (its repository not named where it was read); v_max at x 0.066
#: (Ra 10⁵) from a public FEM script that checks itself against it
#: (https://pastebin.com/Y4gxSnYR). The other positions (y 0.823, 0.855, 0.850; x 0.178,
#: 0.119, 0.0379) are the paper's as commonly tabled, not read here.
DE_VAHL_DAVIS = {
    1.0e3: {"nu": 1.118, "u_max": 3.649, "y_umax": 0.813, "v_max": 3.697, "x_vmax": 0.178},
    1.0e4: {"nu": 2.243, "u_max": 16.178, "y_umax": 0.823, "v_max": 19.617, "x_vmax": 0.119},
    1.0e5: {"nu": 4.519, "u_max": 34.73, "y_umax": 0.855, "v_max": 68.59, "x_vmax": 0.066},
    1.0e6: {"nu": 8.800, "u_max": 64.63, "y_umax": 0.850, "v_max": 219.36, "x_vmax": 0.0379},
}

#: The differentially heated cube (Pr 0.71, hot and cold opposite vertical walls, the other
#: four adiabatic, no slip everywhere): the mean Nusselt number of the hot wall. The values of
#: Tric, Labrosse & Betrouni (2000, "A first incursion into the 3D structure of natural
#: convection of air in a differentially heated cubic cavity") and Wakashima & Saitoh (2004),
#: Int. J. Heat Mass Transfer 47, 853-864, as a
#: public GitHub file quotes them (``utils_3D_convection.py``, its dictionary
#: ``WAKASHIMA_SAITOH_2004_GROUND_TRUTH``, read through a code search whose index does not name
#: the repository): Nu 2.054 at Ra 10⁴ and 4.337 at 10⁵. A secondary source, rounded to
#: three decimals; the papers' own tables could not be read here. The velocity maxima that
#: file gives could not be corroborated and are not used.
CUBE_NU = {1.0e4: 2.054, 1.0e5: 4.337}


#: The masked projection's tolerance (:attr:`Flow.volume_tolerance`): the divergence left may
#: change a fluid cell's volume by 10⁻¹⁰ of itself a step (root mean square over the fluid);
#: over the 40 000 flow steps of the default case to its breach, 4 × 10⁻⁶.
VOLUME_TOLERANCE = 1.0e-10


class Poisson:
    """div(grad phi) = rhs in a box of cubic cells of side dx, no flux through its walls:
    exact (to round-off) by the cosine transform. Solvable when rhs sums to 0 (then phi's
    mean is 0); the mean of rhs is dropped."""

    def __init__(self, shape: tuple[int, ...], dx: float, workers: int | None = None) -> None:
        self.shape = tuple(shape)
        self.axes = tuple(a for a, n in enumerate(shape) if n > 1)
        lam = np.zeros(shape)
        for a in self.axes:
            n = shape[a]
            k = np.arange(n)
            e = (2.0 * np.cos(np.pi * k / n) - 2.0) / (dx * dx)
            view = [1] * len(shape)
            view[a] = n
            lam = lam + e.reshape(view)
        lam[(0,) * len(shape)] = 1.0  # the mean: set to 0 below
        self.inverse = 1.0 / lam
        self.inverse[(0,) * len(shape)] = 0.0
        self.workers = workers

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        from scipy.fft import dctn, idctn

        hat = dctn(rhs, type=2, axes=self.axes, norm="ortho", workers=self.workers)
        hat *= self.inverse
        return idctn(hat, type=2, axes=self.axes, norm="ortho", workers=self.workers)


class MaskedPoisson:
    """div(grad phi) = rhs on the fluid cells of a box, no flux through the faces to other
    cells or the walls: conjugate gradients preconditioned by a multigrid V-cycle
    (:mod:`whitted.stefan.multigrid`, both cores) on the fluid's bounding box, started from
    the last solution; the levels rebuilt when the fluid changes. Solved until the
    divergence left after the correction is at most ``tolerance`` (1/s, root mean square
    over the fluid cells)."""

    def __init__(self, shape: tuple[int, int, int], dx: float) -> None:
        self.shape = tuple(shape)
        self.dx = float(dx)
        self._mask: np.ndarray | None = None
        self._phi = np.zeros(shape)
        self.iterations = 0  # of the last solve
        self.solves = 0
        self.total_iterations = 0

    def _build(self, fluid: np.ndarray) -> None:
        from .multigrid import Hierarchy

        self._mask = fluid.copy()
        idx = np.argwhere(fluid)
        if idx.size == 0:
            self.crop = None
            return
        lo, hi = idx.min(axis=0), idx.max(axis=0) + 1
        self.crop = tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))
        self.fluid_cells = int(fluid.sum())
        self.hierarchy = Hierarchy(fluid[self.crop], self.dx)

    def zero_closed(self, u, v, w, fluid: np.ndarray) -> None:
        """No flow through a face unless both its cells are fluid (the walls' faces stay 0)."""
        u[1:-1][~(fluid[1:] & fluid[:-1])] = 0.0
        v[:, 1:-1][~(fluid[:, 1:] & fluid[:, :-1])] = 0.0
        if fluid.shape[2] > 1:
            w[:, :, 1:-1][~(fluid[:, :, 1:] & fluid[:, :, :-1])] = 0.0

    def solve(self, fluid: np.ndarray, rhs: np.ndarray, tolerance: float) -> np.ndarray:
        """phi on the fluid cells (0 elsewhere) for ``rhs`` (div u* / dt); ``tolerance``:
        the divergence (1/s, root mean square) the correction may leave, divided by dt."""
        if self._mask is None or not np.array_equal(self._mask, fluid):
            self._build(fluid)
        phi = np.zeros(self.shape)
        if self.crop is None:
            return phi
        inside = self._mask[self.crop]
        b = np.where(inside, -rhs[self.crop], 0.0).ravel()
        x = np.where(inside, self._phi[self.crop], 0.0).ravel()
        tol = float(tolerance) * np.sqrt(self.fluid_cells)
        self.iterations = self.hierarchy.solve(b, x, tol)
        self.solves += 1
        self.total_iterations += self.iterations
        phi[self.crop] = x.reshape(inside.shape)
        self._phi = phi
        return phi


class Flow:
    """Velocities on the faces of a box of ``shape`` cells (2-D when the last is 1), with
    kinematic viscosity ``nu`` (m²/s, or Pr in the benchmark's units)."""

    def __init__(self, shape: tuple[int, int, int], dx: float, nu: float) -> None:
        n0, n1, n2 = shape
        self.shape = (n0, n1, n2)
        self.dx = float(dx)
        self.nu = float(nu)
        self.flat = n2 == 1
        self.u = np.zeros((n0 + 1, n1, n2))
        self.v = np.zeros((n0, n1 + 1, n2))
        self.w = np.zeros((n0, n1, n2 + 1))
        self._u = np.zeros_like(self.u)
        self._v = np.zeros_like(self.v)
        self._w = np.zeros_like(self.w)
        self._div = np.zeros(shape)
        #: incremental projection (with ``fluid``): the last projection's pressure acts in
        #: the predictor, and the projection solves for its change
        self.incremental = False
        self.pressure = np.zeros(shape)
        self._zero = np.zeros(shape)
        self.poisson = Poisson(shape, dx, workers=-1)
        self._masked = MaskedPoisson(shape, dx)
        #: the masked projection's tolerance: the volume a fluid cell may gain or lose in a
        #: step through the divergence left, as a fraction of the cell (root mean square)
        self.volume_tolerance = VOLUME_TOLERANCE

    def viscous_dt(self) -> float:
        """The explicit diffusion's limit dx²/(2 d nu)."""
        return self.dx * self.dx / (2.0 * (2 if self.flat else 3) * self.nu)

    def advective_dt(self, cfl: float = 0.5) -> float:
        """The advection's limit cfl dx / (|u| + |v| + |w|) (inf at rest)."""
        speed = (np.abs(self.u).max() + np.abs(self.v).max()
                 + (0.0 if self.flat else np.abs(self.w).max()))
        return cfl * self.dx / speed if speed > 0.0 else math.inf

    def stable_dt(self, cfl: float = 0.5) -> float:
        """The explicit step's limit: diffusion (dx²/(2 d nu)) and advection (cfl dx / |u|)."""
        return min(self.viscous_dt(), self.advective_dt(cfl))

    def step(self, dt: float, buoyancy: np.ndarray, sink: np.ndarray | None = None,
             fluid: np.ndarray | None = None, parts: bool = False) -> None:
        """One step: ``buoyancy`` (m/s², per cell, along +axis 1, which is up), the
        enthalpy-porosity ``sink`` (1/s per cell; None: none) and, with ``fluid``, the
        projection on those cells only (:meth:`project`). ``parts``: the predictor in as
        many explicit parts as keep each within 0.9 of the limits at the speed of the
        moment (:meth:`stable_dt` with cfl 0.4), then one projection for the whole step."""
        sink = self._zero if sink is None else sink
        left = dt
        while left > 1e-12 * dt:
            h = left
            if parts:
                h = min(left, 0.9 * self.stable_dt(0.4))
                if left - h < 0.05 * h:
                    h = left
            self._predict(h, buoyancy, sink)
            if self.incremental and fluid is not None:
                fk.correct_damped(self.u, self.v, self.w, self.pressure, h, self.dx, sink,
                                  self.flat)
                self._masked.zero_closed(self.u, self.v, self.w, fluid)
            left -= h
        self.project(dt, fluid)

    def _predict(self, dt: float, buoyancy: np.ndarray, sink: np.ndarray) -> None:
        dx, nu, flat = self.dx, self.nu, self.flat
        t = (1, 0, 2)
        fk.predict(self.u, self.v, self.w, nu, dt, dx, self._zero, sink, self._u, flat)
        # a flat box's views along v are Fortran-ordered (a length-1 last axis), its axis 0
        # the contiguous one: the kernel of a 3-D box's last component, whose inner loop runs
        # along axis 0; w is not read there (flat), so u's view stands in for it (the
        # two-face-deep w's view would not be Fortran-ordered)
        p = self.u.transpose(t)
        if flat:
            fk.predict_inner(self.v.transpose(t), p, p, nu, dt, dx, buoyancy.transpose(t),
                             sink.transpose(t), self._v.transpose(t), True)
        else:
            fk.predict(self.v.transpose(t), p, self.w.transpose(t), nu, dt, dx,
                       buoyancy.transpose(t), sink.transpose(t), self._v.transpose(t), False)
            t = (2, 1, 0)
            fk.predict_inner(self.w.transpose(t), self.v.transpose(t), self.u.transpose(t),
                             nu, dt, dx, self._zero.transpose(t), sink.transpose(t),
                             self._w.transpose(t), False)
        self.u, self._u = self._u, self.u
        self.v, self._v = self._v, self.v
        self.w, self._w = self._w, self.w

    def project(self, dt: float, fluid: np.ndarray | None = None) -> None:
        """Make the velocity divergence-free: in the whole box (cosine transform), or, with
        ``fluid`` (a mask of cells), in the fluid cells only, with no flow through the faces
        of the others (:class:`MaskedPoisson`)."""
        if fluid is not None:
            self._masked.zero_closed(self.u, self.v, self.w, fluid)
            fk.divergence(self.u, self.v, self.w, self.dx, self._div, self.flat)
            phi = self._masked.solve(fluid, self._div / dt,
                                    self.volume_tolerance / (dt * dt))
            fk.correct(self.u, self.v, self.w, phi, dt, self.dx, self.flat)
            self._masked.zero_closed(self.u, self.v, self.w, fluid)
            if self.incremental:
                self.pressure += phi
                self.pressure[~fluid] = 0.0
            return
        fk.divergence(self.u, self.v, self.w, self.dx, self._div, self.flat)
        phi = self.poisson.solve(self._div / dt)
        fk.correct(self.u, self.v, self.w, phi, dt, self.dx, self.flat)

    def max_divergence(self) -> float:
        fk.divergence(self.u, self.v, self.w, self.dx, self._div, self.flat)
        return float(np.abs(self._div).max())


# --- the differentially heated cavity -------------------------------------------------------

@dataclass
class CavityResult:
    ra: float
    cells: int
    nu: float  # mean Nusselt number (the x flux averaged over every x face of the cavity)
    nu_wall: float  # at the hot wall
    u_max: float  # on the vertical centre line (alpha / L)
    v_max: float  # on the horizontal centre line
    steps: int
    seconds: float
    cell_updates_per_s: float
    dims: int = 2
    y_umax: float = math.nan  # the height of u_max (units of L)
    x_vmax: float = math.nan  # the distance of v_max from the hot wall


def _peak_at(values: np.ndarray) -> tuple[float, float]:
    """The largest of samples at unit spacing and where it is (in samples from the first),
    both refined by the parabola through the largest and its two neighbours."""
    m = int(np.argmax(values))
    if 0 < m < len(values) - 1:
        a, b, c = values[m - 1], values[m], values[m + 1]
        den = a - 2.0 * b + c
        if den < 0.0:
            x = 0.5 * (a - c) / den
            return float(b - 0.25 * (a - c) * x), m + float(x)
    return float(values[m]), float(m)


def heated_cavity(ra: float, cells: int, pr: float = 0.71, dims: int = 2, tol: float = 1e-6,
                  t_max: float = 3.0, progress=None) -> CavityResult:
    """The square (``dims`` 2) or cubic (3) cavity of side 1, hot wall (T = +1/2) at x = 0,
    cold (−1/2) at x = 1, the others adiabatic, no slip everywhere, Boussinesq air: in units
    of L and L²/alpha, u_t + u.grad u = −grad p + Pr lap u + Ra Pr T y, T_t + u.grad T =
    lap T. Run from the conduction profile to the steady state (the mean Nusselt number
    changes by less than ``tol`` over a time of 0.01). Nusselt numbers, the centre lines'
    velocity maxima and the throughput."""
    n = int(cells)
    n2 = 1 if dims == 2 else n
    dx = 1.0 / n
    flow = Flow((n, n, n2), dx, pr)
    x = (np.arange(n) + 0.5) * dx
    T = np.broadcast_to((0.5 - x)[:, None, None], (n, n, n2)).copy()
    Tn = np.empty_like(T)
    dt_diff = dx * dx / (2.0 * (2 if n2 == 1 else 3) * max(1.0, pr))
    t = 0.0
    steps = 0
    last_nu = None
    next_check = 0.01
    start = time.perf_counter()
    while t < t_max:
        dt = min(0.9 * dt_diff, flow.stable_dt(0.4))
        fk.temperature_step(T, flow.u, flow.v, flow.w, 1.0, dt, dx, 0.5, -0.5, Tn, flow.flat)
        flow.step(dt, ra * pr * T)
        T, Tn = Tn, T
        t += dt
        steps += 1
        if t >= next_check:
            next_check += 0.01
            nu = _mean_nusselt(T, flow, dx)
            if progress is not None:
                progress(t / t_max, t, nu)
            if last_nu is not None and abs(nu - last_nu) < tol * abs(nu) and t > 0.05:
                break
            last_nu = nu
    seconds = time.perf_counter() - start
    nu = _mean_nusselt(T, flow, dx)
    hot = 2.0 * (0.5 - T[0]) / dx  # -dT/dx at the hot wall (L / (k dT) units)
    mid_z = n2 // 2
    # the vertical centre line x = 1/2 (a face line when n is even) and the horizontal y = 1/2
    if n % 2 == 0:
        ucol = flow.u[n // 2, :, mid_z]
        vrow = flow.v[:, n // 2, mid_z]
    else:
        ucol = 0.5 * (flow.u[n // 2, :, mid_z] + flow.u[n // 2 + 1, :, mid_z])
        vrow = 0.5 * (flow.v[:, n // 2, mid_z] + flow.v[:, n // 2 + 1, mid_z])
    if n2 > 1 and n2 % 2 == 0:  # the cube's mid plane z = 1/2 between two cell layers
        ucol = 0.5 * (flow.u[n // 2, :, mid_z - 1] + ucol) if n % 2 == 0 else ucol
        vrow = 0.5 * (flow.v[:, n // 2, mid_z - 1] + vrow) if n % 2 == 0 else vrow
    u_max, ju = _peak_at(ucol)  # u sampled at the cell centres' heights (j + 1/2) dx
    v_max, iv = _peak_at(vrow)  # v at the cell centres' x
    return CavityResult(ra, n, nu, float(hot.mean()), u_max, v_max, steps, seconds,
                        n * n * n2 * steps / max(seconds, 1e-9), dims, (ju + 0.5) * dx,
                        (iv + 0.5) * dx)


def _mean_nusselt(T: np.ndarray, flow: Flow, dx: float) -> float:
    """The x heat flux (advection and conduction), averaged over every x face of the cavity
    (both walls included), in units of k dT / L."""
    inner = flow.u[1:-1] * 0.5 * (T[1:] + T[:-1]) - (T[1:] - T[:-1]) / dx
    hot = 2.0 * (0.5 - T[0]) / dx
    cold = 2.0 * (T[-1] + 0.5) / dx
    n0 = T.shape[0]
    return float((inner.sum(axis=0).mean() + hot.mean() + cold.mean()) / (n0 + 1))


# --- the melt --------------------------------------------------------------------------------

#: The flow in the melt is projected once an enthalpy step, and more often when the fastest
#: water would cross more than this fraction of a cell in between (its predictor keeps to
#: the explicit limits in parts of its own). Gallium (4 mm cells, 2-4 cm/s) moves by under
#: 0.01 of the width at 15 min between 0.4 and 0.9 (docs/stefan.md).
PROJECTION_CFL = 0.9
#: The flow in the melt is stepped every FLOW_EVERY enthalpy steps, for their time together
#: (its predictor still in parts under its limits, its heat carried in parts of under half a
#: cell): the conduction's step limit is far below the flow's time scales.
FLOW_EVERY = 2
#: the melt's projection incremental (:attr:`Flow.incremental`)
INCREMENTAL = True

MUSHY_CONSTANT = 1.6e6  # kg/m³s: the Carman-Kozeny constant C (Brent, Voller & Reid 1988)


def water_density_array(t: np.ndarray) -> np.ndarray:
    """Kell's (1975) density (kg/m³) of water at t °C, element by element."""
    num = (999.83952 + 16.945176 * t - 7.9870401e-3 * t ** 2 - 46.170461e-6 * t ** 3
           + 105.56302e-9 * t ** 4 - 280.54253e-12 * t ** 5)
    return num / (1.0 + 16.879850e-3 * t)


class MeltFlow:
    """The flow of the cavity's water inside the enthalpy solver's grid: a box of cells
    around the liquid (``box``: slices of the unpadded grid), stepped after every
    ``every`` enthalpy steps for their time together, carrying the liquid's sensible heat.
    Viscosity at 2 °C (1.67 mPa s; the Vogel
    equation of :mod:`whitted.stefan.convection`), constant."""

    G = 9.80665

    def __init__(self, box: tuple[slice, slice, slice], dx: float, props,
                 t_viscosity: float = 2.0, viscosity: float | None = None,
                 expansion: float | None = None, mushy: float | None = None) -> None:
        """``viscosity`` (kinematic, m²/s) and ``expansion`` (beta, 1/K: the Boussinesq
        buoyancy g beta (T - T_melt)) replace water's (Vogel's viscosity at ``t_viscosity``,
        Kell's density) for another liquid (the gallium benchmark); ``mushy`` the
        Carman-Kozeny constant (kg/m³s; default :data:`MUSHY_CONSTANT`)."""
        from .convection import water_density, water_viscosity

        self.box = box
        shape = tuple(s.stop - s.start for s in box)
        self.rho0 = water_density(0.0)
        self.expansion = expansion
        self.nu = (water_viscosity(t_viscosity) / water_density(t_viscosity)
                   if viscosity is None else float(viscosity))
        self.flow = Flow(shape, dx, self.nu)
        self.flow.incremental = INCREMENTAL
        self.props = props
        self.dx = float(dx)
        self._out = np.zeros(shape)
        self._buoy = np.zeros(shape)
        self._open = np.ones(shape)  # the faces' weights: the velocity is 0 off the fluid
        self.box0 = np.array([s.start + 1 for s in box], dtype=np.int64)  # padded indices
        #: the projection at least every time the fastest water crosses this much of a cell
        self.projection_cfl = PROJECTION_CFL
        #: stepped after every ``every`` enthalpy steps, for their time together
        self.every = FLOW_EVERY
        self.sink_c = (MUSHY_CONSTANT if mushy is None else float(mushy)) / props.water.rho
        self.time = 0.0
        #: tracer particles carried by the flow (for the film): positions in cell units of the
        #: box (a cell's centre at i + 1/2), seeded by :meth:`seed_tracers`
        self.tracers = np.zeros((0, 3))

    def projection_dt(self) -> float:
        """The longest step between two projections: the time the fastest water takes to
        cross ``projection_cfl`` of a cell (inf at rest). The predictor's stability limits
        are met by its parts (:meth:`Flow.step`)."""
        return self.projection_cfl * self.flow.advective_dt(1.0)

    def fields(self, Hp: np.ndarray, kindp: np.ndarray):
        """Liquid fraction, temperature and sensible heat (J/m³) of the box's cells."""
        b = tuple(slice(s.start + 1, s.stop + 1) for s in self.box)
        H = Hp[b]
        body = kindp[b] == 1
        hl = self.props.latent_per_volume
        f = np.where(body, np.clip(H / hl, 0.0, 1.0), 0.0)
        heat = np.where(body & (hl < H), H - hl, 0.0)
        T = heat / self.props.water.capacity
        return f, T, heat

    def step(self, Hp: np.ndarray, kindp: np.ndarray, dt: float) -> None:
        """One step of the flow with the field of now, then its heat carried into ``Hp``."""
        f, T, heat = self.fields(Hp, kindp)
        if self.expansion is None:
            buoy = self._buoy
            fk.kell_buoyancy(T, f, self.G, self.rho0, buoy)
        else:
            buoy = self.G * self.expansion * T * f
        sink = self.sink_c * (1.0 - f) ** 2 / (f ** 3 + 1.0e-3)
        self.flow.step(dt, buoy, sink, fluid=f >= 0.5, parts=True)
        # the heat goes with the new velocity: in as many parts as keep each under half a cell
        parts = max(1, int(math.ceil(self.speed() * dt / (0.5 * self.dx))))
        for q in range(parts):
            if q > 0:
                f, T, heat = self.fields(Hp, kindp)
            fk.advect_enthalpy(Hp, self.box0, self.flow.u, self.flow.v, self.flow.w,
                               self._open, heat, dt / parts, self.dx, self.flow.flat,
                               self._out)
            self.move_tracers(f, dt / parts)
        self.time += dt

    def seed_tracers(self, Hp: np.ndarray, kindp: np.ndarray, count: int = 48,
                     seed: int = 1) -> None:
        """``count`` tracers at random points of the liquid cells of now (a fixed seed: the
        same run seeds the same tracers)."""
        f, _, _ = self.fields(Hp, kindp)
        cells = np.argwhere(f >= 1.0)
        if len(cells) == 0:
            return
        rng = np.random.default_rng(seed)
        pick = cells[rng.integers(0, len(cells), size=count)]
        self.tracers = pick + rng.uniform(0.15, 0.85, size=(count, 3))

    def move_tracers(self, f: np.ndarray, dt: float) -> None:
        """Carry the tracers one step with the velocity at their cell (the mean of its faces);
        one that would leave the liquid (a cell under half liquid) stays where it is."""
        if len(self.tracers) == 0:
            return
        fl = self.flow
        idx = np.clip(self.tracers.astype(np.int64), 0, np.array(fl.shape) - 1)
        i, j, k = idx[:, 0], idx[:, 1], idx[:, 2]
        vel = np.stack([0.5 * (fl.u[i, j, k] + fl.u[i + 1, j, k]),
                        0.5 * (fl.v[i, j, k] + fl.v[i, j + 1, k]),
                        0.5 * (fl.w[i, j, k] + fl.w[i, j, k + 1])], axis=1)
        moved = self.tracers + vel * dt / self.dx
        new = np.clip(moved.astype(np.int64), 0, np.array(fl.shape) - 1)
        ok = (f[new[:, 0], new[:, 1], new[:, 2]] >= 0.5) & np.all(moved >= 0.0, axis=1) \
            & np.all(moved < np.array(fl.shape), axis=1)
        self.tracers[ok] = moved[ok]

    def tracer_points(self) -> np.ndarray:
        """The tracers in the unpadded grid's cell-index units (cell centres at integers)."""
        return self.tracers + np.array([s.start for s in self.box]) - 0.5

    def state(self) -> dict:
        """What a resumed run needs to go on with the flow as it was."""
        return {"flow_u": self.flow.u, "flow_v": self.flow.v, "flow_w": self.flow.w,
                "flow_pressure": self.flow.pressure, "flow_tracers": self.tracers,
                "flow_phi": self.flow._masked._phi,
                "flow_box": np.array([[s.start, s.stop] for s in self.box])}

    def restore(self, z) -> None:
        """The flow of a saved state (:meth:`state`), when its box is this one's."""
        if "flow_box" not in z or not np.array_equal(
                z["flow_box"], np.array([[s.start, s.stop] for s in self.box])):
            return
        self.flow.u[...] = z["flow_u"]
        self.flow.v[...] = z["flow_v"]
        self.flow.w[...] = z["flow_w"]
        if "flow_pressure" in z:  # (a state saved before the incremental projection: 0)
            self.flow.pressure[...] = z["flow_pressure"]
        if "flow_phi" in z:  # the pressure solve's last answer, its next first guess
            self.flow._masked._phi = np.array(z["flow_phi"], dtype=np.float64)
        self.tracers = np.array(z["flow_tracers"], dtype=np.float64).reshape(-1, 3)

    def speed(self) -> float:
        """The largest speed (m/s) on the faces now."""
        fl = self.flow
        return float(max(np.abs(fl.u).max(), np.abs(fl.v).max(), np.abs(fl.w).max()))


def cavity_box(kind_liquid: np.ndarray, margin: int) -> tuple[slice, slice, slice]:
    """The bounding box of the liquid cells, ``margin`` cells wider each way (clipped to the
    grid): where the flow is solved."""
    idx = np.argwhere(kind_liquid)
    if idx.size == 0:
        raise ValueError("no liquid cells: nothing flows")
    lo = np.maximum(idx.min(axis=0) - margin, 0)
    hi = np.minimum(idx.max(axis=0) + 1 + margin, kind_liquid.shape)
    return tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))  # type: ignore


def reynolds_like(speed: float, length: float, nu: float) -> float:
    return speed * length / nu if nu > 0 else math.inf


__all__ = ["CUBE_NU", "DE_VAHL_DAVIS", "CavityResult", "Flow", "MeltFlow", "Poisson", "cavity_box",
           "heated_cavity", "water_density_array"]
