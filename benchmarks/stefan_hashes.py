"""SHA-256 of the Stefan solver's and the flow solver's results, to compare two trees bit for
bit: serial and parallel melts (3-D at 16 and 24 cells, a 2-D block of 48 x 48), melts with
the water's flow (12 and 20 cells), the square and the cubic heated cavity, and multigrid
pressure solves (a 3-D and a flat mask). Two threads. Run it in each tree and diff the output:

    PYTHONPATH=src WHITTED_CACHE_DIR=$PWD/.cache python benchmarks/stefan_hashes.py > a.txt

About 75 s of CPU on a 2-core AMD EPYC VM with the kernels cached.
"""

from __future__ import annotations

import hashlib

import numpy as np


def digest(*arrays) -> str:
    s = hashlib.sha256()
    for a in arrays:
        s.update(np.ascontiguousarray(np.asarray(a, dtype=np.float64)).tobytes())
    return s.hexdigest()[:16]


def melt(cells: int, parallel: bool, flow: bool, steps: int) -> str:
    from whitted.stefan.case import case_from_dict
    from whitted.stefan.geometry import initial_state
    from whitted.stefan.solver import EnthalpySolver

    case = case_from_dict({"grid": {"cells": cells},
                           "cavity": {"convection": "flow" if flow else "off"}})
    H, kind, _, _ = initial_state(case)
    s = EnthalpySolver(H, kind, case.dx, case.solver_properties(), faces=case.solver_faces(),
                       air=case.solver_air(), flow=case.solver_flow(H, kind) if flow else None)
    s.parallel = parallel
    s.stop_on_breach = False
    s.run_steps(steps)
    out = [s.H, s.kind, s.totals, [s.enthalpy(), s.steps, s.heat_in, s.drained]]
    if flow:
        out += [s.flow.flow.u, s.flow.flow.v, s.flow.flow.w]
    return digest(*out)


def block_2d(parallel: bool, n: int = 48) -> str:
    from whitted.stefan.properties import Properties
    from whitted.stefan.solver import Air, EnthalpySolver, Faces

    props = Properties()
    H = np.zeros((n, n, 1))
    kind = np.zeros((n, n, 1), dtype=np.uint8)
    kind[4:-4, 4:-4] = 1
    H[4:-4, 4:-4] = props.enthalpy(-2.0, liquid=False)
    s = EnthalpySolver(H, kind, 1e-3, props,
                       faces=Faces.adiabatic().set("x-", 50.0, 15.0, True), air=Air(25.0, 30.0))
    s.parallel = parallel
    s.stop_on_breach = False
    s.run_steps(3000)
    return digest(s.H, s.kind, s.totals, [s.enthalpy()])


def main() -> None:
    import numba

    from whitted.stefan import flow as fl
    from whitted.stefan.multigrid import Hierarchy

    numba.set_num_threads(2)
    rows = []
    for par in (False, True):
        rows.append((f"melt 3-D 16 parallel={par}", melt(16, par, False, 1500)))
        rows.append((f"melt 3-D 24 parallel={par}", melt(24, par, False, 800)))
        rows.append((f"melt 2-D 48x48x1 parallel={par}", block_2d(par)))
        rows.append((f"melt+flow 3-D 12 parallel={par}", melt(12, par, True, 600)))
    rows.append(("melt+flow 3-D 20 auto", melt(20, True, True, 300)))
    for dims, cells in ((2, 24), (3, 10)):
        r = fl.heated_cavity(1e4, cells, dims=dims, t_max=0.05)
        rows.append((f"cavity {dims}-D {cells}",
                     digest([r.nu, r.nu_wall, r.u_max, r.v_max, r.steps])))
    rng = np.random.default_rng(3)
    for shape in ((20, 24, 18), (30, 30, 1)):
        fluid = rng.random(shape) < 0.8
        hi = Hierarchy(fluid, 0.01)
        b = rng.standard_normal(fluid.size) * fluid.ravel()
        b -= b.mean()
        x = np.zeros(fluid.size)
        it = hi.solve(b, x, 1e-9)
        rows.append((f"multigrid {shape}", digest(x, [it], hi.apply(x))))
    for name, dig in rows:
        print(f"{dig}  {name}")


if __name__ == "__main__":
    main()
