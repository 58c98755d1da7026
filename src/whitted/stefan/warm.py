"""The Stefan solver's kernels compiled (or loaded) ahead of use, for ``whitted warm``: a few
steps of a tiny block of ice, with the serial and the parallel step kernel."""

from __future__ import annotations

import time

import numpy as np


def warm_stefan_kernels() -> float:
    """Compile or load every kernel a ``whitted stefan`` run calls; returns the seconds."""
    from .properties import Properties
    from .solver import Air, EnthalpySolver, Faces

    start = time.perf_counter()
    props = Properties()
    for parallel in (False, True):
        H = np.zeros((6, 6, 6))
        kind = np.zeros((6, 6, 6), dtype=np.uint8)
        kind[1:5, 1:5, 1:5] = 1
        H[1:5, 1:5, 1:5] = props.enthalpy(-1.0, liquid=False)
        solver = EnthalpySolver(H, kind, 1e-3, props, faces=Faces.adiabatic().set("x-", 20.0, 5.0),
                                air=Air(20.0, 10.0))
        solver.parallel = parallel
        solver.run_steps(2)
        solver.enthalpy()
    _warm_flow()
    return time.perf_counter() - start


def _warm_flow() -> None:
    """The flow's kernels (``cavity.convection = "flow"`` and the square-cavity check): one
    step of a tiny melt with its water flowing, and of a 2-D box of air."""
    from . import flow_kernels as fk
    from .case import case_from_dict
    from .flow import Flow
    from .geometry import initial_state
    from .solver import EnthalpySolver

    case = case_from_dict({"grid": {"cells": 8}, "cavity": {"radius": 0.008,
                                                            "convection": "flow"}})
    H, kind, _, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                            faces=case.solver_faces(), air=case.solver_air(),
                            flow=case.solver_flow(H, kind))
    solver.run_steps(solver.flow.every)  # (the flow steps after its every-th enthalpy step)
    flat = Flow((4, 4, 1), 0.25, 0.71)
    T = np.zeros((4, 4, 1))
    fk.temperature_step(T, flat.u, flat.v, flat.w, 1.0, 1e-3, 0.25, 0.5, -0.5, T.copy(), True)
    flat.step(1e-3, T)
