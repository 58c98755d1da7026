"""The pressure of the flow in the melt: div(grad phi) = rhs on the fluid cells of a box, no
flux through the faces to other cells, by conjugate gradients preconditioned with one
geometric multigrid V-cycle; Numba, parallel over the first axis (both cores).

The operator is the graph Laplacian of the fluid cells (a face is open when both its cells
are fluid), written as the positive A = -L: per cell a diagonal ``d`` and the weights of its
faces to the previous cell along each axis (``wx``, ``wy``, ``wz``). The levels coarsen by
two along every axis longer than one cell (a 2-D problem stays one cell deep); a coarse cell
is the block of its children, its operator the Galerkin product PᵀAP of piecewise-constant
prolongation P halved (so a coarse face's weight is half the sum of the open fine faces
between the two blocks: on a full grid exactly the Laplacian of the doubled cell, and on a
masked one the fluid's shape carried down without a rule of its own; the halving is the
usual correction of piecewise-constant interpolation's too small coarse correction). The
smoother is red-black Gauss-Seidel, red then black before the coarse correction and black
then red after it, and the coarsest level is a fixed number of those sweeps: the V-cycle is
a symmetric positive operator, as conjugate gradients requires.

Every level's arrays are concatenated in flat vectors (``off[l]`` the first cell of level l,
``shp[l]`` its shape), so one Numba function runs the whole solve. Inner products are summed
per plane of the first axis and the planes added in order: the same bits whatever the number
of threads. Each connected body of fluid is singular (phi up to a constant): the finest
diagonal is raised by 10⁻¹⁰ of itself, which fixes the constant without moving the gradient
measurably.
"""

from __future__ import annotations

import numpy as np

from ..jit import builder, numba_object

prange = numba_object("numba", "prange")

#: the diagonal's relative shift (the constant of each singular body of fluid)
SHIFT = 1.0e-10
#: red-black sweeps before and after the coarse correction, and at the coarsest level
SMOOTH = 2
COARSEST_SWEEPS = 24


#: levels of fewer cells run their loops on one thread (a parallel loop's start costs more
#: than the work of a small level)
PARALLEL_MIN_CELLS = 4096

# Each level kernel below calls its plane function from its parallel loop and from its serial
# one: a call, not Numba's inlining, so each plane function is compiled once (inlined, it was
# compiled into both loops; the solve within 2 % of its speed, docs/performance.md).

@builder(entry=False, error_model="numpy")
def _apply_plane(wx, wy, wz, d, x, out, o, n0, n1, n2, i):
    s1 = n1 * n2
    for j in range(n1):
        for k in range(n2):
            c = o + i * s1 + j * n2 + k
            if d[c] == 0.0:
                out[c] = 0.0
                continue
            s = d[c] * x[c]
            if i > 0:
                s -= wx[c] * x[c - s1]
            if i < n0 - 1:
                s -= wx[c + s1] * x[c + s1]
            if j > 0:
                s -= wy[c] * x[c - n2]
            if j < n1 - 1:
                s -= wy[c + n2] * x[c + n2]
            if k > 0:
                s -= wz[c] * x[c - 1]
            if k < n2 - 1:
                s -= wz[c + 1] * x[c + 1]
            out[c] = s


@builder(entry=False, parallel=True, error_model="numpy")
def _apply(wx, wy, wz, d, x, out, o, n0, n1, n2):
    """out = A x on level (o, n0, n1, n2)."""
    if n0 * n1 * n2 >= PARALLEL_MIN_CELLS:
        for i in prange(0, n0):  # an int64 index (prange(n0)'s is unsigned)
            _apply_plane(wx, wy, wz, d, x, out, o, n0, n1, n2, i)
    else:
        for i in range(n0):
            _apply_plane(wx, wy, wz, d, x, out, o, n0, n1, n2, i)


@builder(entry=False, error_model="numpy")
def _sweep_plane(wx, wy, wz, d, b, x, o, n0, n1, n2, color, i):
    s1 = n1 * n2
    for j in range(n1):
        for k in range((color + i + j) % 2, n2, 2):
            c = o + i * s1 + j * n2 + k
            dc = d[c]
            if dc > 0.0:
                s = b[c]
                if i > 0:
                    s += wx[c] * x[c - s1]
                if i < n0 - 1:
                    s += wx[c + s1] * x[c + s1]
                if j > 0:
                    s += wy[c] * x[c - n2]
                if j < n1 - 1:
                    s += wy[c + n2] * x[c + n2]
                if k > 0:
                    s += wz[c] * x[c - 1]
                if k < n2 - 1:
                    s += wz[c + 1] * x[c + 1]
                x[c] = s / dc


