"""Constructive solid geometry: the nearest visible surface of a CSG object along a ray.

A CSG object is a row ``SHAPE_CSG`` (in the scene BVH, with the box of the whole) followed by
its tree in postfix order: leaves are ordinary solid rows (sphere, box, frustum, torus; the
object's transform baked in or kept as their own ``PRIM_XFORM``) or ``SHAPE_CSG_MESH`` rows
naming the triangle rows of a closed mesh (after the tree, each tested in turn), operations
are ``SHAPE_CSG_OP`` rows with their code and number of operands. These rows are in no BVH;
a visible surface is reported as the row it belongs to (a mesh's triangle), so shading reads
its material and normal as anywhere else.

The walk follows the ray through the leaves' crossings in order, keeping each leaf's inside
state as one bit of an int64: a leaf's state where the ray starts is whether its first
crossing past ``tmin`` leaves it (bounded solids: no crossing ahead, outside), and each
crossing sets it to whether the ray enters there (the sign of the leaf's normal). A ray
that only grazes a surface (normal perpendicular to it, to 1e-9) changes no state and shows
nothing. A crossing of leaf k is a surface of the object when POV-Ray's rules keep it, given
the states of the other leaves at that point (evaluated up the tree in one postfix pass):

- union: every surface of every operand;
- merge: an operand's surfaces outside every other operand;
- intersection: an operand's surfaces inside every other operand;
- difference: the first operand's surfaces outside all the others, and the others' surfaces
  inside the first and outside the rest (shown turned inside out: ``PRIM_FLIP``).

Every crossing of a leaf is computed from the ray alone, so asking again from past one
crossing finds the next one exactly; leaves the ray no longer crosses before ``tmax`` drop
out of the walk (the pips of a die that a ray misses cost one test each).
"""

from __future__ import annotations

import math

import numpy as np

from .intersect import INF, intersect_local, intersect_triangle, normal_local
from .jit import kernel, numba_object
from .layout import (
    CSG_DIFFERENCE,
    CSG_INTERSECTION,
    CSG_MAX_LEAVES,
    CSG_MERGE,
    PRIM_TYPE,
    PRIM_XFORM,
    SHAPE_CSG_MESH,
    SHAPE_CSG_OP,
    SHAPE_TORUS,
)
from .torus import intersect_torus, torus_normal
from .traverse import inverse_direction, slab_entry
from .vec import dot, madd
from .xform import normal_to_world, to_object

# kernels/frame_array.py is a Numba extension: imported with Numba (kernels/jit.py)
float_slots = numba_object(".frame_array", "float_slots")
int_slots = numba_object(".frame_array", "int_slots")
slots = numba_object(".frame_array", "slots")
FRAME_SLOTS = CSG_MAX_LEAVES + 1  # kernels/frame_array.py's

GRAZING = 1e-9  # |cos| between ray and normal below which a crossing is only a touch


@kernel
def _mesh_t(geo, j, o, d, tmin, tmax):
    """Nearest crossing in (tmin, tmax) with the triangles of mesh leaf ``j``, and the
    triangle's row (each tested: a CSG mesh is small)."""
    first = int(geo.prim_params[j, 0])
    best_t = INF
    best = np.int64(-1)
    for r in range(first, first + int(geo.prim_params[j, 1])):
        t = intersect_triangle(geo.prim_params, r, o, d, tmin, min(tmax, best_t))
        if t < best_t:
            best_t = t
            best = np.int64(r)
    return best_t, best


@kernel
def leaf_t(geo, j, o, d, tmin, tmax):
    """Nearest crossing in (tmin, tmax) of the world ray with leaf row ``j`` (INF: none), and
    the row whose surface it is (``j``, or a mesh leaf's triangle)."""
    typ = geo.prim_info[j, PRIM_TYPE]
    if typ == SHAPE_CSG_MESH:
        return _mesh_t(geo, j, o, d, tmin, tmax)
    xf = geo.prim_info[j, PRIM_XFORM]
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
    if typ == SHAPE_TORUS:
        return intersect_torus(geo.prim_params, j, o, d, tmin, tmax), np.int64(j)
    return intersect_local(typ, geo.prim_params, j, o, d, tmin, tmax), np.int64(j)


