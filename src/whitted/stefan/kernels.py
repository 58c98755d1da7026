"""The enthalpy method's Numba kernels: explicit steps on a 3-D cell grid, all cores.

Physics only: nothing here knows the renderer. One file, so Numba's own cache invalidation
(per source file) covers every function; the cache folder is whitted's (``_cache``).

Arrays are padded with one ghost cell on every side. Cell kinds: ``AIR`` (0, the drained
outside), ``BODY`` (1, ice, water or both; its enthalpy per volume ``H``, see
:class:`~whitted.stefan.properties.Properties`), ``GHOST`` (2, outside the grid). Air and
ghost cells have conductivity 0, so the conduction pass is one branch-free stencil over the
whole grid (a face to a cell of conductivity 0 carries nothing); it runs a slab of x planes
per thread, with T and k computed from H two planes at a time (never stored for the grid)
and each face computed once (``_conduct_slab``). Heat from outside enters in a sparse pass
over the list of surface cells, each slab's right after its conduction: the faces of the
grid's own boundary are given per side (x-, x+, y-, y+, z-, z+) as a heat transfer
coefficient ``h`` (0: adiabatic, inf: the temperature is held), a temperature and a drain
flag (1: air that carries meltwater away); between a body cell and an air cell the air's
coefficient applies, scaled by |n|_2/|n|_1 of the surface normal estimated from the 3x3x3
occupancy gradient, so a staircase surface takes the heat of the true surface it stands for
(without it a sphere melts sqrt(3) times faster along the diagonals). Surface cells that
reach all-liquid drain (become air); their neighbours join the surface list.

No fast-math (NumPy's error model on the arithmetic, so LLVM can vectorise: no division here
is by zero): the energy balance (enthalpy change = boundary heat - drained enthalpy) holds to
round-off because each interior face's flux is computed once and added to one side, negated
(exactly) to the other; the totals are summed in a fixed order, whatever the thread count.
"""

from __future__ import annotations

import os

# Threads that wait at the end of a parallel loop sleep instead of spinning (OpenMP layer). A
# step is three short parallel loops; on a machine shared with other work a spinning thread
# keeps a core from the thread everyone waits for. Measured on the 2-core VM under load:
# 2 threads 4.0 -> 94.5 M cell updates/s (1 thread: 56-69).
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np  # noqa: E402

from ..jit import builder, numba_object  # noqa: E402

#: Numba's parallel range, in the kernels' globals once Numba is loaded (jit/decorators.py)
prange = numba_object("numba", "prange")

AIR = 0
BODY = 1
GHOST = 2

# indices into the property vector (Properties.as_array)
P_CI, P_KI, P_CW, P_KW, P_HL = 0, 1, 2, 3, 4
TINY = 1e-300  # keeps 0/0 out of the harmonic mean of two zero conductivities


@builder(entry=False, error_model="numpy", numba_inline=True)
def _temperature(h, p):
    if h < 0.0:
        return h * (1.0 / p[P_CI])
    if h > p[P_HL]:
        return (h - p[P_HL]) * (1.0 / p[P_CW])
    return 0.0


@builder(entry=False, error_model="numpy", numba_inline=True)
def _conductivity(h, p):
    if h <= 0.0:
        return p[P_KI]
    if h >= p[P_HL]:
        return p[P_KW]
    return p[P_KI] + h * ((p[P_KW] - p[P_KI]) / p[P_HL])


@builder(entry=False, error_model="numpy", numba_inline=True)
def _face(kc, kn, tn, tc):
    return 2.0 * kc * kn / (kc + kn + TINY) * (tn - tc)


@builder(entry=False, error_model="numpy", numba_inline=True)
def _state(h, hl, inv_ci, inv_cw, ki, kw, slope):
    """Temperature and conductivity of a body cell of enthalpy ``h``: ``_temperature`` and
    ``_conductivity`` with every branch computed and selected (the same operations, so the
    same bits), which lets the compiler vectorise the loops that call it. The properties
    come as scalars (:func:`_state_constants`), the divisions as products by reciprocals
    computed once a plane: a division costs several multiplications' time, and a loop over
    a plane holds nothing else as slow (the faces' harmonic means aside)."""
    t_ice = h * inv_ci
    t_water = (h - hl) * inv_cw
    k_mushy = ki + h * slope
    t = t_ice if h < 0.0 else (t_water if h > hl else 0.0)
    k = ki if h <= 0.0 else (kw if h >= hl else k_mushy)
    return t, k


