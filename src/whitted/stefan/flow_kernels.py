"""The flow solver's Numba kernels: incompressible Navier-Stokes on a staggered (MAC) grid of
cubic cells, explicit in time, parallel over the first axis (both cores).

Velocities live on the faces: ``u`` (n0 + 1, n1, n2) along axis 0, ``v`` (n0, n1 + 1, n2)
along axis 1, ``w`` (n0, n1, n2 + 1) along axis 2; the box's walls are no-slip (the normal
component is 0 on the wall faces, the tangential one mirrored in a ghost). One predictor
kernel serves all three components: the v and w equations are the u equation on transposed
views (axes 1, 0, 2 and 2, 1, 0), so every term is written once. ``flat``: a 2-D problem
(n2 = 1, no w, no walls along axis 2).

Advection in conservative central form, diffusion by the 7-point Laplacian, a body force on
the faces (the mean of the two cells' buoyancy) and an enthalpy-porosity sink ``a`` (1/s, per
cell; its face value the mean of the two cells') taken implicitly: u* = (u + dt RHS) /
(1 + dt a), so any sink is stable and a solid cell's velocity is driven to 0.
"""

from __future__ import annotations

from ..jit import builder, numba_object

#: Numba's parallel range, in the kernels' globals once Numba is loaded (jit/decorators.py)
prange = numba_object("numba", "prange")


@builder(entry=False, error_model="numpy", numba_inline=True)
def _predict_at(q, p, r, visc, inv, dt, force, sink, out, flat, i, j, k):
    """The predictor at face (i, j, k) of the views (:func:`predict`)."""
    n1 = q.shape[1]
    n2 = q.shape[2]
    qc = q[i, j, k]
    qe = q[i + 1, j, k]
    qw = q[i - 1, j, k]
    ce = 0.5 * (qc + qe)
    cw = 0.5 * (qw + qc)
    adv = (ce * ce - cw * cw) * inv
    lap = qe + qw - 2.0 * qc
    qn = q[i, j + 1, k] if j < n1 - 1 else -qc
    qs = q[i, j - 1, k] if j > 0 else -qc
    pn = 0.5 * (p[i - 1, j + 1, k] + p[i, j + 1, k])
    ps = 0.5 * (p[i - 1, j, k] + p[i, j, k])
    adv += (0.5 * (qc + qn) * pn - 0.5 * (qc + qs) * ps) * inv
    lap += qn + qs - 2.0 * qc
    if not flat:
        qt = q[i, j, k + 1] if k < n2 - 1 else -qc
        qb = q[i, j, k - 1] if k > 0 else -qc
        rt = 0.5 * (r[i - 1, j, k + 1] + r[i, j, k + 1])
        rb = 0.5 * (r[i - 1, j, k] + r[i, j, k])
        adv += (0.5 * (qc + qt) * rt - 0.5 * (qc + qb) * rb) * inv
        lap += qt + qb - 2.0 * qc
    f = 0.5 * (force[i - 1, j, k] + force[i, j, k])
    a = 0.5 * (sink[i - 1, j, k] + sink[i, j, k])
    out[i, j, k] = (qc + dt * (visc * lap - adv + f)) / (1.0 + dt * a)


@builder(parallel=True, error_model="numpy")
def predict(q, p, r, nu, dt, dx, force, sink, out, flat):
    """``out`` = the predicted component ``q`` (along axis 0 of these views; ``p`` and ``r``
    the components along axes 1 and 2) after one explicit step of advection, diffusion,
    ``force`` (per cell, along axis 0; the face takes the mean of its two cells) and the
    implicit ``sink`` (1/s per cell). Wall faces (first and last along axis 0) are 0.
    Parallel over axis 0: for views whose last axis is the arrays' contiguous one
    (:func:`predict_inner` for the others)."""
    n0 = q.shape[0] - 1
    n1 = q.shape[1]
    n2 = q.shape[2]
    inv = 1.0 / dx
    visc = nu / (dx * dx)
    for i in prange(1, n0):
        for j in range(n1):
            for k in range(n2):
                _predict_at(q, p, r, visc, inv, dt, force, sink, out, flat, i, j, k)
    _predict_walls(out, n0, n1, n2)


