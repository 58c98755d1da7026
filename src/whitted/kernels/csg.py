"""Constructive solid geometry: the nearest visible surface of a CSG object along a ray.

A CSG object is a row ``SHAPE_CSG`` (in the scene BVH, with the box of the whole) followed by
its tree in postfix order: leaves are ordinary solid rows (sphere, box, frustum, torus; the
object's transform baked in or kept as their own ``PRIM_XFORM``) or ``SHAPE_CSG_MESH`` rows
naming the triangle rows of a closed mesh (after the tree; a big one's crossings found
through the BVH of the mesh stored for it, a small one's rows each tested), operations
are ``SHAPE_CSG_OP`` rows with their code and number of operands. These rows are in no BVH;
a visible surface is reported as the row it belongs to (a mesh's triangle), so shading reads
its material and normal as anywhere else.

The walk follows the ray through the leaves' crossings in order, keeping each leaf's inside
state as one bit of an int64. An analytic leaf (sphere, box, frustum, torus) gives every
crossing of the ray's whole line at once, sorted. For a sphere, a box or a torus the line
enters at the first, leaves at the second (a torus: again at the third and fourth), so the
leaf is inside where an odd number of its crossings lie behind, and a tangent touch (two
equal crossings) is none. A frustum is convex: its first crossing and its last are kept (a
ray through a cap's rim meets the cap and the side there, a rounding apart: the crossings
between are that rim met twice). A mesh leaf is asked for its next crossing past the last
one the walk used. It and any leaf with an odd number of crossings (one lost to rounding at
an edge, or a frustum only touched) are walked by their normals: the state where the ray
starts is whether its first crossing past ``tmin`` leaves it (no crossing ahead: outside),
and each crossing sets it to whether the ray enters there (the sign of the normal; a
crossing that only grazes, normal perpendicular to the ray to 1e-9, changes no state and
shows nothing). A crossing of leaf k is a surface of the object when POV-Ray's rules keep
it, given the states of the other leaves at that point (evaluated up the tree in one postfix
pass, or, for a tree of one operation on leaves, as bit masks):

- union: every surface of every operand;
- merge: an operand's surfaces outside every other operand;
- intersection: an operand's surfaces inside every other operand;
- difference: the first operand's surfaces outside all the others, and the others' surfaces
  inside the first and outside the rest (shown turned inside out: ``PRIM_FLIP``).

Every crossing of a leaf is computed from the ray alone, so the walk sees the same crossings
whatever ``tmin`` it starts from; leaves the ray no longer crosses before ``tmax`` drop out
of the walk (the pips of a die that a ray misses cost one test each).
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel, numba_object
from .hit_list import keep_nearest
from .layout import (
    CSG_DIFFERENCE,
    CSG_INTERSECTION,
    CSG_MAX_LEAVES,
    CSG_MERGE,
    MESH_TRI_OFFSET,
    PRIM_TYPE,
    PRIM_XFORM,
)
from .mesh import mesh_closest_hit
from .shapes import INF
from .shapes.dispatch import (
    has_crossings,
    is_csg_mesh_leaf,
    is_csg_operation,
    solid_crossings,
    solid_normal,
)
from .shapes.triangle import intersect_triangle
from .traverse import inverse_direction, slab_entry
from .vec import dot, madd
from .xform import normal_to_world, to_object

# kernels/frame_array.py is a Numba extension: imported with Numba (jit/decorators.py)
float_slots = numba_object(f"{__package__}.frame_array", "float_slots")
int_slots = numba_object(f"{__package__}.frame_array", "int_slots")
slots = numba_object(f"{__package__}.frame_array", "slots")
FRAME_SLOTS = CSG_MAX_LEAVES + 1  # kernels/frame_array.py's

GRAZING = 1e-9  # |cos| between ray and normal below which a crossing is only a touch


@kernel
def mesh_leaf_t(geo, j, o, d, tmin, tmax):
    """Nearest crossing in (tmin, tmax) with the triangles of mesh leaf ``j``, and the
    triangle's row: through the BVH of the mesh stored for it (``prim_params[j, 2]``: its
    mesh_info row + 1, in its own space: ``PRIM_XFORM``), whose triangle k is row first + k,
    or, for a small mesh, each row tested."""
    first = int(geo.prim_params[j, 0])
    mesh = int(geo.prim_params[j, 2]) - 1
    if mesh >= 0:
        xf = geo.prim_info[j, PRIM_XFORM]
        if xf >= 0:
            o, d = to_object(geo.xforms, xf, o, d)
        stack = slots(int_slots(), FRAME_SLOTS)  # as deep as an instance's walk
        t, tri, _, _ = mesh_closest_hit(geo, mesh, o, d, inverse_direction(d), tmin, tmax,
                                        stack, 0)
        if tri < 0:
            return INF, np.int64(-1)
        return t, np.int64(first + tri - geo.mesh_info[mesh, MESH_TRI_OFFSET])
    best_t = INF
    best = np.int64(-1)
    for r in range(first, first + int(geo.prim_params[j, 1])):
        t = intersect_triangle(geo.prim_params, r, o, d, tmin, min(tmax, best_t))
        if t < best_t:
            best_t = t
            best = np.int64(r)
    return best_t, best


@kernel(inline="always")
def leaf_crossings(geo, j, o, d):
    """Every crossing of the world ray's whole line with analytic leaf row ``j``: (count,
    t0, t1, t2, t3), sorted, inf-padded. A closed solid's line enters at t0 and leaves at
    t1 (a torus's again at t2 and t3); a tangent touch (two equal crossings) is none; a
    frustum's are its first and last (module docstring)."""
    xf = geo.prim_info[j, PRIM_XFORM]
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
    return solid_crossings(geo.prim_info[j, PRIM_TYPE], geo.prim_params, j, o, d)


@kernel
def leaf_normal(geo, j, p):
    """Outward unit normal, in world space, of leaf row ``j``'s own solid at world ``p``."""
    xf = geo.prim_info[j, PRIM_XFORM]
    lp = p
    if xf >= 0:
        lp, _ = to_object(geo.xforms, xf, p, p)
    n = solid_normal(geo.prim_info[j, PRIM_TYPE], geo.prim_params, j, lp)
    if xf >= 0:
        return normal_to_world(geo.xforms, xf, n)
    return n


@kernel(inline="always")
def _bit(bits, k):
    return (bits >> np.int64(k)) & np.int64(1)


@kernel(inline="always")
def _with_bit(bits, k, value):
    """``bits`` with bit k set to ``value`` (0 or 1)."""
    one = np.int64(1) << np.int64(k)
    return (bits | one) if value else (bits & ~one)


@kernel(inline="always")
def _shows_in(geo, start, n_rows, hit_leaf, inside):
    """(inside, shows) of the subtree in rows [start, start + n_rows) (its leaves numbered
    from 0), at a point on leaf number ``hit_leaf``'s surface where the other leaves' inside
    states are the bits of ``inside``. One postfix pass: each entry of the evaluation stack
    is (inside the subtree, the point is a visible surface of the subtree), both kept as bits
    of an int64."""
    ins = np.int64(0)
    vis = np.int64(0)
    sp = 0
    leaf = 0
    for r in range(start, start + n_rows):
        if not is_csg_operation(geo.prim_info[r, PRIM_TYPE]):
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
    return _bit(ins, 0), _bit(vis, 0)


@kernel(inline="always")
def _cut_mask(geo, root):
    """The bits of the leaves that are a difference root's cuts when every cut is one leaf
    (``prim_params[root, 9]``: the rows of its first operand, 0 otherwise), else 0: then the
    walk evaluates only the first operand's rows and tests the cuts as one mask."""
    P = geo.prim_params
    if P[root, 9] <= 0.0:
        return np.int64(0)
    n_leaves = np.int64(P[root, 1])
    low = (np.int64(1) << np.int64(P[root, 8])) - np.int64(1)
    every = (np.int64(1) << n_leaves) - np.int64(1) if n_leaves < 63 else ~np.int64(0)
    return every & ~low


@kernel(inline="always")
def surface_shows(geo, root, hit_leaf, inside, cuts):
    """Is leaf number ``hit_leaf``'s surface, at a point where the other leaves' inside
    states are the bits of ``inside``, a surface of CSG object ``root``? ``cuts``: its
    :func:`_cut_mask` (a difference whose cuts are leaves: a surface shows where no other
    cut holds the point, and the first operand shows it, or, on a cut, holds it)."""
    if cuts != 0:
        if inside & cuts & ~(np.int64(1) << np.int64(hit_leaf)) != 0:
            return False
        ins, vis = _shows_in(geo, root + 1, int(geo.prim_params[root, 9]), hit_leaf, inside)
        if hit_leaf < int(geo.prim_params[root, 8]):
            return vis == 1
        return ins == 1
    _, vis = _shows_in(geo, root + 1, int(geo.prim_params[root, 0]), hit_leaf, inside)
    return vis == 1


@kernel(inline="always")
def may_show(geo, root, possible, cuts):
    """Can CSG object ``root`` still show a surface, given ``possible``: a bit per leaf, 0
    where the leaf has no crossing left in the walk and the ray is outside it there? (0 for a
    subtree: it stays outside and shows nothing for the rest of the walk; union and merge
    need one such operand, intersection every one, difference its first.) One postfix pass,
    over the first operand's rows only when ``cuts`` (:func:`_cut_mask`) is not 0."""
    n_rows = int(geo.prim_params[root, 9]) if cuts != 0 else int(geo.prim_params[root, 0])
    st = np.int64(0)
    sp = 0
    leaf = 0
    for r in range(root + 1, root + 1 + n_rows):
        if not is_csg_operation(geo.prim_info[r, PRIM_TYPE]):
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


@kernel(inline="always")
def _missed_groups(geo, root, o, inv, tmin, tmax):
    """Bits of the cut leaves in the groups (rows after the tree: first leaf, end leaf,
    box padded) whose box the segment (tmin, tmax) misses: no crossing there, and outside
    them all along it."""
    P = geo.prim_params
    skip = np.int64(0)
    g0 = root + 1 + int(P[root, 0])
    for g in range(g0, g0 + int(P[root, 10])):
        if slab_entry(P[g, 2], P[g, 3], P[g, 4], P[g, 5], P[g, 6], P[g, 7], o, inv, tmin,
                      tmax) == INF:
            first = np.int64(P[g, 0])
            end = np.int64(P[g, 1])
            skip |= ((np.int64(1) << end) - np.int64(1)) & ~((np.int64(1) << first)
                                                             - np.int64(1))
    return skip


@kernel(inline="always")
def _flat_shows(op, k, inside, every):
    """:func:`surface_shows` for a tree of one operation on leaves (``every``: their bits):
    the rules of the module docstring as masks."""
    others = inside & ~(np.int64(1) << np.int64(k))
    if op == CSG_MERGE:
        return others == 0
    if op == CSG_INTERSECTION:
        return others == every & ~(np.int64(1) << np.int64(k))
    if op == CSG_DIFFERENCE:
        if k == 0:
            return others == 0
        return (inside & np.int64(1)) == 1 and (others & ~np.int64(1)) == 0
    return True  # union


@kernel(inline="always")
def _flat_may_show(op, possible, every):
    """:func:`may_show` for a tree of one operation on leaves."""
    if op == CSG_INTERSECTION:
        return (possible & every) == every
    if op == CSG_DIFFERENCE:
        return (possible & np.int64(1)) == 1
    return (possible & every) != 0


@kernel(inline="always")
def _shows(geo, root, flat, k, inside, cuts, every):
    if flat >= 0:
        return _flat_shows(flat, k, inside, every)
    return surface_shows(geo, root, k, inside, cuts)


@kernel(inline="always")
def _may_show(geo, root, flat, possible, cuts, every):
    if flat >= 0:
        return _flat_may_show(flat, possible, every)
    return may_show(geo, root, possible, cuts)


@kernel(inline="always")
def _crossing(r0, r1, r2, r3, k, c):
    """Crossing number ``c`` of leaf ``k`` (its sorted crossings are r0..r3[k])."""
    if c == 0:
        return r0[k]
    if c == 1:
        return r1[k]
    if c == 2:
        return r2[k]
    return r3[k]


@kernel(inline="always")
def _pick(c, x0, x1, x2, x3):
    """``x<c>``, INF past the fourth."""
    if c == 0:
        return x0
    if c == 1:
        return x1
    if c == 2:
        return x2
    if c == 3:
        return x3
    return INF


@kernel(inline="always")
def _pair_walk(geo, root, op, o, d, tmin, tmax, collect, hits, n_hits, full):
    """:func:`_walk` for one operation on two leaves walked by parity (a block minus a
    ball, a lens, a half ring, a merge of two balls: most CSG objects), with the two leaves'
    crossings in registers rather than in the walk's slots; the same crossings, visited in
    the same order (leaf 0 first on a tie), so the same answer. Returns (done, t, leaf row,
    n_hits, full); not done when a leaf has an odd number of crossings (one lost to
    rounding at an edge: the general walk goes by its normals)."""
    na, a0, a1, a2, a3 = leaf_crossings(geo, root + 1, o, d)
    nb, b0, b1, b2, b3 = leaf_crossings(geo, root + 2, o, d)
    if na % 2 == 1 or nb % 2 == 1:
        return False, INF, np.int64(-1), n_hits, full
    ia = 0
    while ia < na and _pick(ia, a0, a1, a2, a3) <= tmin:
        ia += 1
    ib = 0
    while ib < nb and _pick(ib, b0, b1, b2, b3) <= tmin:
        ib += 1
    inside = np.int64(ia % 2) | (np.int64(ib % 2) << np.int64(1))
    while True:
        ta = _pick(ia, a0, a1, a2, a3) if ia < na else INF
        tb = _pick(ib, b0, b1, b2, b3) if ib < nb else INF
        if ta <= tb:
            t = ta
            k = 0
            entering = ia % 2 == 0
            ia += 1
        else:
            t = tb
            k = 1
            entering = ib % 2 == 0
            ib += 1
        if t >= tmax:
            break
        if _flat_shows(op, k, inside, np.int64(3)):
            if not collect:
                return True, t, np.int64(root + 1 + k), n_hits, full
            n_hits, full = keep_nearest(hits, n_hits, t, np.int64(root + 1 + k), full)
        inside = _with_bit(inside, k, 1 if entering else 0)
    return True, INF, np.int64(-1), n_hits, full


@kernel(inline="always")
def _box_met(geo, root, o, inv, tmin, tmax):
    """Does the segment (tmin, tmax) meet the box of CSG object ``root``? (Shadow rays test
    listed objects without their boxes.)"""
    P = geo.prim_params
    return slab_entry(P[root, 2], P[root, 3], P[root, 4], P[root, 5], P[root, 6], P[root, 7],
                      o, inv, tmin, tmax) != INF


@kernel(inline="always")
def _is_pair(geo, root):
    """Is CSG object ``root`` one operation on two leaves walked by parity, with no groups
    of cuts (:func:`_pair_walk`)?"""
    P = geo.prim_params
    return (P[root, 0] == 3.0 and P[root, 1] == 2.0 and P[root, 10] <= 0.0
            and has_crossings(geo.prim_info[root + 1, PRIM_TYPE])
            and has_crossings(geo.prim_info[root + 2, PRIM_TYPE]))


@kernel
def csg_hit(geo, root, o, d, inv, tmin, tmax):
    """(t, leaf row) of the nearest visible surface of CSG object ``root`` in (tmin, tmax),
    or (INF, -1) (``inv``: the ray's inverse direction). Two leaves are walked here
    (:func:`_pair_walk`), in registers; any other tree through a call (:func:`_walk`), whose
    frame holds the slots of up to 63 leaves."""
    if not _box_met(geo, root, o, inv, tmin, tmax):
        return INF, np.int64(-1)
    if _is_pair(geo, root):
        done, t, row, _, _ = _pair_walk(geo, root, int(geo.prim_params[root + 3, 0]), o, d,
                                        tmin, tmax, False, slots(float_slots(), FRAME_SLOTS),
                                        0, False)
        if done:
            return t, row
    return _general_hit(geo, root, o, d, inv, tmin, tmax)


@kernel
def _general_hit(geo, root, o, d, inv, tmin, tmax):
    t, row, _, _ = _walk(geo, root, o, d, inv, tmin, tmax, False,
                         slots(float_slots(), FRAME_SLOTS), 0, False)
    return t, row


@kernel
def csg_surfaces(geo, root, o, d, inv, tmin, tmax, hits, n, full):
    """Every visible surface of CSG object ``root`` in (tmin, tmax), as (t, leaf row) pairs
    kept in the shadow ray's ``hits`` list (hit_list.py; its n and full in and out): one walk
    where asking :func:`csg_hit` again from past each surface walked once a surface."""
    if not _box_met(geo, root, o, inv, tmin, tmax):
        return n, full
    if _is_pair(geo, root):
        done, _, _, n_pair, full_pair = _pair_walk(
            geo, root, int(geo.prim_params[root + 3, 0]), o, d, tmin, tmax, True, hits, n,
            full)
        if done:
            return n_pair, full_pair
    return _general_surfaces(geo, root, o, d, inv, tmin, tmax, hits, n, full)


@kernel
def _general_surfaces(geo, root, o, d, inv, tmin, tmax, hits, n, full):
    _, _, n, full = _walk(geo, root, o, d, inv, tmin, tmax, True, hits, n, full)
    return n, full


@kernel(inline="always")
def _walk(geo, root, o, d, inv, tmin, tmax, collect, hits, n_hits, full):
    """The walk: (t, leaf row) of the nearest visible surface of CSG object ``root`` in
    (tmin, tmax), or (INF, -1); with ``collect``, every visible surface is put in ``hits``
    instead (:func:`.hit_list.keep_nearest`) and the walk goes on past it. Returns those two
    and the list's (n_hits, full).

    An analytic leaf's crossings with the whole line are found once (:func:`leaf_crossings`)
    and walked in order: a leaf is inside where an odd number of them lie behind, so the walk
    needs no normals. A mesh leaf's next crossing is asked for only once the walk has passed
    its last one (its state from the sign of the normal there, as the module docstring
    says). The walk stops as soon as no surface can show (``may_show``), first after the
    leaves of the root's first operand (a die: the rays that miss its rounded cube skip its
    pips)."""
    P = geo.prim_params
    n_rows = int(P[root, 0])
    n_leaves = int(P[root, 1])
    first_leaves = int(P[root, 8])  # leaves of the first operand of a root that needs it
    cuts = _cut_mask(geo, root)
    every = (np.int64(1) << np.int64(n_leaves)) - np.int64(1) if n_leaves < 63 else ~np.int64(0)
    # a tree of one operation on leaves (rows: the leaves, then it) is tested with masks
    flat = int(P[root + n_rows, 0]) if n_rows == n_leaves + 1 else -1
    # an analytic leaf's crossings r0..r3 and their count (-1: a mesh leaf, whose next
    # crossing is r0, on triangle row ``part``, with d · normal there ``next_cos``, NaN
    # until computed); ``cur``: the leaf's next crossing in the walk
    r0 = slots(float_slots(), FRAME_SLOTS)
    r1 = slots(float_slots(), FRAME_SLOTS)
    r2 = slots(float_slots(), FRAME_SLOTS)
    r3 = slots(float_slots(), FRAME_SLOTS)
    count = slots(int_slots(), FRAME_SLOTS)
    cur = slots(int_slots(), FRAME_SLOTS)
    rows = slots(int_slots(), FRAME_SLOTS)
    part = slots(int_slots(), FRAME_SLOTS)
    next_cos = slots(float_slots(), FRAME_SLOTS)
    inside = np.int64(0)
    alive = np.int64(0)
    skip = np.int64(0)  # cut leaves in groups the ray misses: outside, no crossing
    odd = np.int64(0)  # analytic leaves walked by their normals (see below)
    leaf = 0
    for r in range(root + 1, root + 1 + n_rows):
        if is_csg_operation(geo.prim_info[r, PRIM_TYPE]):
            continue
        rows[leaf] = r
        cur[leaf] = 0
        if _bit(skip, leaf):
            count[leaf] = 0
        elif is_csg_mesh_leaf(geo.prim_info[r, PRIM_TYPE]):
            t, tri = mesh_leaf_t(geo, r, o, d, tmin, INF)
            count[leaf] = -1
            r0[leaf] = t
            part[leaf] = tri
            if t < INF:
                if t < tmax:
                    alive = _with_bit(alive, leaf, 1)
                cos = dot(d, leaf_normal(geo, tri, madd(o, d, t)))
                next_cos[leaf] = cos  # the walk's crossing there needs it again
                if cos > 0.0:
                    inside = _with_bit(inside, leaf, 1)  # its first crossing leaves it
        else:
            n, a0, a1, a2, a3 = leaf_crossings(geo, r, o, d)
            count[leaf] = n
            r0[leaf] = a0
            r1[leaf] = a1
            r2[leaf] = a2
            r3[leaf] = a3
            c = 0
            while c < n and _crossing(r0, r1, r2, r3, leaf, c) <= tmin:
                c += 1
            cur[leaf] = c
            # an odd count (one lost to rounding, or a touch): the normals say which way each
            # crossing goes, as for a mesh
            if n % 2 == 1:
                odd = _with_bit(odd, leaf, 1)
                if c < n and dot(d, leaf_normal(geo, r, madd(
                        o, d, _crossing(r0, r1, r2, r3, leaf, c)))) > 0.0:
                    inside = _with_bit(inside, leaf, 1)
            elif c % 2 == 1:
                inside = _with_bit(inside, leaf, 1)
            if c < n and _crossing(r0, r1, r2, r3, leaf, c) < tmax:
                alive = _with_bit(alive, leaf, 1)
        leaf += 1
        if leaf == first_leaves and leaf < n_leaves:  # the rest unknown yet: possible
            untested = ~((np.int64(1) << np.int64(leaf)) - np.int64(1))
            if not _may_show(geo, root, flat, alive | inside | untested, cuts, every):
                return INF, np.int64(-1), n_hits, full
            if P[root, 10] > 0.0:
                skip = _missed_groups(geo, root, o, inv, tmin, tmax)
    if not _may_show(geo, root, flat, alive | inside, cuts, every):
        return INF, np.int64(-1), n_hits, full
    d_len = math.sqrt(dot(d, d))
    while alive != 0:
        best_t = INF
        k = -1
        for j in range(n_leaves):
            if _bit(alive, j):
                t = r0[j] if count[j] < 0 else _crossing(r0, r1, r2, r3, j, cur[j])
                if t < best_t:
                    best_t = t
                    k = j
        if k < 0:
            break
        if count[k] < 0:  # a mesh leaf: which way it crosses from its normal
            row = np.int64(part[k])
            cos = next_cos[k]
            if math.isnan(cos):
                cos = dot(d, leaf_normal(geo, row, madd(o, d, best_t)))
            touch = abs(cos) <= GRAZING * d_len  # no state changes, nothing shows
            entering = cos < 0.0
        elif _bit(odd, k):
            row = np.int64(rows[k])
            cos = dot(d, leaf_normal(geo, row, madd(o, d, best_t)))
            touch = abs(cos) <= GRAZING * d_len
            entering = cos < 0.0
        else:
            row = np.int64(rows[k])
            touch = False
            entering = cur[k] % 2 == 0
        if not touch:
            if _shows(geo, root, flat, k, inside, cuts, every):
                if not collect:
                    return best_t, row, n_hits, full
                n_hits, full = keep_nearest(hits, n_hits, best_t, row, full)
            inside = _with_bit(inside, k, 1 if entering else 0)
        # the leaf's next crossing
        if count[k] < 0:
            t, tri = mesh_leaf_t(geo, rows[k], o, d, best_t, tmax)
            r0[k] = t
            part[k] = tri
            next_cos[k] = math.nan
            dead = t == INF
        else:
            cur[k] += 1
            dead = cur[k] >= count[k] or _crossing(r0, r1, r2, r3, k, cur[k]) >= tmax
        if dead:
            alive = _with_bit(alive, k, 0)
            if not _may_show(geo, root, flat, alive | inside, cuts, every):
                break
    return INF, np.int64(-1), n_hits, full