@builder(entry=False, error_model="numpy", numba_inline=True)
def _state_constants(p):
    """L per volume, 1/c_i, 1/c_w, k_i, k_w and the mushy slope (k_w - k_i)/L of the property
    vector, computed as ``_temperature`` and ``_conductivity`` compute them (same bits)."""
    return (p[P_HL], 1.0 / p[P_CI], 1.0 / p[P_CW], p[P_KI], p[P_KW],
            (p[P_KW] - p[P_KI]) / p[P_HL])


@builder(entry=False, error_model="numpy")
def _state_plane(H, kind, p, i, T, K):
    """Temperature and conductivity of the cells of plane i, ghosts included (air and ghost
    cells 0): computed from H as a step needs them, never stored for the grid."""
    hl, inv_ci, inv_cw, ki, kw, slope = _state_constants(p)  # locals: T, K may alias p
    for j in range(H.shape[1]):
        h = H[i, j]
        c = kind[i, j]
        t = T[j]
        kk = K[j]
        for k in range(H.shape[2]):
            tv, kv = _state(h[k], hl, inv_ci, inv_cw, ki, kw, slope)
            body = c[k] == BODY
            t[k] = tv if body else 0.0
            kk[k] = kv if body else 0.0


@builder(entry=False, error_model="numpy")
def _faces_x(Ka, Ta, Kb, Tb, fx):
    """``fx[j, k]``: the flux term of the face between cell (j, k) of plane a and of the next
    plane b, as the cell in plane a computes it (``_face``); the cell in plane b adds its
    negation, which is what it would compute itself, bit for bit (2 k_a k_b and k_a + k_b
    commute exactly; T_a - T_b is -(T_b - T_a) exactly)."""
    for j in range(1, Ka.shape[0] - 1):
        ka = Ka[j]
        kb = Kb[j]
        ta = Ta[j]
        tb = Tb[j]
        f = fx[j]
        for k in range(1, Ka.shape[1] - 1):
            f[k] = _face(ka[k], kb[k], tb[k], ta[k])


@builder(entry=False, error_model="numpy")
def _conduct_slab(H, kind, Hn, p, g, i0, i1, TA, KA, TB, KB, fxa, fxb, fya, fyb, fz):
    """Hn = H + dt/dx² * sum over the six faces of k_face (T_nb - T) (harmonic-mean face
    conductivity; air and ghost neighbours, k = 0, add exactly zero) for the planes
    i0 <= i < i1. T and k come from H a plane at a time (``TA``/``KA`` and ``TB``/``KB``
    hold two planes); each face is computed once: x faces a plane at a time (``fxa`` below
    the current plane, ``fxb`` above), y faces a row at a time, z faces along the row. The
    sum per cell keeps the order x-, x+, y-, y+, z-, z+: the same result to the last bit as
    six faces per cell."""
    ny = H.shape[1] - 2
    nz = H.shape[2] - 2
    _state_plane(H, kind, p, i0 - 1, TA, KA)
    _state_plane(H, kind, p, i0, TB, KB)
    _faces_x(KA, TA, KB, TB, fxa)
    for i in range(i0, i1):
        _state_plane(H, kind, p, i + 1, TA, KA)  # plane i + 1 replaces plane i - 1
        _faces_x(KB, TB, KA, TA, fxb)
        ka = KB[0]
        ta = TB[0]
        kb = KB[1]
        tb = TB[1]
        for k in range(1, nz + 1):
            fya[k] = _face(ka[k], kb[k], tb[k], ta[k])
        for j in range(1, ny + 1):
            kc = KB[j]
            tc = TB[j]
            kn = KB[j + 1]
            tn = TB[j + 1]
            for k in range(1, nz + 1):
                fyb[k] = _face(kc[k], kn[k], tn[k], tc[k])
            for k in range(0, nz + 1):
                fz[k] = _face(kc[k], kc[k + 1], tc[k + 1], tc[k])
            h = H[i, j]
            hn = Hn[i, j]
            xa = fxa[j]
            xb = fxb[j]
            for k in range(1, nz + 1):
                s = xb[k] - xa[k]
                s -= fya[k]
                s += fyb[k]
                s -= fz[k - 1]
                s += fz[k]
                hn[k] = h[k] + g * s
            fya, fyb = fyb, fya
        TA, TB = TB, TA
        KA, KB = KB, KA
        fxa, fxb = fxb, fxa