@kernel
def leaf_normal(geo, j, p):
    """Outward unit normal, in world space, of leaf row ``j``'s own solid at world ``p``."""
    xf = geo.prim_info[j, PRIM_XFORM]
    lp = p
    if xf >= 0:
        lp, _ = to_object(geo.xforms, xf, p, p)
    typ = geo.prim_info[j, PRIM_TYPE]
    if typ == SHAPE_TORUS:
        n = torus_normal(geo.prim_params, j, lp)
    else:
        n = normal_local(typ, geo.prim_params, j, lp)
    if xf >= 0:
        return normal_to_world(geo.xforms, xf, n)
    return n


@kernel
def _bit(bits, k):
    return (bits >> np.int64(k)) & np.int64(1)


@kernel
def _with_bit(bits, k, value):
    """``bits`` with bit k set to ``value`` (0 or 1)."""
    one = np.int64(1) << np.int64(k)
    return (bits | one) if value else (bits & ~one)


@kernel
def surface_shows(geo, root, hit_leaf, inside):
    """Is leaf number ``hit_leaf``'s surface, at a point where the other leaves' inside
    states are the bits of ``inside``, a surface of CSG object ``root``? One postfix pass:
    each entry of the evaluation stack is (inside the subtree, the point is a visible surface
    of the subtree), both kept as bits of an int64."""
    n_rows = int(geo.prim_params[root, 0])
    ins = np.int64(0)
    vis = np.int64(0)
    sp = 0
    leaf = 0
    for r in range(root + 1, root + 1 + n_rows):
        if geo.prim_info[r, PRIM_TYPE] != SHAPE_CSG_OP:
            ins = _with_bit(ins, sp, _bit(inside, leaf) if leaf != hit_leaf else 0)
            vis = _with_bit(vis, sp, 1 if leaf == hit_leaf else 0)
            sp += 1
            leaf += 1
            continue
        op = int(geo.prim_params[r, 0])
        m = int(geo.prim_params[r, 1])
        base = sp - m
        carrier = -1  # the operand holding the hit leaf, if any
        for c in range(m):
            if _bit(vis, base + c):
                carrier = c
        any_other = 0  # some operand but the carrier contains the point
        all_other = 1  # every operand but the carrier contains it
        any_cut = 0  # some operand after the first, but the carrier, contains it
        for c in range(m):
            if c == carrier:
                continue
            b = _bit(ins, base + c)
            any_other |= b
            all_other &= b
            if c > 0:
                any_cut |= b
        first_in = _bit(ins, base)
        # the subtree's inside state matters only where it holds no hit (its parent's
        # other operands): there the carrier is -1 and every operand counts
        if op == CSG_INTERSECTION:
            inside_here = all_other
            shows = carrier >= 0 and all_other == 1
        elif op == CSG_DIFFERENCE:
            inside_here = first_in & (1 - any_cut)
            shows = any_cut == 0 and (carrier == 0 or (carrier > 0 and first_in == 1))
        elif op == CSG_MERGE:
            inside_here = any_other
            shows = carrier >= 0 and any_other == 0
        else:  # union
            inside_here = any_other
            shows = carrier >= 0
        ins = _with_bit(ins, base, inside_here)
        vis = _with_bit(vis, base, 1 if shows else 0)
        sp = base + 1
    return _bit(vis, 0) == 1


@kernel
def may_show(geo, root, possible):
    """Can CSG object ``root`` still show a surface, given ``possible``: a bit per leaf, 0
    where the leaf has no crossing left in the walk and the ray is outside it there? (0 for a
    subtree: it stays outside and shows nothing for the rest of the walk; union and merge
    need one such operand, intersection every one, difference its first.) One postfix pass."""
    n_rows = int(geo.prim_params[root, 0])
    st = np.int64(0)
    sp = 0
    leaf = 0
    for r in range(root + 1, root + 1 + n_rows):
        if geo.prim_info[r, PRIM_TYPE] != SHAPE_CSG_OP:
            st = _with_bit(st, sp, _bit(possible, leaf))
            sp += 1
            leaf += 1
            continue
        op = int(geo.prim_params[r, 0])
        base = sp - int(geo.prim_params[r, 1])
        if op == CSG_DIFFERENCE:
            v = _bit(st, base)
        elif op == CSG_INTERSECTION:
            v = np.int64(1)
            for c in range(base, sp):
                v &= _bit(st, c)
        else:
            v = np.int64(0)
            for c in range(base, sp):
                v |= _bit(st, c)
        st = _with_bit(st, base, v)
        sp = base + 1
    return _bit(st, 0) == 1


