"""Tiny Stefan-solver runs that reach every branch of ``stefan/kernels.py``: run by
tests/test_cov_stefan_kernels.py in its own process and, in a fresh process, with the other JIT
mode (``python tests/stefan_kernel_cases.py OUT.npz``), so that the kernels run once as plain
Python (``NUMBA_DISABLE_JIT=1``) and their results are compared with the compiled ones.

The body: a 5x5x5 block of ice just below melting (a shell) around a 3x3x3 core of warm
water, with one cold ice cell (-5 °C) and one warm water cell (+2 °C) on the shell, in the
corner of a grid of 9x7x7 cells whose other cells are air, plus one isolated cell of ice in
the air (its occupancy gradient is zero: scale 1). Grid faces the block touches: x- drains
at 30 °C (h 40), y- holds 20 °C (h inf), z- is adiabatic; the others a film of 15 W/m²K at
10 °C; the air around is 25 °C, h 20. The shell melts within a few steps, its cells drain
(become air), and the water core is reached (a breach)."""

from __future__ import annotations

import sys

import numpy as np

SHAPE = (9, 7, 7)
STEPS = 9


def build():
    from whitted.stefan.properties import Properties

    props = Properties()
    hl = props.latent_per_volume
    H = np.zeros(SHAPE)
    kind = np.zeros(SHAPE, dtype=np.uint8)
    kind[0:5, 0:5, 0:5] = 1
    H[0:5, 0:5, 0:5] = 0.97 * hl  # the shell: ice at 0 °C, 97 % melted
    H[1:4, 1:4, 1:4] = props.enthalpy(3.0, liquid=True)  # the core: water at 3 °C
    H[0, 2, 2] = props.enthalpy(-5.0, liquid=False)  # a cold ice cell on the x- face
    H[2, 0, 2] = props.enthalpy(2.0, liquid=True)  # a warm water cell on the y- face
    kind[7, 5, 5] = 1  # an isolated ice cell in the air
    H[7, 5, 5] = 0.5 * hl
    return props, H, kind


def solver(parallel: bool, stop_on_breach: bool):
    from whitted.stefan.solver import Air, EnthalpySolver, Faces

    props, H, kind = build()
    faces = Faces.adiabatic().set("x-", 40.0, 30.0, drain=True).set("y-", np.inf, 20.0)
    for face in ("x+", "y+", "z+"):
        faces.set(face, 15.0, 10.0)
    s = EnthalpySolver(H, kind, 1e-3, props, faces=faces, air=Air(25.0, 20.0),
                       stop_on_breach=stop_on_breach, rescale_every=3)
    s.parallel = parallel  # (a grid this small runs the serial kernel by itself)
    return s


def run() -> dict[str, np.ndarray]:
    """Every case's state after its steps, by name."""
    from whitted.stefan import kernels

    out: dict[str, np.ndarray] = {}
    for parallel in (False, True):
        for stop in (True, False):
            name = f"{'parallel' if parallel else 'serial'}_{'stop' if stop else 'drain'}"
            s = solver(parallel, stop)
            first = s.run_steps(STEPS)  # stop: ends at the breach's step
            second = s.run_steps(STEPS)
            out[name + "_H"] = s.H.copy()
            out[name + "_kind"] = s.kind.copy()
            out[name + "_totals"] = s.totals.copy()
            out[name + "_steps"] = np.array([first, second])
            out[name + "_breach"] = np.array([s.breached, s.breach_time or -1.0,
                                              s.energy_error(), s.enthalpy()])
    # the surface scale |n|_2/|n|_1 of ice at 0 °C (occupancy 1) at a flat face, an edge, a
    # corner of the block and at the isolated cell (padded indices: grid index + 1)
    props, _, kind = build()
    Hp = np.zeros(tuple(n + 2 for n in SHAPE))
    kp = np.pad(kind, 1, constant_values=kernels.GHOST)
    hl = props.latent_per_volume
    out["scale"] = np.array([kernels.surface_scale(Hp, kp, 5, 3, 3, hl),
                             kernels.surface_scale(Hp, kp, 5, 5, 3, hl),
                             kernels.surface_scale(Hp, kp, 5, 5, 5, hl),
                             kernels.surface_scale(Hp, kp, 8, 6, 6, hl)])
    return out


if __name__ == "__main__":
    np.savez(sys.argv[1], **run())