@builder(entry=False)
def _slab_buffers(H, slabs):
    """Scratch of each slab, allocated once per call (not per step): two planes of T and k and
    two planes of x faces (``planes[c, 0:6]``), three rows (``rows[c, 0:3]``), and 27
    occupancies (``occ[c]``)."""
    ny = H.shape[1]
    nz = H.shape[2]
    return np.empty((slabs, 6, ny, nz)), np.empty((slabs, 3, nz)), np.empty((slabs, 27))


@builder(entry=False, numba_inline=True)
def _occupancy(H, kind, i, j, k, hl):
    """1 for a body cell (its ice fraction while it melts), 0 for air; a ghost cell mirrors
    the cell inside (an adiabatic wall or the table adds no slope)."""
    nx, ny, nz = H.shape
    i = min(max(i, 1), nx - 2)
    j = min(max(j, 1), ny - 2)
    k = min(max(k, 1), nz - 2)
    if kind[i, j, k] != BODY:
        return 0.0
    h = H[i, j, k]
    if h <= 0.0 or h >= hl:
        return 1.0
    return 1.0 - h / hl


@builder(entry=False, numba_inline=True)
def _surface_scale(H, kind, i, j, k, hl, occ):
    """|n|_2 / |n|_1 of the occupancy gradient (3x3x3, Sobel weights) at a surface cell; 1
    where it vanishes. ``occ`` (27 values) is scratch: each neighbour's occupancy is
    computed once (it enters up to three of the sums)."""
    for a in range(3):
        for b in range(3):
            for c in range(3):
                occ[9 * a + 3 * b + c] = _occupancy(H, kind, i + a - 1, j + b - 1, k + c - 1,
                                                    hl)
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for a in range(3):
        wa = 2.0 if a == 1 else 1.0
        for b in range(3):
            w = wa * (2.0 if b == 1 else 1.0)
            gx += w * (occ[18 + 3 * a + b] - occ[3 * a + b])
            gy += w * (occ[9 * a + 6 + b] - occ[9 * a + b])
            gz += w * (occ[9 * a + 3 * b + 2] - occ[9 * a + 3 * b])
    l1 = abs(gx) + abs(gy) + abs(gz)
    if l1 == 0.0:
        return 1.0
    return np.sqrt(gx * gx + gy * gy + gz * gz) / l1


@builder
def surface_scale(H, kind, i, j, k, hl):
    """``_surface_scale`` with its own scratch."""
    return _surface_scale(H, kind, i, j, k, hl, np.empty(27))


@builder(entry=False, numba_inline=True)
def _boundary_flux(h_coef, inv_h, t_far, drain, tc, kc, hc, dx):
    """Heat flux density (W/m²) into a cell through a face to the outside at ``t_far``:
    series resistance of the film (1/h) and the half cell (dx / 2k). A draining (air) face
    of a cell at 0 °C has no half cell: its meltwater has left, the ice surface is at 0 °C.
    ``inv_h`` is 1 / ``h_coef``."""
    if h_coef == 0.0:
        return 0.0
    r = 0.0
    if not (drain and hc >= 0.0):
        r = 0.5 * dx / kc
    if h_coef != np.inf:
        r += inv_h  # 1 / h_coef, computed once
    return (t_far - tc) / r


@builder(entry=False, numba_inline=True)
def _neighbour(i, j, k, face):
    if face == 0:
        return i - 1, j, k
    if face == 1:
        return i + 1, j, k
    if face == 2:
        return i, j - 1, k
    if face == 3:
        return i, j + 1, k
    if face == 4:
        return i, j, k - 1
    return i, j, k + 1


