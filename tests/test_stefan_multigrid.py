"""The melt's pressure solve: multigrid-preconditioned conjugate gradients on the fluid cells
of a box (the graph Laplacian, no flux to other cells) gives back a known solution's gradient,
in a few iterations, with the same bits on one thread as on two; and the flow's masked
projection leaves no more divergence than its tolerance."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.stefan.flow import Flow
from whitted.stefan.multigrid import Hierarchy


def _sphere(shape, radius):
    c = [(n - 1) / 2 for n in shape]
    grids = np.meshgrid(*[np.arange(n) - cc for n, cc in zip(shape, c, strict=True)],
                        indexing="ij")
    r2 = sum(g * g for g, n in zip(grids, shape, strict=True) if n > 1)
    return r2 <= radius * radius


def _graph_laplacian(phi, fluid, dx):
    """-div(grad phi) on the fluid cells by NumPy (faces open when both cells are fluid)."""
    out = np.zeros(phi.shape)
    for a in range(3):
        if phi.shape[a] < 2:
            continue
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[a] = slice(0, -1)
        hi[a] = slice(1, None)
        lo, hi = tuple(lo), tuple(hi)
        flux = np.where(fluid[lo] & fluid[hi], phi[hi] - phi[lo], 0.0) / dx ** 2
        out[lo] -= flux
        out[hi] += flux
    return out


def _jacobi_cg_iterations(h, b, tol):
    d = h.d[:b.size].reshape(b.shape)
    inv = np.where(d > 0, 1.0 / np.where(d > 0, d, 1.0), 0.0)
    x = np.zeros(b.shape)
    r = b.copy()
    z = inv * r
    p = z.copy()
    rz = float((r * z).sum())
    for it in range(1, 5000):
        q = h.apply(p)
        alpha = rz / float((p * q).sum())
        x += alpha * p
        r -= alpha * q
        if np.linalg.norm(r) <= tol:
            return it
        z = inv * r
        rz, old = float((r * z).sum()), rz
        p = z + rz / old * p
    return 5000


@pytest.mark.parametrize("shape, radius", [((21, 19, 18), 8.5), ((30, 22, 1), 40.0)])
def test_the_solve_returns_a_known_solutions_gradient(shape, radius):
    rng = np.random.default_rng(7)
    fluid = _sphere(shape, radius)
    fluid[0, 0, 0] = True  # a lone fluid cell, cut off from the rest: left alone
    fluid[0, 1, 0] = False
    fluid[1, 0, 0] = False
    dx = 1e-3
    h = Hierarchy(fluid, dx)
    assert h.levels >= 3
    phi = np.where(fluid, rng.normal(size=shape), 0.0)
    b = _graph_laplacian(phi, fluid, dx)
    # the operator is the graph Laplacian (less its 1e-10 shift)
    np.testing.assert_allclose(h.apply(phi), b + 1e-10 * (h.d.reshape(-1)[:phi.size]
                                                          .reshape(shape) * phi) / (1 + 1e-10),
                               rtol=0, atol=1e-6 * np.abs(b).max())
    x = np.zeros(phi.size)
    its = h.solve(b.ravel(), x, 1e-10 * np.linalg.norm(b))
    # a fifth or less of what conjugate gradients preconditioned by the diagonal need
    assert its <= 0.2 * _jacobi_cg_iterations(h, b, 1e-10 * np.linalg.norm(b))
    x = x.reshape(shape)
    for a in range(3):
        if shape[a] < 2:
            continue
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[a] = slice(0, -1)
        hi[a] = slice(1, None)
        open_ = fluid[tuple(lo)] & fluid[tuple(hi)]
        got = (x[tuple(hi)] - x[tuple(lo)])[open_]
        want = (phi[tuple(hi)] - phi[tuple(lo)])[open_]
        assert np.abs(got - want).max() < 1e-7 * np.abs(want).max()


def test_the_solve_has_the_same_bits_on_one_thread_and_two():
    import numba

    fluid = _sphere((24, 24, 24), 10.0)
    rng = np.random.default_rng(3)
    b = np.where(fluid, rng.normal(size=fluid.shape), 0.0)
    b[fluid] -= b[fluid].mean()
    found = []
    before = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            h = Hierarchy(fluid, 1e-3)
            x = np.zeros(b.size)
            h.solve(b.ravel(), x, 1e-9 * np.linalg.norm(b))
            found.append(x)
    finally:
        numba.set_num_threads(before)
    assert np.array_equal(found[0], found[1])


def test_the_masked_projection_leaves_the_divergence_its_tolerance_allows():
    rng = np.random.default_rng(5)
    shape = (16, 16, 16)
    fluid = _sphere(shape, 6.5)
    flow = Flow(shape, 1e-3, 1e-6)
    flow.u[1:-1] = rng.normal(size=flow.u[1:-1].shape) * 1e-3
    flow.v[:, 1:-1] = rng.normal(size=flow.v[:, 1:-1].shape) * 1e-3
    flow.w[:, :, 1:-1] = rng.normal(size=flow.w[:, :, 1:-1].shape) * 1e-3
    dt = 0.05
    flow.project(dt, fluid)
    div = flow._div
    from whitted.stefan import flow_kernels as fk

    fk.divergence(flow.u, flow.v, flow.w, flow.dx, div, False)
    rms = float(np.sqrt(np.mean(div[fluid] ** 2)))
    # the tolerance: a fluid cell's volume changes by at most 1e-10 of itself a step (rms)
    assert rms * dt <= flow.volume_tolerance
    assert flow._masked.iterations <= 12
    # no flow through the faces of the cells that are not fluid
    assert np.all(flow.u[1:-1][~(fluid[1:] & fluid[:-1])] == 0.0)
    assert np.abs(div[~fluid]).max() == 0.0