@kernel
def csg_hit(geo, root, o, d, tmin, tmax):
    """(t, leaf row) of the nearest visible surface of CSG object ``root`` in (tmin, tmax),
    or (INF, -1).

    Each leaf's next crossing is kept (``next_t``, ``next_part``) and asked for again only
    once the walk has reached it: a crossing computed from the ray alone is the same whatever
    ``tmin`` it was asked from, so the walk sees the crossings the leaves would report if
    all were asked again at each step. The walk stops as soon as no surface can show
    (``may_show``), first after the leaves of the root's first operand (a die: the rays
    that miss its rounded cube skip its pips)."""
    P = geo.prim_params
    if slab_entry(P[root, 2], P[root, 3], P[root, 4], P[root, 5], P[root, 6], P[root, 7], o,
                  inverse_direction(d), tmin, tmax) == INF:
        return INF, np.int64(-1)  # (shadow rays test listed objects without their boxes)
    n_rows = int(P[root, 0])
    n_leaves = int(P[root, 1])
    first_leaves = int(P[root, 8])  # leaves of the first operand of a root that needs it
    next_t = slots(float_slots(), FRAME_SLOTS)
    next_part = slots(int_slots(), FRAME_SLOTS)
    rows = slots(int_slots(), FRAME_SLOTS)
    # d · the leaf's normal at next_t (NaN: not computed yet)
    next_cos = slots(float_slots(), FRAME_SLOTS)
    inside = np.int64(0)
    alive = np.int64(0)
    leaf = 0
    for r in range(root + 1, root + 1 + n_rows):
        if geo.prim_info[r, PRIM_TYPE] == SHAPE_CSG_OP:
            continue
        rows[leaf] = r
        t, part = leaf_t(geo, r, o, d, tmin, INF)
        next_t[leaf] = t
        next_part[leaf] = part
        if t < INF:
            if t < tmax:
                alive = _with_bit(alive, leaf, 1)
            cos = dot(d, leaf_normal(geo, part, madd(o, d, t)))
            next_cos[leaf] = cos  # the walk's crossing there needs it again
            if cos > 0.0:
                inside = _with_bit(inside, leaf, 1)  # its first crossing leaves it
        leaf += 1
        if leaf == first_leaves and leaf < n_leaves:  # the rest unknown yet: possible
            untested = ~((np.int64(1) << np.int64(leaf)) - np.int64(1))
            if not may_show(geo, root, alive | inside | untested):
                return INF, np.int64(-1)
    if not may_show(geo, root, alive | inside):
        return INF, np.int64(-1)
    d_len = math.sqrt(dot(d, d))
    t_cur = tmin
    while alive != 0:
        best_t = INF
        best_row = np.int64(-1)
        best_leaf = -1
        died = False
        for k in range(n_leaves):
            if _bit(alive, k):
                t = next_t[k]
                if t <= t_cur:  # reached: its next crossing past here
                    t, part = leaf_t(geo, rows[k], o, d, t_cur, tmax)
                    next_t[k] = t
                    next_part[k] = part
                    next_cos[k] = math.nan
                if t == INF:
                    alive = _with_bit(alive, k, 0)
                    died = True
                elif t < best_t:
                    best_t = t
                    best_row = next_part[k]
                    best_leaf = k
        if best_row < 0:
            break
        if died and not may_show(geo, root, alive | inside):
            break
        cos = next_cos[best_leaf]
        if math.isnan(cos):
            cos = dot(d, leaf_normal(geo, best_row, madd(o, d, best_t)))
        t_cur = best_t
        if abs(cos) <= GRAZING * d_len:
            continue  # a touch: no state changes, nothing shows
        if surface_shows(geo, root, best_leaf, inside):
            return best_t, best_row
        inside = _with_bit(inside, best_leaf, 1 if cos < 0.0 else 0)
    return INF, np.int64(-1)