@builder(entry=False, numba_inline=True)
def _surface_cell(H, kind, Hn, p, dt, dx, face_h, face_inv_h, face_t, face_drain, air_h,
                  air_ice, air_t, i, j, k, scale, out, m, rescale, occ, is_surface):
    """The boundary heat of one surface cell, added to Hn; drain if it is all liquid and a
    face drains. ``out[m]``: heat in (J/m² of face), drained (J/m³), breach signal, drains.
    ``air_h``, ``air_t``: the air's film per face direction (x-, x+, y-, y+, z-, z+).
    An air face carries ``(T_air - T) c`` with ``c`` the film's h on a cell at or above 0 °C
    (its meltwater drains: no half cell) and ``air_ice`` = 1 / (1/h + dx / 2 k_i) on ice
    (:func:`_air_coefficients`): no division per face."""
    out[m, 0] = 0.0
    out[m, 1] = 0.0
    out[m, 2] = 0.0
    out[m, 3] = 0.0
    if kind[i, j, k] != BODY:
        return
    hl = p[P_HL]
    hc = H[i, j, k]
    tc = _temperature(hc, p)
    outer = 0.0
    air_faces = 0.0
    n_air = 0
    wet = False
    coef = air_h if hc >= 0.0 else air_ice
    for face in range(6):
        ii, jj, kk = _neighbour(i, j, k, face)
        kn = kind[ii, jj, kk]
        if kn == GHOST:
            d = face_drain[face] != 0
            outer += _boundary_flux(face_h[face], face_inv_h[face], face_t[face], d, tc,
                                    _conductivity(hc, p), hc, dx)
            if d and face_h[face] > 0.0:
                wet = True
        elif kn == AIR:  # the air's film of this face's direction (h per face: room.py)
            n_air += 1
            if air_h[face] > 0.0:
                wet = True
            air_faces += (air_t[face] - tc) * coef[face]
    if n_air > 0 and air_faces != 0.0:
        if rescale or scale[m] < 0.0:
            scale[m] = _surface_scale(H, kind, i, j, k, hl, occ)
        outer += scale[m] * air_faces
    hn = Hn[i, j, k] + dt / dx * outer
    Hn[i, j, k] = hn
    out[m, 0] = outer * dt
    if wet and hn >= hl:
        out[m, 1] = hn
        out[m, 3] = 1.0
        for face in range(6):  # an inner neighbour at least half liquid: the cavity opens
            ii, jj, kk = _neighbour(i, j, k, face)
            if (kind[ii, jj, kk] == BODY and is_surface[ii, jj, kk] == 0
                    and H[ii, jj, kk] >= 0.5 * hl):
                out[m, 2] += 1.0


@builder(entry=False)
def _air_coefficients(air_h, p, dx):
    """Per face direction, the air film's conductance to an ice cell's centre,
    1 / (1/h + dx / 2 k_i) (0 where h is 0; 2 k_i / dx where h is infinite)."""
    out = np.empty(6)
    for f in range(6):
        h = air_h[f]
        if h == 0.0:
            out[f] = 0.0
        elif h == np.inf:
            out[f] = 2.0 * p[P_KI] / dx
        else:
            out[f] = 1.0 / (1.0 / h + 0.5 * dx / p[P_KI])
    return out


@builder(entry=False)
def _inverse(h):
    """1 / h, 0 where h is 0 or infinite (those faces never use it)."""
    if h > 0.0 and h != np.inf:
        return 1.0 / h
    return 0.0


@builder(entry=False)
def _apply_drains(Hn, kind, surface, scale, out, n_surface, is_surface):
    """Drained cells become air; their body neighbours join the surface list. Serial, in list
    order (deterministic). Returns the new list length."""
    n = n_surface
    for m in range(n_surface):
        if out[m, 3] == 0.0:
            continue
        i = surface[m, 0]
        j = surface[m, 1]
        k = surface[m, 2]
        kind[i, j, k] = AIR
        Hn[i, j, k] = 0.0
        for face in range(6):
            ii, jj, kk = _neighbour(i, j, k, face)
            if kind[ii, jj, kk] == BODY and is_surface[ii, jj, kk] == 0:
                is_surface[ii, jj, kk] = 1
                surface[n, 0] = ii
                surface[n, 1] = jj
                surface[n, 2] = kk
                scale[n] = -1.0
                n += 1
    return n


