"""Build the light buffers of the point lights (see kernels/light_buffer.py for the idea and
the cell layout): for every cell of the cube map around a light, the analytic primitives a
shadow ray through that cell could hit.

The list of a cell is conservative: a primitive is listed when its BVH leaf box meets a cone
that holds the cell's whole pyramid of rays out to the far side of the scene's bounds, and an
unbounded plane unless every ray of the cell runs away from it. In scenes with mesh instances
a cell lists, after its analytic primitives, the leaves of the instance BVH whose boxes meet
the same cone, each as ``-1 - node`` (the shadow ray tests the leaf's box, then each of its
instances: kernels/lighting.py ``listed_occlusion``).
"""

from __future__ import annotations

import numpy as np

from ..jit import kernel
from ..kernels.features import has_instances
from ..kernels.layout import (
    BVH_STACK,
    CELL_COUNT,
    CELL_FIRST,
    CELL_OPAQUE,
    LIGHT_BUFFER,
    LIGHT_BUFFER_SIDE,
    LIGHT_POINT,
    LIGHT_POSITION,
    LIGHT_TYPE,
    MAT_KT,
    PRIM_MATERIAL,
    PRIM_TYPE,
    PRIM_XFORM,
    SHAPE_PLANE,
    GeometryArrays,
    LightArrays,
)
from ..kernels.light_buffer import (
    LIGHT_BUFFER_CAP,
    LIGHT_BUFFER_CELLS,
    LIGHT_BUFFER_RES,
    cell_cone,
    cell_direction,
)
from ..kernels.lighting import list_cone_instance_leaves, list_cone_leaves
from ..kernels.mesh import OPAQUE_KT

CONE_SLACK = 1e-6  # relative widening of each cell's cone (rounding of the ray directions)
CELLS_PER_PRIMITIVE = 256  # cells per light for each primitive, at most: finer cells would
# barely shorten the lists (seed000, 660 primitives, keeps its 128 cells a side)
PLANE_SLACK = 1e-9  # a cell's corner must run this clearly away from a plane to drop it


@kernel
def _plane_out_of_reach(P, i, light, cell, res):
    """True when no ray from ``light`` through ``cell`` meets plane primitive ``i``: every
    corner direction of the cell runs parallel to or away from the plane (the cell's
    directions are spanned by its corners, and the sign of d·n is linear in them)."""
    n = (P[i, 3], P[i, 4], P[i, 5])
    s = (light[0] - P[i, 0]) * n[0] + (light[1] - P[i, 1]) * n[1] + (light[2] - P[i, 2]) * n[2]
    if s == 0.0:
        return False
    face = cell // (res * res)
    iu = (cell // res) % res
    iv = cell % res
    for du in range(2):
        for dv in range(2):
            d = cell_direction(face, -1.0 + 2.0 * (iu + du) / res, -1.0 + 2.0 * (iv + dv) / res)
            away = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) * (1.0 if s > 0.0 else -1.0)
            if away < PLANE_SLACK:
                return False
    return True


@kernel(entry=True)  # called from Python
def list_cell_occluders(geo, mats, light, reach, res, lists, counts, opaque, stack, first,
                        last):
    """For cells ``first`` to ``last - 1``: fill ``lists[cell, :counts[cell]]`` with the
    primitives that may block rays leaving ``light`` through the cell (``counts[cell]`` = -1
    when there are more than the row holds) and ``opaque[cell]`` with whether they are all
    opaque (a cell that lists instance leaves, ``-1 - node``, never is). ``reach`` is at
    least the distance from the light to the farthest corner of the scene BVH's and the
    instance BVH's root boxes. Cells do not depend on each other: ranges may run on threads of
    their own (``stack`` is the thread's)."""
    cap = lists.shape[1]
    for cell in range(first, last):
        n = 0
        all_opaque = n == 0  # True, typed bool (a literal compiles list_cone_leaves twice)
        for j in range(geo.unbounded.shape[0]):
            i = geo.unbounded[j]
            if (geo.prim_info[i, PRIM_TYPE] == SHAPE_PLANE and geo.prim_info[i, PRIM_XFORM] < 0
                    and _plane_out_of_reach(geo.prim_params, i, light, cell, res)):
                continue
            if n == cap:
                n = -1
                break
            lists[cell, n] = i
            n += 1
            all_opaque = all_opaque and mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT
        if n >= 0:
            c, tan_half = cell_cone(cell, res)
            axis = (c[0] * reach, c[1] * reach, c[2] * reach)
            radius = reach * tan_half * (1.0 + CONE_SLACK) + reach * CONE_SLACK
            n, all_opaque = list_cone_leaves(geo, mats, light, axis, radius, stack, lists[cell],
                                             n, cap, all_opaque)
            if n >= 0 and has_instances(geo):
                n, all_opaque = list_cone_instance_leaves(geo, light, axis, radius, stack,
                                                          lists[cell], n, cap, all_opaque)
        counts[cell] = n
        opaque[cell] = 1 if (n >= 0 and all_opaque) else 0