@builder(entry=False, parallel=True, error_model="numpy")
def _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, color):
    """One Gauss-Seidel pass over the cells with (i + j + k) % 2 == color (their neighbours
    all of the other colour: the order within a pass does not matter)."""
    if n0 * n1 * n2 >= PARALLEL_MIN_CELLS:
        for i in prange(0, n0):  # an int64 index (prange(n0)'s is unsigned)
            _sweep_plane(wx, wy, wz, d, b, x, o, n0, n1, n2, color, i)
    else:
        for i in range(n0):
            _sweep_plane(wx, wy, wz, d, b, x, o, n0, n1, n2, color, i)


@builder(entry=False, error_model="numpy")
def _restrict_plane(wx, wy, wz, d, b, x, bc, fo, n0, n1, n2, co, m1, m2, c0, c1, c2, ci):
    s1 = n1 * n2
    base = co + ci * m1 * m2
    for c in range(base, base + m1 * m2):
        bc[c] = 0.0
    for i in range(ci * c0, min(ci * c0 + c0, n0)):
        for j in range(n1):
            row = base + (j // c1) * m2
            for k in range(n2):
                c = fo + i * s1 + j * n2 + k
                if d[c] == 0.0:
                    continue
                s = b[c] - d[c] * x[c]
                if i > 0:
                    s += wx[c] * x[c - s1]
                if i < n0 - 1:
                    s += wx[c + s1] * x[c + s1]
                if j > 0:
                    s += wy[c] * x[c - n2]
                if j < n1 - 1:
                    s += wy[c + n2] * x[c + n2]
                if k > 0:
                    s += wz[c] * x[c - 1]
                if k < n2 - 1:
                    s += wz[c + 1] * x[c + 1]
                bc[row + k // c2] += s


@builder(entry=False, parallel=True, error_model="numpy")
def _restrict(wx, wy, wz, d, b, x, bc, fo, n0, n1, n2, co, m0, m1, m2, c0, c1, c2):
    """bc (coarse) = the sum over each block of the fine residual b - A x."""
    if n0 * n1 * n2 >= PARALLEL_MIN_CELLS:
        for ci in prange(0, m0):  # an int64 index (prange(m0)'s is unsigned)
            _restrict_plane(wx, wy, wz, d, b, x, bc, fo, n0, n1, n2, co, m1, m2, c0, c1, c2,
                            ci)
    else:
        for ci in range(m0):
            _restrict_plane(wx, wy, wz, d, b, x, bc, fo, n0, n1, n2, co, m1, m2, c0, c1, c2,
                            ci)


@builder(entry=False, error_model="numpy")
def _prolong_plane(d, x, fo, n1, n2, co, m1, m2, c0, c1, c2, i):
    s1 = n1 * n2
    for j in range(n1):
        for k in range(n2):
            c = fo + i * s1 + j * n2 + k
            if d[c] > 0.0:
                x[c] += x[co + ((i // c0) * m1 + j // c1) * m2 + k // c2]


@builder(entry=False, parallel=True, error_model="numpy")
def _prolong(d, x, fo, n0, n1, n2, co, m1, m2, c0, c1, c2):
    """x (fine) += the coarse x of each fluid cell's block."""
    if n0 * n1 * n2 >= PARALLEL_MIN_CELLS:
        for i in prange(0, n0):  # an int64 index (prange(n0)'s is unsigned)
            _prolong_plane(d, x, fo, n1, n2, co, m1, m2, c0, c1, c2, i)
    else:
        for i in range(n0):
            _prolong_plane(d, x, fo, n1, n2, co, m1, m2, c0, c1, c2, i)


@builder(entry=False, error_model="numpy")
def _zero(x, o, n):
    for c in range(n):
        x[o + c] = 0.0


@builder(entry=False, error_model="numpy")
def _vcycle(wx, wy, wz, d, b, x, off, shp, levels, smooth, coarsest):
    """x (level 0) = one V-cycle applied to b (level 0), from x = 0."""
    for lv in range(levels - 1):
        o = off[lv]
        n0, n1, n2 = shp[lv, 0], shp[lv, 1], shp[lv, 2]
        _zero(x, o, n0 * n1 * n2)
        for _ in range(smooth):
            _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 0)
            _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 1)
        m0, m1, m2 = shp[lv + 1, 0], shp[lv + 1, 1], shp[lv + 1, 2]
        _restrict(wx, wy, wz, d, b, x, b, o, n0, n1, n2, off[lv + 1], m0, m1, m2,
                  2 if n0 > 1 else 1, 2 if n1 > 1 else 1, 2 if n2 > 1 else 1)
    lv = levels - 1
    o = off[lv]
    n0, n1, n2 = shp[lv, 0], shp[lv, 1], shp[lv, 2]
    _zero(x, o, n0 * n1 * n2)
    for _ in range(coarsest):
        _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 0)
        _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 1)
    for _ in range(coarsest):
        _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 1)
        _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 0)
    for lv in range(levels - 2, -1, -1):
        o = off[lv]
        n0, n1, n2 = shp[lv, 0], shp[lv, 1], shp[lv, 2]
        _prolong(d, x, o, n0, n1, n2, off[lv + 1], shp[lv + 1, 1], shp[lv + 1, 2],
                 2 if n0 > 1 else 1, 2 if n1 > 1 else 1, 2 if n2 > 1 else 1)
        for _ in range(smooth):
            _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 1)
            _sweep(wx, wy, wz, d, b, x, o, n0, n1, n2, 0)