@builder
def find_surface(kind, face_h, air_h, surface, is_surface):
    """Fill the surface list: body cells with a face to air (its direction's air_h > 0) or to a grid
    face with h > 0. Returns its length."""
    nx, ny, nz = kind.shape
    n = 0
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            for k in range(1, nz - 1):
                is_surface[i, j, k] = 0
                if kind[i, j, k] != BODY:
                    continue
                hit = False
                for face in range(6):
                    ii, jj, kk = _neighbour(i, j, k, face)
                    kn = kind[ii, jj, kk]
                    if (kn == GHOST and face_h[face] > 0.0) or (kn == AIR and air_h[face] > 0.0):
                        hit = True
                if hit:
                    is_surface[i, j, k] = 1
                    surface[n, 0] = i
                    surface[n, 1] = j
                    surface[n, 2] = k
                    n += 1
    return n


@builder(entry=False)
def _index_surface(surface, ns, plane_start, plane_cells):
    """The surface list by grid plane (a counting sort, list order within a plane): plane i
    holds ``plane_cells[plane_start[i - 1]:plane_start[i]]``."""
    plane_start[:] = 0
    for m in range(ns):
        plane_start[surface[m, 0]] += 1
    for q in range(1, plane_start.shape[0]):
        plane_start[q] += plane_start[q - 1]
    fill = plane_start[:-1].copy()
    for m in range(ns):
        q = surface[m, 0] - 1
        plane_cells[fill[q]] = m
        fill[q] += 1


@builder(entry=False)
def _copy(a, b):
    """b = a, element by element (of arrays of one shape): what ``b[...] = a`` does, without
    the broadcast's shape check and the error message Numba compiles for it."""
    nx, ny, nz = a.shape
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                b[i, j, k] = a[i, j, k]


@builder(entry=False)
def _zeros_rows(n):
    """An (n, 4) array of zeros: ``np.zeros`` compiled without the parallel option."""
    return np.zeros((n, 4))


@builder(parallel=True)
def run_steps_parallel(H, kind, Hn, p, dt, dx, face_h, face_t, face_drain, air_h,
                       air_t, surface, scale, n_surface, is_surface, n_steps, totals,
                       stop_on_breach, rescale_every, first_step, slabs):
    """Up to ``n_steps`` explicit steps (H holds the result), parallel over grid rows and
    surface cells. ``totals`` accumulates heat in, drained enthalpy, breach signals and
    drained cells; ``n_surface[0]`` is the surface list's length (grows as cells drain).
    Returns the steps done: fewer when a breach is signalled and ``stop_on_breach``."""
    nx = H.shape[0] - 2
    out = _zeros_rows(surface.shape[0])  # (np.zeros here would be a parallel loop of its own)
    face_inv_h = np.empty(6)
    for f in range(6):
        face_inv_h[f] = _inverse(face_h[f])
    air_ice = _air_coefficients(air_h, p, dx)
    g = dt / (dx * dx)
    done = 0
    src = H
    dst = Hn
    slabs = max(1, min(nx, slabs))
    planes, rows, occs = _slab_buffers(H, slabs)
    plane_start = np.empty(nx + 1, dtype=np.int64)
    plane_cells = np.empty(surface.shape[0], dtype=np.int64)
    _index_surface(surface, n_surface[0], plane_start, plane_cells)
    for step in range(n_steps):
        ns = n_surface[0]
        rescale = (first_step + step) % rescale_every == 0
        for c in prange(slabs):  # a slab of planes, then its surface cells (cache-warm)
            i0 = 1 + c * nx // slabs
            i1 = 1 + (c + 1) * nx // slabs
            pl = planes[c]
            rw = rows[c]
            _conduct_slab(src, kind, dst, p, g, i0, i1, pl[0], pl[1], pl[2], pl[3], pl[4],
                          pl[5], rw[0], rw[1], rw[2])
            occ = occs[c]
            for e in range(plane_start[i0 - 1], plane_start[i1 - 1]):
                m = plane_cells[e]
                _surface_cell(src, kind, dst, p, dt, dx, face_h, face_inv_h, face_t,
                              face_drain, air_h, air_ice, air_t, surface[m, 0],
                              surface[m, 1], surface[m, 2], scale, out, m, rescale, occ,
                              is_surface)
        breach = 0.0
        drains = 0.0
        for m in range(ns):  # in list order: no dependence on the thread count
            totals[0] += out[m, 0]
            totals[1] += out[m, 1]
            breach += out[m, 2]
            drains += out[m, 3]
        totals[2] += breach
        totals[3] += drains
        if drains > 0.0:
            n_surface[0] = _apply_drains(dst, kind, surface, scale, out, ns,
                                         is_surface)
            _index_surface(surface, n_surface[0], plane_start, plane_cells)
        src, dst = dst, src
        done += 1
        if breach > 0.0 and stop_on_breach:
            break
    if done % 2 == 1:  # the result is in the second buffer
        _copy(Hn, H)
    return done


