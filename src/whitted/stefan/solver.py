"""The enthalpy-method solver: state on a fixed 3-D grid, the stability limit, time stepping
with energy bookkeeping and breach detection.

>>> solver = EnthalpySolver(H, kind, dx, props, faces=Faces.adiabatic(), air=Air(22, 15))
>>> solver.advance(60.0)                                  # doctest: +SKIP
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from . import kernels
from .properties import Properties

PARALLEL_MIN_ROWS = 16
FACE_NAMES = ("x-", "x+", "y-", "y+", "z-", "z+")


@dataclass
class Faces:
    """The six outer faces of the grid: heat transfer coefficient h (W/m²K; 0 adiabatic,
    inf a held temperature), far temperature (°C), drain (meltwater leaves through it)."""

    h: np.ndarray = field(default_factory=lambda: np.zeros(6))
    temperature: np.ndarray = field(default_factory=lambda: np.zeros(6))
    drain: np.ndarray = field(default_factory=lambda: np.zeros(6, dtype=np.uint8))

    @classmethod
    def adiabatic(cls) -> Faces:
        return cls()

    def set(self, face: str, h: float, temperature: float = 0.0, drain: bool = False) -> Faces:
        n = FACE_NAMES.index(face)
        self.h[n] = h
        self.temperature[n] = temperature
        self.drain[n] = 1 if drain else 0
        return self


@dataclass(frozen=True)
class Air:
    """The air around the body: its temperature (°C) and heat transfer coefficient h; or,
    with ``faces``, a film (h, temperature) per face direction in ``FACE_NAMES`` order
    (``air.h = "auto"``: natural convection per face, :mod:`whitted.stefan.convection`);
    ``h`` is then the largest (the stability limit's)."""

    temperature: float
    h: float
    faces: tuple[tuple[float, float], ...] | None = None

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """h and far temperature per face direction (x-, x+, y-, y+, z-, z+)."""
        if self.faces is None:
            return np.full(6, float(self.h)), np.full(6, float(self.temperature))
        return (np.array([float(f[0]) for f in self.faces]),
                np.array([float(f[1]) for f in self.faces]))


def stability_limit(props: Properties, dx: float, dims: int, faces: Faces, air: Air) -> float:
    """The largest explicit step (s) that keeps every cell's update a convex combination of
    its own and its neighbours' temperatures (hence stable and free of oscillation).

    A cell of phase p with capacity C_p changes by ``dt/(C_p dx²) * sum_f a_f (T_f - T)``;
    positivity needs ``dt * sum_f a_f <= C_p dx²``. An interior face has ``a = k_face``
    (harmonic mean, at most max(k_p, 2 k_p k_q/(k_p + k_q))); a face to the outside has
    ``a = dx / (1/h + dx/(2 k_p)) <= 2 k_p``. A cell has 2*dims faces, of which at most dims
    can be outer (a corner). Mushy cells (0 °C) have unbounded capacity and never limit.
    """
    out = math.inf
    phases = (props.ice, props.water)
    h_values = [float(h) for h in faces.h if h > 0.0] + ([air.h] if air.h > 0 else [])
    for me in phases:
        interior = max(me.k, *(2 * me.k * o.k / (me.k + o.k) for o in phases))
        boundary = 0.0
        for h in h_values:
            film = 0.0 if math.isinf(h) else 1.0 / h
            boundary = max(boundary, dx / (film + 0.5 * dx / me.k))
        worst = 2 * dims * interior + dims * max(0.0, boundary - interior)
        out = min(out, me.capacity * dx * dx / worst)
    return out


class EnthalpySolver:
    """Explicit fixed-grid enthalpy method (Voller; Alexiades & Solomon).

    ``H`` enthalpy per volume (J/m³, float64, 3-D: a 1-D problem is shape (n, 1, 1)), ``kind``
    0 air / 1 body (uint8), ``dx`` the cubic cell's side (m). ``dt`` defaults to ``cfl`` times
    the stability limit; a given ``dt`` above the limit raises ValueError.
    """

    def __init__(self, H: np.ndarray, kind: np.ndarray, dx: float, props: Properties,
                 faces: Faces | None = None, air: Air | None = None, dt: float | None = None,
                 cfl: float = 0.9, stop_on_breach: bool = True, time: float = 0.0,
                 rescale_every: int = 8, convection=None, flow=None) -> None:
        if H.ndim != 3 or H.shape != kind.shape:
            raise ValueError("H and kind must be 3-D arrays of one shape")
        self.dx = float(dx)
        self.props = props
        self.faces = faces or Faces.adiabatic()
        self.air = air or Air(0.0, 0.0)
        self.dims = sum(1 for n in H.shape if n > 1) or 1
        self.dt_limit = stability_limit(props, self.dx, self.dims, self.faces, self.air)
        if dt is None:
            dt = cfl * self.dt_limit
        elif dt > self.dt_limit:
            raise ValueError(f"time step {dt:g} s is over the stability limit "
                             f"{self.dt_limit:.4g} s")
        # the cavity water's flow (flow.MeltFlow): stepped after every enthalpy step, projected
        # once or more (MeltFlow.projection_dt), its predictor in parts within its limits
        self.flow = flow
        self.dt = float(dt)
        self.stop_on_breach = stop_on_breach
        # the cavity water's effective conductivity (convection.CavityConvection), refreshed
        # every ``convection.every`` steps (counted from the start: chunking changes nothing);
        # the time step is chosen for its largest value (``props`` carry it)
        self.convection = convection
        self._k_set = False
        if convection is not None:
            convection.every = max(1, int(round(convection.interval / self.dt)))
        self.rescale_every = int(rescale_every)
        self.time = float(time)
        self.steps = 0
        # A 1-D line along x or y is stored along z (the kernels work a plane at a time: a line
        # along x is n planes of one cell, 4.8x slower than one plane of n cells; measured
        # 2.63 s against 0.54 s for 20,000 steps of 400 cells). Only the axes' order changes:
        # one nonzero face per cell either way, so the same bits.
        self._perm = (0, 1, 2)
        if sum(1 for n in H.shape if n > 1) == 1 and H.shape[2] == 1:
            long_axis = int(np.argmax(H.shape))
            self._perm = tuple(a for a in range(3) if a != long_axis) + (long_axis,)
        self._inverse = tuple(int(i) for i in np.argsort(self._perm))
        H = np.transpose(np.asarray(H), self._perm)
        kind = np.transpose(np.asarray(kind), self._perm)
        # padded arrays: one ghost cell on every side (kind GHOST, conductivity 0)
        shape = tuple(n + 2 for n in H.shape)
        self._Hp = np.zeros(shape)
        self._Hp[1:-1, 1:-1, 1:-1] = H
        self._kindp = np.full(shape, kernels.GHOST, dtype=np.uint8)
        self._kindp[1:-1, 1:-1, 1:-1] = np.where(np.asarray(kind) == 1, 1, 0)
        self._Hp[self._kindp != 1] = 0.0
        self._Hn = np.zeros(shape)
        # slabs of x planes are the parallel unit (one per thread); 1-D and thin grids run in
        # one thread (measured with the earlier row-parallel kernels: the parallel kernel was
        # faster from 24³ up, 164 vs 69 M cell updates per CPU-second)
        # whatever the orientation: a grid is thin (serial) unless it has at least 4 x planes
        # and PARALLEL_MIN_ROWS cells per plane (a 1-D line along x ran the parallel kernel
        # with one cell per plane: 4.5x slower than the same line along z)
        self.parallel = (H.shape[0] >= 4 and H.shape[1] * H.shape[2] >= PARALLEL_MIN_ROWS
                         and H.size >= 4096)  # thin grids: serial, whatever the orientation
        # totals: heat in (J/m² per face), drained (J/m³ per cell), breach signals, drained
        self.totals = np.zeros(4)
        self.breached = False
        self.breach_time: float | None = None
        self._p = props.as_array()
        self._face_arrays()
        self._build_surface()
        self.initial_enthalpy = self.enthalpy()

    @property
    def H(self) -> np.ndarray:
        """Enthalpy per volume (J/m³) of every cell (a view; air cells 0)."""
        return np.transpose(self._Hp[1:-1, 1:-1, 1:-1], self._inverse)

    @property
    def kind(self) -> np.ndarray:
        """0 air, 1 body, per cell (a view)."""
        return np.transpose(self._kindp[1:-1, 1:-1, 1:-1], self._inverse)

    def _face_arrays(self) -> None:
        f = self.faces
        order = [2 * self._perm[a] + side for a in range(3) for side in (0, 1)]
        self._face_h = np.asarray(f.h, dtype=np.float64)[order].copy()
        self._face_t = np.asarray(f.temperature, dtype=np.float64)[order].copy()
        self._face_drain = np.asarray(f.drain, dtype=np.uint8)[order].copy()
        air_h, air_t = self.air.arrays()
        self._air_h = air_h[order].copy()
        self._air_t = air_t[order].copy()

    def _build_surface(self) -> None:
        cells = max(1, int((self._kindp == 1).sum()))
        self._surface = np.zeros((cells, 3), dtype=np.int64)
        self._scale = np.full(cells, -1.0)
        self._is_surface = np.zeros(self._kindp.shape, dtype=np.uint8)
        self._n_surface = np.zeros(1, dtype=np.int64)
        self._n_surface[0] = kernels.find_surface(self._kindp, self._face_h, self._air_h,
                                                  self._surface, self._is_surface)

    # --- time stepping -------------------------------------------------------------------
    def run_steps(self, n: int) -> int:
        """Up to n steps; fewer at the first sign of a breach (checked here on the field: a
        true one sets ``breach_time``; in drain mode the cavity's water open to the air then
        drains, and the next call goes on)."""
        if self.flow is not None:
            done = 0
            while done < n:
                did = self._run(1)
                if did == 0:
                    break
                done += 1
                every = max(1, int(self.flow.every))  # the flow every that many steps
                if self.steps % every != 0:  # (counted from the start: chunks change nothing)
                    if self.breached and self.stop_on_breach:
                        break
                    continue
                left = every * self.dt  # projected once, or more often at the speed of now
                while left > 1e-12 * self.dt:
                    h = min(left, self.flow.projection_dt())
                    if left - h < 0.05 * h:
                        h = left
                    self.flow.step(self._Hp, self._kindp, h)
                    left -= h
                if self.breached and self.stop_on_breach:
                    break
            return done
        if self.convection is not None:
            done = 0
            while done < n:
                if self.steps % self.convection.every == 0 or not self._k_set:
                    self._k_set = True  # (a resumed run refreshes it at once)
                    self._p[kernels.P_KW] = self.convection.conductivity(
                        self.H, self.kind, self.dx, self.props)
                m = min(n - done, self.convection.every - self.steps % self.convection.every)
                did = self._run(m)
                done += did
                if did < m or (self.breached and self.stop_on_breach):
                    break  # a breach (even on a refresh's last step) stops as without
            return done
        return self._run(n)

    def _run(self, n: int) -> int:
        args = ()
        runner = kernels.run_steps_serial
        if self.parallel:  # one slab of x planes per thread
            runner = kernels.run_steps_parallel
            args = (numba.get_num_threads(),)
        done = runner(self._Hp, self._kindp, self._Hn, self._p, self.dt, self.dx, self._face_h,
                      self._face_t, self._face_drain,
                      self._air_h, self._air_t, self._surface,
                      self._scale, self._n_surface, self._is_surface, int(n), self.totals,
                      not self.breached, self.rescale_every, self.steps, *args)
        self.steps += done
        self.time += done * self.dt
        if self.totals[2] > 0:
            if not self.breached:
                if self._confirm_breach():
                    self.breached = True
                    self.breach_time = self.time
                    if not self.stop_on_breach:
                        self.drain_open_water()
            elif not self.stop_on_breach:
                self.drain_open_water()  # more of the cavity opened
        return done

    def advance(self, t_end: float, chunk: int = 2000, should_stop=None, on_chunk=None) -> bool:
        """Step until ``t_end`` (the last step shortened to land on it) or a breach stop.
        ``should_stop()`` is asked between chunks of steps (False: go on); returns False when
        it stopped the run before ``t_end``. The chunking never changes the result."""
        while self.time < t_end - 1e-9 * max(1.0, t_end):
            if should_stop is not None and should_stop():
                return False
            n = int(math.floor((t_end - self.time) / self.dt + 1e-9))
            if n == 0:  # land exactly on t_end with one short step (still stable)
                full = self.dt
                self.dt = t_end - self.time
                self.run_steps(1)
                self.dt = full
                self.time = t_end
                break
            self.run_steps(min(n, chunk))
            if on_chunk is not None:
                on_chunk()
            if self.breached and self.stop_on_breach:
                return True
        return True

    def _open_cavity(self) -> np.ndarray:
        """The cavity's water open to the air: the bodies of cells at least half liquid
        (6-connected) that hold a cell without a face to the air (above the table's layer,
        which a conducting table melts) and touch the air. Empty before a breach."""
        from scipy import ndimage

        from .measures import outer_cells

        faces = ndimage.generate_binary_structure(3, 1)
        wet = (self.kind == 1) & (0.5 * self.props.latent_per_volume <= self.H)
        labels, n = ndimage.label(wet, structure=faces)
        if n == 0 or not (self.kind == 0).any():
            return np.zeros(self.H.shape, dtype=bool)
        open_cells = outer_cells(self.kind)
        inner = wet & ~open_cells
        inner[:, 0, :] = False
        index = np.arange(n + 1)
        has_inner = ndimage.sum_labels(inner, labels, index) > 0
        touches = ndimage.sum_labels(wet & open_cells, labels, index) > 0
        chosen = has_inner & touches
        chosen[0] = False
        return chosen[labels]

    def _confirm_breach(self) -> bool:
        """The kernel's signal (a cell drained next to an inner cell at least half liquid),
        checked on the field: the cavity's water reaches the air (``_open_cavity``)."""
        if self._open_cavity().any():
            return True
        self.totals[2] = 0.0  # a false alarm
        return False

    def drain_open_water(self) -> int:
        """Drain the cavity's water open to the air (after a breach, in 'drain' mode): those
        cells become air and their enthalpy is counted as drained. Returns cells."""
        cells = self._open_cavity()
        self.totals[2] = 0.0
        if not cells.any():
            return 0
        self.totals[1] += float(self.H[cells].sum())
        self.totals[3] += float(cells.sum())
        self.H[cells] = 0.0
        self.kind[cells] = 0
        self._build_surface()  # the cavity's wall is now a surface to the air
        return int(cells.sum())

    # --- measures ------------------------------------------------------------------------
    def enthalpy(self) -> float:
        """Total enthalpy of the body (J)."""
        return float(kernels.total_enthalpy(self._Hp, self._kindp)) * self.dx ** 3

    @property
    def heat_in(self) -> float:
        """Heat that crossed the boundary into the body since the start (J)."""
        return float(self.totals[0]) * self.dx ** 2

    @property
    def drained(self) -> float:
        """Enthalpy carried away by drained meltwater since the start (J)."""
        return float(self.totals[1]) * self.dx ** 3

    def energy_error(self) -> float:
        """(H_now - H_0) - (heat in - drained), J: zero to round-off."""
        return (self.enthalpy() - self.initial_enthalpy) - (self.heat_in - self.drained)

    def temperature(self) -> np.ndarray:
        return np.where(self.kind == 1, self.props.temperature(self.H), np.nan)

    def liquid_fraction(self) -> np.ndarray:
        """Liquid fraction of every cell (air cells: 0)."""
        return np.where(self.kind == 1, self.props.liquid_fraction(self.H), 0.0)

    def melted_length(self, axis: int = 0) -> float:
        """Sum of liquid fractions times dx along a 1-D grid: the front position of a
        one-sided melt (m)."""
        return float(self.liquid_fraction().sum()) * self.dx / (self.H.size / self.H.shape[axis])
