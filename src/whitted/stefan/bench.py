"""``whitted stefan bench``: the solvers' throughput in cell updates a second, per thread count.

Two measurements, each a warm-up and then timed runs of a fixed number of steps, the thread
counts alternating run by run (a machine whose load drifts shares the drift between them):

- the enthalpy step (conduction, the surface's heat): the default case at ``cells`` cells a
  side with the cavity's convection off, ``steps`` steps a run;
- the flow solver (predictor, pressure by the cosine transform, correction, and the
  temperature it carries): the differentially heated cube at Ra 1e5 on ``flow_cells``³.

A cell update is one cell advanced one step. Reported per thread count: the median and best
run, the rate per thread, and the speed-up over one thread. Numba's thread count is set in
this process (``numba.set_num_threads``); SciPy's transforms take as many workers.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass, field


@dataclass
class Rates:
    """One solver's runs at one thread count: cell updates a second of each run."""

    solver: str
    threads: int
    cells: int
    steps: int
    runs: list[float] = field(default_factory=list)

    @property
    def median(self) -> float:
        return statistics.median(self.runs)

    @property
    def best(self) -> float:
        return max(self.runs)

    @property
    def per_thread(self) -> float:
        return self.median / self.threads


def _enthalpy_runner(cells: int):
    from .case import Case
    from .geometry import initial_state
    from .solver import EnthalpySolver

    case = Case.model_validate({"grid": {"cells": cells}, "cavity": {"convection": "off"}})
    H, kind, _, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                            faces=case.solver_faces(), air=case.solver_air(),
                            stop_on_breach=False)
    return solver.run_steps, H.size


def _flow_runner(cells: int, ra: float = 1.0e5, pr: float = 0.71):
    """One step of the cube of :func:`whitted.stefan.flow.heated_cavity` (fixed dt), from a
    flow that has run 200 steps (a developed boundary layer)."""
    import numpy as np

    from . import flow_kernels as fk
    from .flow import Flow

    n = int(cells)
    dx = 1.0 / n
    flow = Flow((n, n, n), dx, pr)
    x = (np.arange(n) + 0.5) * dx
    state = {"T": np.broadcast_to((0.5 - x)[:, None, None], (n, n, n)).copy()}
    Tn = np.empty_like(state["T"])
    dt = 0.9 * dx * dx / (6.0 * max(1.0, pr)) * 0.5

    def run(steps: int) -> int:
        T, out = state["T"], Tn
        for _ in range(steps):
            fk.temperature_step(T, flow.u, flow.v, flow.w, 1.0, dt, dx, 0.5, -0.5, out, False)
            flow.step(dt, ra * pr * T)
            T, out = out, T
        state["T"][...] = T
        return steps

    run(200)
    return run, flow, n ** 3


def measure(cells: int = 64, flow_cells: int = 48, threads: tuple[int, ...] = (1, 2),
            runs: int = 5, steps: int = 200, flow_steps: int = 40,
            progress=None) -> list[Rates]:
    """Both solvers at each thread count, ``runs`` timed runs each (after a warm-up), the
    thread counts alternating run by run."""
    import numba

    threads = tuple(max(1, min(int(t), numba.config.NUMBA_NUM_THREADS)) for t in threads)
    results: list[Rates] = []
    enthalpy, n_cells = _enthalpy_runner(cells)
    flow_run, flow, n_flow = _flow_runner(flow_cells)
    rows = {("enthalpy", t): Rates("enthalpy step", t, n_cells, steps) for t in threads}
    rows.update({("flow", t): Rates("flow (cube, Ra 1e5)", t, n_flow, flow_steps)
                 for t in threads})
    for t in threads:  # warm-up at each count (threads started, caches filled)
        numba.set_num_threads(t)
        flow.poisson.workers = t
        enthalpy(max(1, steps // 10))
        flow_run(max(1, flow_steps // 10))
    for r in range(runs):
        for t in threads:
            numba.set_num_threads(t)
            flow.poisson.workers = t
            t0 = time.perf_counter()
            done = enthalpy(steps)
            rows["enthalpy", t].runs.append(n_cells * done / (time.perf_counter() - t0))
            t0 = time.perf_counter()
            done = flow_run(flow_steps)
            rows["flow", t].runs.append(n_flow * done / (time.perf_counter() - t0))
            if progress is not None:
                progress(r, t)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    results = [rows["enthalpy", t] for t in threads] + [rows["flow", t] for t in threads]
    return results


__all__ = ["Rates", "measure"]