@builder(parallel=True, error_model="numpy")
def predict_inner(q, p, r, nu, dt, dx, force, sink, out, flat):
    """:func:`predict` with the loop along axis 0 innermost, parallel over the rows (k, j):
    for the views whose axis 0 is the arrays' contiguous one (the last component of a 3-D
    box, 13 times faster at 48³ than striding across planes; the second of a flat box,
    whose views are Fortran-ordered too); the same operations per face. Two kernels, not a
    flag: each layout's compile holds one loop."""
    n0 = q.shape[0] - 1
    n1 = q.shape[1]
    n2 = q.shape[2]
    inv = 1.0 / dx
    visc = nu / (dx * dx)
    for row in prange(n2 * n1):
        k = row // n1
        j = row - k * n1
        for i in range(1, n0):
            _predict_at(q, p, r, visc, inv, dt, force, sink, out, flat, i, j, k)
    _predict_walls(out, n0, n1, n2)


@builder(entry=False, error_model="numpy", numba_inline=True)
def _predict_walls(out, n0, n1, n2):
    """The wall faces (first and last along axis 0) of a predicted component: 0."""
    for j in range(n1):
        for k in range(n2):
            out[0, j, k] = 0.0
            out[n0, j, k] = 0.0


@builder(parallel=True, error_model="numpy")
def divergence(u, v, w, dx, out, flat):
    """The net outflow of each cell over dx (1/s)."""
    n0, n1, n2 = out.shape
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                d = u[i + 1, j, k] - u[i, j, k] + v[i, j + 1, k] - v[i, j, k]
                if not flat:
                    d += w[i, j, k + 1] - w[i, j, k]
                out[i, j, k] = d / dx


@builder(parallel=True, error_model="numpy")
def correct(u, v, w, phi, dt, dx, flat):
    """u -= dt grad(phi) on the interior faces (the projection's correction)."""
    n0, n1, n2 = phi.shape
    g = dt / dx
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                if i > 0:
                    u[i, j, k] -= g * (phi[i, j, k] - phi[i - 1, j, k])
                if j > 0:
                    v[i, j, k] -= g * (phi[i, j, k] - phi[i, j - 1, k])
                if k > 0 and not flat:
                    w[i, j, k] -= g * (phi[i, j, k] - phi[i, j, k - 1])


@builder(parallel=True, error_model="numpy")
def correct_damped(u, v, w, phi, dt, dx, sink, flat):
    """u -= dt grad(phi) / (1 + dt a) on the interior faces, ``a`` the face's sink (the mean
    of its two cells'): the pressure of the last projection inside the predictor, braked by
    the implicit sink as the predictor's other terms are."""
    n0, n1, n2 = phi.shape
    g = dt / dx
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                if i > 0:
                    a = 0.5 * (sink[i, j, k] + sink[i - 1, j, k])
                    u[i, j, k] -= g * (phi[i, j, k] - phi[i - 1, j, k]) / (1.0 + dt * a)
                if j > 0:
                    a = 0.5 * (sink[i, j, k] + sink[i, j - 1, k])
                    v[i, j, k] -= g * (phi[i, j, k] - phi[i, j - 1, k]) / (1.0 + dt * a)
                if k > 0 and not flat:
                    a = 0.5 * (sink[i, j, k] + sink[i, j, k - 1])
                    w[i, j, k] -= g * (phi[i, j, k] - phi[i, j, k - 1]) / (1.0 + dt * a)