@builder(entry=False, parallel=True, error_model="numpy")
def _dot(a, b, n0, s1, part):
    """The inner product of level 0's a and b, per plane then in order (deterministic)."""
    for i in prange(n0):
        t = 0.0
        for c in range(i * s1, i * s1 + s1):
            t += a[c] * b[c]
        part[i] = t
    t = 0.0
    for i in range(n0):
        t += part[i]
    return t


@builder(entry=False, parallel=True, error_model="numpy")
def _update(x, r, p, q, alpha, n0, s1, part):
    """x += alpha p, r -= alpha q; returns |r|²."""
    for i in prange(n0):
        t = 0.0
        for c in range(i * s1, i * s1 + s1):
            x[c] += alpha * p[c]
            rc = r[c] - alpha * q[c]
            r[c] = rc
            t += rc * rc
        part[i] = t
    t = 0.0
    for i in range(n0):
        t += part[i]
    return t


@builder(entry=False, parallel=True, error_model="numpy")
def _direction(p, z, beta, n):
    for c in prange(n):
        p[c] = z[c] + beta * p[c]


@builder(error_model="numpy")
def mg_cg(wx, wy, wz, d, vb, vx, off, shp, levels, b, x, r, z, p, q, part, tol, maxiter,
          smooth, coarsest):
    """Solve A x = b (level 0; ``x`` the start, overwritten) until |b - A x|₂ <= ``tol``, at
    most ``maxiter`` iterations, each preconditioned by one V-cycle (``vb``, ``vx``: the
    levels' scratch). Returns the iterations done."""
    n0, n1, n2 = shp[0, 0], shp[0, 1], shp[0, 2]
    n = n0 * n1 * n2
    s1 = n1 * n2
    _apply(wx, wy, wz, d, x, q, 0, n0, n1, n2)
    for c in range(n):
        r[c] = b[c] - q[c]
    rr = _dot(r, r, n0, s1, part)
    it = 0
    if rr <= tol * tol:
        return it
    for c in range(n):
        vb[c] = r[c]
    _vcycle(wx, wy, wz, d, vb, vx, off, shp, levels, smooth, coarsest)
    for c in range(n):
        z[c] = vx[c]
        p[c] = vx[c]
    rz = _dot(r, z, n0, s1, part)
    while it < maxiter:
        _apply(wx, wy, wz, d, p, q, 0, n0, n1, n2)
        pq = _dot(p, q, n0, s1, part)
        if not pq > 0.0:
            break
        alpha = rz / pq
        rr = _update(x, r, p, q, alpha, n0, s1, part)
        it += 1
        if rr <= tol * tol:
            break
        for c in range(n):
            vb[c] = r[c]
        _vcycle(wx, wy, wz, d, vb, vx, off, shp, levels, smooth, coarsest)
        for c in range(n):
            z[c] = vx[c]
        rz_new = _dot(r, z, n0, s1, part)
        _direction(p, z, rz_new / rz, n)
        rz = rz_new
    return it


