"""The enthalpy step of two (or more) source trees side by side: cell updates a second of the
default case (cavity convection off where the tree has it), each tree in a fresh process,
the trees and thread counts interleaved round by round, ratios to the first tree.

    python benchmarks/stefan_ab.py OLD_TREE NEW_TREE [--cells 64] [--rounds 3] [--threads 1,2]

A tree is a checkout's root (``git worktree add ../whitted-old f9bebe4``); its ``src`` goes
first on PYTHONPATH and its kernels are cached in its own ``.cache``. It works with trees from
before ``whitted stefan bench`` (the case API of then is bridged below). Each measurement is
``--reps`` runs of ``--steps`` steps after a warm-up: the best and the median run are printed,
the best being the least disturbed on a shared machine. The CPU is printed first: compare
figures only within one run of this script.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import sys, time
import numba
from whitted.stefan.case import Case
from whitted.stefan.geometry import initial_state
from whitted.stefan.solver import EnthalpySolver
cells, steps, reps = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
try:
    case = Case.model_validate({"grid": {"cells": cells}, "cavity": {"convection": "off"}})
except Exception:  # a tree from before the cavity's convection
    case = Case.model_validate({"grid": {"cells": cells}})
H, kind = initial_state(case)[:2]
if hasattr(case, "solver_air"):
    air = case.solver_air()
else:
    from whitted.stefan.solver import Air
    air = Air(case.air.temperature, case.air.h)
props = case.solver_properties() if hasattr(case, "solver_properties") else case.properties
s = EnthalpySolver(H, kind, case.dx, props, faces=case.solver_faces(), air=air)
s.stop_on_breach = False
s.run_steps(5)
rates = []
for _ in range(reps):
    t = time.perf_counter()
    done = s.run_steps(steps)
    rates.append(H.size * done / (time.perf_counter() - t))
print(numba.get_num_threads(), max(rates), sorted(rates)[len(rates) // 2])
"""


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def measure(tree: Path, threads: int, cells: int, steps: int, reps: int) -> tuple[float, float]:
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads), PYTHONPATH=str(tree / "src"),
               WHITTED_CACHE_DIR=str(tree / ".cache"))
    done = subprocess.run([sys.executable, "-c", CHILD, str(cells), str(steps), str(reps)],
                          cwd=tree, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: {done.stderr.strip().splitlines()[-1:]}")
    _, best, median = done.stdout.split()[-3:]
    return float(best), float(median)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs="+", type=Path)
    ap.add_argument("--cells", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--reps", type=int, default=60)
    a = ap.parse_args()
    counts = [int(t) for t in a.threads.split(",")]
    print(f"CPU: {cpu_name()}; load average {os.getloadavg()[0]:.2f}")
    found: dict[tuple[str, int], list[tuple[float, float]]] = {}
    for r in range(a.rounds):
        for t in counts:
            for tree in a.trees:
                best, median = measure(tree.resolve(), t, a.cells, a.steps, a.reps)
                found.setdefault((str(tree), t), []).append((best, median))
                print(f"round {r + 1} {tree} threads {t}: best {best / 1e6:.1f}, median "
                      f"{median / 1e6:.1f} M cell updates/s (load {os.getloadavg()[0]:.2f})",
                      flush=True)
    first = str(a.trees[0])
    print("summary (median over rounds of each round's best and median; ratio to the first "
          "tree):")
    for t in counts:
        for tree in a.trees:
            rows = found[str(tree), t]
            best = statistics.median(b for b, _ in rows)
            median = statistics.median(m for _, m in rows)
            ref = found[first, t]
            ratios = [b / rb for (b, _), (rb, _) in zip(rows, ref, strict=True)]
            print(f"  {tree} threads {t}: best {best / 1e6:.1f}, median {median / 1e6:.1f} M/s; "
                  f"best/first per round {', '.join(f'{x:.2f}' for x in ratios)}")


if __name__ == "__main__":
    main()
