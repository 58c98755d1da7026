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
    return time.perf_counter() - start
