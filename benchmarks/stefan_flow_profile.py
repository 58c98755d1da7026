"""Where a step of the Stefan solver with the water's flow spends its time: wall and CPU
seconds per phase (pressure solve, predictor, enthalpy step, ...) over a number of steps
from the start of a case whose cavity has ``convection = "flow"``.

    python benchmarks/stefan_flow_profile.py CASE.toml [--threads 2] [--steps 300] [--whole]

The case is the example ``examples/stefan/hollow_ice.toml`` with its cavity's convection
set to ``"flow"`` (48 cells: the default case with the flow). Ten steps warm up first (and
compile on a cold cache). ``--whole`` times the step only, without wrapping each phase (for
trees whose internals differ). The CPU and the load are printed first: compare figures only
within one run on one machine.
"""

from __future__ import annotations

import argparse
import time
import tomllib


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--whole", action="store_true", help="time whole steps only")
    args = parser.parse_args()

    import numba

    from whitted.machine import cpu_name, load_average
    from whitted.stefan import flow_kernels
    from whitted.stefan.case import Case
    from whitted.stefan.geometry import initial_state
    from whitted.stefan.solver import EnthalpySolver

    load = load_average()
    print(f"CPU: {cpu_name()}; load average {'unknown' if load is None else f'{load:.2f}'}")
    numba.set_num_threads(args.threads)
    with open(args.case, "rb") as f:
        case = Case.model_validate(tomllib.load(f))
    H, kind, _, _ = initial_state(case)
    solver = EnthalpySolver(H, kind, case.dx, case.solver_properties(),
                            faces=case.solver_faces(), air=case.solver_air(), dt=case.time.dt,
                            cfl=case.time.cfl, flow=case.solver_flow(H, kind))
    wall: dict[str, float] = {}
    cpu: dict[str, float] = {}

    def wrap(obj, name: str, key: str) -> None:
        inner = getattr(obj, name)

        def timed(*a, **k):
            t0, c0 = time.perf_counter(), time.process_time()
            result = inner(*a, **k)
            wall[key] = wall.get(key, 0.0) + time.perf_counter() - t0
            cpu[key] = cpu.get(key, 0.0) + time.process_time() - c0
            return result

        setattr(obj, name, timed)

    if not args.whole:
        for name in ("predict", "predict_inner", "divergence", "correct", "advect_enthalpy",
                     "kell_buoyancy"):
            if hasattr(flow_kernels, name):
                wrap(flow_kernels, name, name)
        masked = solver.flow.flow._masked
        wrap(masked, "solve", "pressure (masked solve)")
        wrap(masked, "zero_closed", "zero_closed")
        wrap(solver.flow, "fields", "fields")
        wrap(solver, "_run", "enthalpy step")
    solver.run_steps(10)
    wall.clear()
    cpu.clear()
    t0, c0 = time.perf_counter(), time.process_time()
    solver.run_steps(args.steps)
    w, c = time.perf_counter() - t0, time.process_time() - c0
    u = solver.flow.flow.u
    box = u.shape[1] * u.shape[2] * (u.shape[0] - 1)
    print(f"threads {args.threads}: {args.steps} steps in {w:.2f} s wall, {c:.2f} s CPU; "
          f"{1e3 * w / args.steps:.2f} ms a step; grid {H.size} cells, flow box {box} cells; "
          f"{H.size * args.steps / c / 1e6:.1f} M enthalpy cell-updates per CPU second, "
          f"{box * args.steps / c / 1e6:.2f} M flow box cell-steps per CPU second")
    for key in sorted(wall, key=lambda k: -cpu[k]):
        print(f"  {key:26s} {wall[key]:7.2f} s wall {cpu[key]:7.2f} s CPU "
              f"({100 * cpu[key] / c:4.1f} %)")
    masked = getattr(solver.flow.flow, "_masked", None)
    if masked is not None and getattr(masked, "solves", 0):
        print(f"  pressure: {masked.solves} solves, "
              f"{masked.total_iterations / masked.solves:.1f} iterations each")


if __name__ == "__main__":
    main()