@builder(parallel=True, error_model="numpy")
def temperature_step(T, u, v, w, alpha, dt, dx, t_low, t_high, out, flat):
    """One explicit step of dT/dt + div(u T) = alpha lap T in the box: the walls across axis
    0 held at ``t_low`` (first) and ``t_high`` (last), the others adiabatic; central fluxes
    (the face value the mean of its two cells)."""
    n0, n1, n2 = T.shape
    g = dt / dx
    d = alpha / dx
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                tc = T[i, j, k]
                # axis 0: Dirichlet walls (half a cell to the wall, no flow through it)
                if i > 0:
                    fw = u[i, j, k] * 0.5 * (T[i - 1, j, k] + tc) - d * (tc - T[i - 1, j, k])
                else:
                    fw = -2.0 * d * (tc - t_low)
                if i < n0 - 1:
                    fe = u[i + 1, j, k] * 0.5 * (tc + T[i + 1, j, k]) - d * (T[i + 1, j, k] - tc)
                else:
                    fe = -2.0 * d * (t_high - tc)
                s = fw - fe
                if j > 0:
                    s += v[i, j, k] * 0.5 * (T[i, j - 1, k] + tc) - d * (tc - T[i, j - 1, k])
                if j < n1 - 1:
                    s -= v[i, j + 1, k] * 0.5 * (tc + T[i, j + 1, k]) - d * (T[i, j + 1, k] - tc)
                if not flat:
                    if k > 0:
                        s += (w[i, j, k] * 0.5 * (T[i, j, k - 1] + tc)
                              - d * (tc - T[i, j, k - 1]))
                    if k < n2 - 1:
                        s -= (w[i, j, k + 1] * 0.5 * (tc + T[i, j, k + 1])
                              - d * (T[i, j, k + 1] - tc))
                out[i, j, k] = tc + g * s


@builder(parallel=True, error_model="numpy")
def advect_enthalpy(H, box0, u, v, w, frac, heat, dt, dx, flat, out):
    """The liquid's sensible heat carried across the faces of the box (first upwind: the
    heat ``heat`` (J/m³, per cell of the box) of the cell the flow comes from, through a face
    open by the lesser liquid fraction ``frac`` of its two cells), added to the padded
    enthalpy ``H`` whose cell (i, j, k) of the box is ``box0`` + (i, j, k). ``out`` is scratch
    (the change per cell, added to ``H`` as it is computed: no term reads ``H``). Each face's
    flux is added to one cell and taken from the other: the total enthalpy does not change."""
    n0, n1, n2 = frac.shape
    g = dt / dx
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                s = 0.0
                fc = frac[i, j, k]
                hc = heat[i, j, k]
                if i > 0:
                    a = u[i, j, k] * min(fc, frac[i - 1, j, k])
                    s += a * (heat[i - 1, j, k] if a > 0.0 else hc)
                if i < n0 - 1:
                    a = u[i + 1, j, k] * min(fc, frac[i + 1, j, k])
                    s -= a * (hc if a > 0.0 else heat[i + 1, j, k])
                if j > 0:
                    a = v[i, j, k] * min(fc, frac[i, j - 1, k])
                    s += a * (heat[i, j - 1, k] if a > 0.0 else hc)
                if j < n1 - 1:
                    a = v[i, j + 1, k] * min(fc, frac[i, j + 1, k])
                    s -= a * (hc if a > 0.0 else heat[i, j + 1, k])
                if not flat:
                    if k > 0:
                        a = w[i, j, k] * min(fc, frac[i, j, k - 1])
                        s += a * (heat[i, j, k - 1] if a > 0.0 else hc)
                    if k < n2 - 1:
                        a = w[i, j, k + 1] * min(fc, frac[i, j, k + 1])
                        s -= a * (hc if a > 0.0 else heat[i, j, k + 1])
                out[i, j, k] = g * s
                H[box0[0] + i, box0[1] + j, box0[2] + k] += out[i, j, k]


@builder(parallel=True, error_model="numpy")
def kell_buoyancy(T, f, g, rho0, out):
    """``out`` = g (rho0 - rho(T)) / rho0 f per cell, rho Kell's (1975) density of water
    (:func:`whitted.stefan.flow.water_density_array`, the same operations in one pass)."""
    n0, n1, n2 = T.shape
    for i in prange(n0):
        for j in range(n1):
            for k in range(n2):
                t = T[i, j, k]
                num = (999.83952 + 16.945176 * t - 7.9870401e-3 * t ** 2
                       - 46.170461e-6 * t ** 3 + 105.56302e-9 * t ** 4
                       - 280.54253e-12 * t ** 5)
                rho = num / (1.0 + 16.879850e-3 * t)
                out[i, j, k] = g * (rho0 - rho) / rho0 * f[i, j, k]