def _block_sum(a: np.ndarray, c: tuple[int, int, int]) -> np.ndarray:
    """The sums of ``a`` over blocks of c[0] x c[1] x c[2] cells (the last blocks partial)."""
    pad = [(0, (-n) % f) for n, f in zip(a.shape, c, strict=True)]
    a = np.pad(a, pad)
    m = [n // f for n, f in zip(a.shape, c, strict=True)]
    return a.reshape(m[0], c[0], m[1], c[1], m[2], c[2]).sum(axis=(1, 3, 5))


class Hierarchy:
    """The levels of one fluid mask (cells of side ``dx``): weights, diagonals and scratch."""

    def __init__(self, fluid: np.ndarray, dx: float, coarsest_cells: int = 8) -> None:
        h2 = 1.0 / (dx * dx)
        f = fluid.astype(np.float64)
        ws = []
        for a in range(3):
            w = np.zeros(fluid.shape)
            if fluid.shape[a] > 1:
                lo = [slice(None)] * 3
                hi = [slice(None)] * 3
                lo[a] = slice(0, -1)
                hi[a] = slice(1, None)
                w[tuple(hi)] = f[tuple(lo)] * f[tuple(hi)] * h2
            ws.append(w)
        levels = [(ws, self._diagonal(ws, fluid, h2))]
        while True:
            shape = levels[-1][1].shape
            if np.prod(shape) <= coarsest_cells or max(shape) <= 2:
                break
            c = tuple(2 if n > 1 else 1 for n in shape)
            fine_w, fine_d = levels[-1]
            coarse = []
            for a in range(3):
                faces = fine_w[a]
                if c[a] == 2:  # the faces between blocks: the fine ones at even indices
                    take = [slice(None)] * 3
                    take[a] = slice(0, None, 2)
                    faces = faces[tuple(take)]
                cc = list(c)
                cc[a] = 1
                coarse.append(0.5 * _block_sum(faces, tuple(cc)))
            active = _block_sum((fine_d > 0).astype(np.float64), c) > 0
            levels.append((coarse, self._diagonal(coarse, active, 0.0)))
        self.levels = len(levels)
        sizes = [lv[1].size for lv in levels]
        self.off = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        self.shp = np.array([lv[1].shape for lv in levels], dtype=np.int64)
        self.wx, self.wy, self.wz = (np.concatenate([lv[0][a].ravel() for lv in levels])
                                     for a in range(3))
        self.d = np.concatenate([lv[1].ravel() for lv in levels])
        total = int(sum(sizes))
        self.vb = np.zeros(total)
        self.vx = np.zeros(total)
        n = sizes[0]
        self.r, self.z, self.p, self.q = (np.zeros(n) for _ in range(4))
        self.part = np.zeros(int(self.shp[0, 0]))

    @staticmethod
    def _diagonal(ws, active: np.ndarray, h2: float) -> np.ndarray:
        """Each cell's diagonal: the sum of its faces' weights, raised by ``SHIFT`` of itself
        (finest level: an isolated fluid cell gets ``SHIFT`` h⁻²; coarser: an isolated
        block is left out, 0)."""
        total = ws[0].copy() + ws[1] + ws[2]
        for a in range(3):
            hi = [slice(None)] * 3
            hi[a] = slice(1, None)
            lo = [slice(None)] * 3
            lo[a] = slice(0, -1)
            total[tuple(lo)] += ws[a][tuple(hi)]
        d = total * (1.0 + SHIFT)
        if h2 > 0.0:
            d = np.where(active & (total == 0.0), SHIFT * h2, d)
        return np.where(active, d, 0.0)

    def apply(self, x: np.ndarray) -> np.ndarray:
        """A x on the finest level (for checks)."""
        out = np.zeros(self.r.size)
        s = self.shp[0]
        _apply(self.wx, self.wy, self.wz, self.d, np.ascontiguousarray(x.ravel()), out, 0,
               int(s[0]), int(s[1]), int(s[2]))
        return out.reshape(tuple(s))

    def solve(self, b: np.ndarray, x: np.ndarray, tol: float, maxiter: int = 500) -> int:
        """A x = b (flat level-0 vectors; ``x`` the start, overwritten) to |r|₂ <= tol."""
        return int(mg_cg(self.wx, self.wy, self.wz, self.d, self.vb, self.vx, self.off,
                         self.shp, self.levels, b, x, self.r, self.z, self.p, self.q,
                         self.part, float(tol), int(maxiter), SMOOTH, COARSEST_SWEEPS))


__all__ = ["Hierarchy", "mg_cg"]
