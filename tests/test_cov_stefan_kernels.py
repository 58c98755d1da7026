"""The Stefan solver's kernels (stefan/kernels.py) as plain Python and compiled, on a tiny grid
whose runs reach every branch: cold ice and warm water on the surface, held, adiabatic,
draining and film faces, air around, an isolated cell, drains, a breach that stops the run
and one that drains the open cavity, the serial and the parallel kernel
(tests/stefan_kernel_cases.py describes the case)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import stefan_kernel_cases as cases  # noqa: E402
from other_jit import in_other_jit_mode  # noqa: E402

BODY_CELLS = 5 * 5 * 5 + 1


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(this process's results, the other JIT mode's results in a fresh process)."""
    here = cases.run()
    out = tmp_path_factory.mktemp("stefan_kernels") / "other.npz"
    return here, in_other_jit_mode("stefan_kernel_cases.py", out)


def test_plain_python_and_compiled_stefan_kernels_agree(runs):
    here, other = runs
    assert sorted(here) == sorted(other)
    for key, value in here.items():
        if key.endswith(("_kind", "_steps")):
            assert np.array_equal(value, other[key]), key
        else:  # no fast-math in these kernels: the same arithmetic, to round-off
            assert np.allclose(value, other[key], rtol=1e-12, atol=1e-9), key


def test_the_parallel_kernel_gives_the_serial_result_to_the_last_bit(runs):
    here, _ = runs
    for case in ("stop", "drain"):
        for what in ("H", "kind", "totals", "steps", "breach"):
            assert np.array_equal(here[f"parallel_{case}_{what}"],
                                  here[f"serial_{case}_{what}"]), (case, what)


def test_the_shell_drains_and_the_core_breaches(runs):
    here, _ = runs
    stop_steps = here["serial_stop_steps"]
    breached, breach_time, energy_error, enthalpy = here["serial_stop_breach"]
    # the first call stops at the breach's step, the next one runs all its steps
    assert 0 < stop_steps[0] < cases.STEPS and stop_steps[1] == cases.STEPS
    assert breached == 1.0 and breach_time > 0.0
    s = cases.solver(False, True)
    assert breach_time == pytest.approx(stop_steps[0] * s.dt)
    # the energy balance holds to round-off; every body cell is kept or counted drained
    for case in ("stop", "drain"):
        assert abs(here[f"serial_{case}_breach"][2]) < 1e-12 * max(1.0, enthalpy)
        drained = here[f"serial_{case}_totals"][3]
        assert drained + here[f"serial_{case}_kind"].sum() == BODY_CELLS
    # drain mode empties the opened cavity at once: fewer cells left than when stopped
    assert here["serial_drain_kind"].sum() < here["serial_stop_kind"].sum()
    assert here["serial_drain_totals"][2] == 0.0  # its breach signals were consumed


def test_surface_scale_is_the_ratio_of_the_normal_norms(runs):
    """|n|_2/|n|_1 of the Sobel occupancy gradient: 1 on a flat face, 1/sqrt(2) on an edge,
    1/sqrt(3) on a corner, 1 where the gradient vanishes (an isolated cell)."""
    here, other = runs
    expected = [1.0, 1 / math.sqrt(2), 1 / math.sqrt(3), 1.0]
    assert here["scale"] == pytest.approx(expected, rel=1e-15)
    assert other["scale"] == pytest.approx(expected, rel=1e-15)