@builder
def run_steps_serial(H, kind, Hn, p, dt, dx, face_h, face_t, face_drain, air_h,
                     air_t, surface, scale, n_surface, is_surface, n_steps, totals,
                     stop_on_breach, rescale_every, first_step):
    """``run_steps_parallel`` in one thread: for small grids and 1-D runs, where starting the
    threads every step would cost more than the work."""
    nx = H.shape[0] - 2
    out = np.zeros((surface.shape[0], 4))
    face_inv_h = np.empty(6)
    for f in range(6):
        face_inv_h[f] = _inverse(face_h[f])
    air_ice = _air_coefficients(air_h, p, dx)
    g = dt / (dx * dx)
    done = 0
    src = H
    dst = Hn
    planes, rows, occs = _slab_buffers(H, 1)
    ta, ka, tb, kb, fxa, fxb = planes[0, 0], planes[0, 1], planes[0, 2], planes[0, 3], \
        planes[0, 4], planes[0, 5]
    fya, fyb, fz = rows[0, 0], rows[0, 1], rows[0, 2]
    occ = occs[0]
    for step in range(n_steps):
        _conduct_slab(src, kind, dst, p, g, 1, nx + 1, ta, ka, tb, kb, fxa, fxb, fya, fyb, fz)
        ns = n_surface[0]
        rescale = (first_step + step) % rescale_every == 0
        for m in range(ns):
            _surface_cell(src, kind, dst, p, dt, dx, face_h, face_inv_h,
                          face_t, face_drain, air_h, air_ice, air_t, surface[m, 0],
                          surface[m, 1], surface[m, 2], scale, out, m, rescale, occ,
                              is_surface)
        breach = 0.0
        drains = 0.0
        for m in range(ns):
            totals[0] += out[m, 0]
            totals[1] += out[m, 1]
            breach += out[m, 2]
            drains += out[m, 3]
        totals[2] += breach
        totals[3] += drains
        if drains > 0.0:
            n_surface[0] = _apply_drains(dst, kind, surface, scale, out, ns,
                                         is_surface)
        src, dst = dst, src
        done += 1
        if breach > 0.0 and stop_on_breach:
            break
    if done % 2 == 1:
        _copy(Hn, H)
    return done


@builder(parallel=True)
def total_enthalpy(H, kind):
    """Sum of H over body cells (J/m³ times cells), in a fixed order."""
    nx, ny, nz = H.shape
    rows = np.empty(nx * ny)  # every row written below (np.zeros: a parallel loop of its own)
    for q in prange(nx * ny):
        i = q // ny
        j = q - i * ny
        s = 0.0
        for k in range(nz):
            if kind[i, j, k] == BODY:
                s += H[i, j, k]
        rows[q] = s
    total = 0.0  # the rows' sums added in order (rows.sum() would be a parallel reduction,
    for q in range(nx * ny):  # its order, so its last bits, the thread count's)
        total += rows[q]
    return total