def _reach(geo: GeometryArrays, light: np.ndarray) -> float:
    """Distance from ``light`` to the farthest corner of the scene BVH's root box and of the
    instance BVH's, widened."""
    far = 0.0
    if geo.node_box.shape[0]:
        lo, hi = geo.node_box[0]
        # the root box is in the BVH's frame (compile/bvh_frame.py)
        seen = geo.bvh_frame @ light if geo.bvh_frame.shape[0] else light
        far = float(np.linalg.norm(np.maximum(np.abs(lo - seen), np.abs(hi - seen))))
    if geo.inst_box.shape[0]:
        lo, hi = geo.inst_box[0].astype(np.float64)
        far = max(far, float(np.linalg.norm(np.maximum(np.abs(lo - light), np.abs(hi - light)))))
    if far == 0.0:
        return 1.0
    return far * (1.0 + 1e-6) + 1e-9


def buffer_side(n_point_lights: int, n_prims: int, res: int = LIGHT_BUFFER_RES) -> int:
    """Cells along a cube-face side for each of ``n_point_lights`` buffers over ``n_prims``
    primitives: ``res``, less when so many lights share the LIGHT_BUFFER_CELLS budget, and
    less for a scene so small that finer cells would barely part its primitives further (at
    most CELLS_PER_PRIMITIVE cells each: a one-sphere scene gets 6 a side and builds at once)."""
    if n_point_lights == 0 or res <= 0:  # res 0: no buffers at all
        return 0
    fit = min(LIGHT_BUFFER_CELLS / n_point_lights, CELLS_PER_PRIMITIVE * max(1, n_prims))
    return max(1, min(res, int(np.sqrt(fit / 6))))


def build_light_buffers(geo: GeometryArrays, materials: np.ndarray, table: np.ndarray,
                        res: int = LIGHT_BUFFER_RES, cap: int = LIGHT_BUFFER_CAP,
                        threads: int = 1) -> LightArrays:
    """The light table with a light buffer for each point light (its LIGHT_BUFFER column set
    to its first cell; -1 for other lights, and for every light when ``res`` is 0). The
    cells are listed on ``threads`` threads, each taking an equal run of every light's cells:
    the same buffers on any number."""
    table = table.copy()
    res = buffer_side(int(np.sum(table[:, LIGHT_TYPE] == LIGHT_POINT)), len(geo.prim_info), res)
    table[:, LIGHT_BUFFER] = -1.0
    lights = [j for j in range(table.shape[0])
              if not (res <= 0 or table[j, LIGHT_TYPE] != LIGHT_POINT)]
    n_cells = 6 * res * res if lights else 0
    lists = np.empty((len(lights) * n_cells, cap), np.int32)
    counts = np.empty(len(lights) * n_cells, np.int32)
    opaque = np.empty(len(lights) * n_cells, np.int32)
    work = []  # (light position, reach, first cell, last cell, row offset)
    for k, j in enumerate(lights):
        light = table[j, LIGHT_POSITION : LIGHT_POSITION + 3].copy()
        table[j, LIGHT_BUFFER] = k * n_cells
        table[j, LIGHT_BUFFER_SIDE] = res
        position = (float(light[0]), float(light[1]), float(light[2]))
        reach = _reach(geo, light)
        parts = max(1, threads)
        bounds = [n_cells * i // parts for i in range(parts + 1)]
        work += [(position, reach, bounds[i], bounds[i + 1], k * n_cells)
                 for i in range(parts) if bounds[i + 1] > bounds[i]]

    def run(part) -> None:
        position, reach, first, last, row = part
        block = slice(row, row + n_cells)  # the light's own rows: cells count from 0 in it
        list_cell_occluders(geo, materials, position, reach, res, lists[block], counts[block],
                            opaque[block], np.empty(BVH_STACK, np.int32), first, last)

    if threads > 1 and len(work) > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(min(threads, len(work))) as pool:
            list(pool.map(run, work))  # the kernel releases the GIL
    else:
        for part in work:
            run(part)
    listed = np.maximum(counts, 0)
    offsets = np.zeros(len(listed), np.int64)
    np.cumsum(listed[:-1], out=offsets[1:])
    # each cell's list (none where the count is -1), one after another: row by row
    prims = lists[np.arange(lists.shape[1])[None, :] < counts[:, None]]
    cells = np.empty((len(counts), 3), np.int32)
    cells[:, CELL_FIRST] = offsets
    cells[:, CELL_COUNT] = counts
    cells[:, CELL_OPAQUE] = opaque
    return LightArrays(table=table, buffer_cells=cells, buffer_prims=prims)
