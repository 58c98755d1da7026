"""The one place a primitive's shape code picks its shape's function: for each query (hit,
normal, uv, crossings), one function here switches on the ``SHAPE_*`` code and calls the
shape's own file. The scene-level queries (accel.py, uv.py, lighting.py), the kernels of
the shapes only some scenes have (extras.py) and the CSG walk (csg.py) all ask here; none of
them names a shape. Where they must tell kinds apart (a composite walked by code of its own,
a smooth-shaded triangle, a body crossed twice) they ask one of the predicates at the end of
this file. A new shape adds its branch to each function here, and its entry in ``PIECES``.

The switches are chains of comparisons on the code, not tables of functions: a Numba
function value is an indirect call that cannot be inlined, and the hit is asked once per
BVH candidate. What is inlined where is chosen by measurement (docs/performance.md): the
hit switch into the walks; the sphere's and the flat shapes' normals and uvs written into
the switch, the other shapes' behind a call.

The core shapes (codes below ``FIRST_EXTRA_SHAPE``) are in every render kernel; the torus is
asked for through the ``extra_shape_*`` functions, which extras.py reaches only in kernels
compiled for scenes that have such shapes (features.py ``has_extras``).
"""

from __future__ import annotations

import numpy as np

from ...jit import kernel
from ..layout import (
    FIRST_EXTRA_SHAPE,
    SHAPE_BOX,
    SHAPE_CSG,
    SHAPE_CSG_MESH,
    SHAPE_CSG_OP,
    SHAPE_DISK,
    SHAPE_FRUSTUM,
    SHAPE_MESH,
    SHAPE_PLANE,
    SHAPE_RECTANGLE,
    SHAPE_SPHERE,
    SHAPE_TORUS,
    SHAPE_TRIANGLE,
    TRIANGLE_NORMALS,
)
from . import INF
from .box import box_normal, box_span, box_uv, intersect_box
from .disk import disk_normal, disk_uv, intersect_disk
from .frustum import (
    frustum_normal,
    frustum_solid_crossings,
    frustum_uv,
    intersect_frustum,
)
from .plane import intersect_plane, plane_normal, plane_uv
from .rectangle import intersect_rectangle, rectangle_normal, rectangle_uv
from .sphere import intersect_sphere, sphere_ball, sphere_normal, sphere_span, sphere_uv
from .torus import intersect_torus, torus_crossings, torus_normal, torus_uv
from .triangle import intersect_triangle, triangle_ball, triangle_normal, triangle_uv


@kernel(inline="always")
def intersect_local(typ, P, i, o, d, tmin, tmax):
    """Nearest hit in (tmin, tmax) of core primitive ``i`` of shape ``typ`` (``INF``: a
    miss); ``o`` and ``d`` in the primitive's own space."""
    i = np.uint64(i)  # unsigned: no negative-index wraparound code on the parameter loads
    if typ == SHAPE_SPHERE:
        return intersect_sphere(P, i, o, d, tmin, tmax)
    if typ == SHAPE_TRIANGLE:
        return intersect_triangle(P, i, o, d, tmin, tmax)
    if typ == SHAPE_RECTANGLE:
        return intersect_rectangle(P, i, o, d, tmin, tmax)
    if typ == SHAPE_BOX:
        return intersect_box(P, i, o, d, tmin, tmax)
    if typ == SHAPE_PLANE:
        return intersect_plane(P, i, o, d, tmin, tmax)
    if typ == SHAPE_DISK:
        return intersect_disk(P, i, o, d, tmin, tmax)
    if typ == SHAPE_FRUSTUM:
        return intersect_frustum(P, i, o, d, tmin, tmax)
    return INF


@kernel(inline="always")
def normal_local(typ, P, i, p):
    """Outward unit normal at point ``p`` (in the primitive's own space) of a core shape:
    the sphere's and the flat shapes' inlined, a box's or frustum's through a call (inlining
    those too slowed the analytic benchmark by a tenth)."""
    if typ == SHAPE_SPHERE:
        return sphere_normal(P, i, p)
    if typ == SHAPE_TRIANGLE:
        return triangle_normal(P, i, p)
    if typ == SHAPE_RECTANGLE:
        return rectangle_normal(P, i, p)
    if typ == SHAPE_PLANE:
        return plane_normal(P, i, p)
    if typ == SHAPE_DISK:
        return disk_normal(P, i, p)
    return _solid_normal(typ, P, i, p)


@kernel
def _solid_normal(typ, P, i, p):
    """:func:`normal_local` of a box or a frustum."""
    if typ == SHAPE_BOX:
        return box_normal(P, i, p)
    if typ == SHAPE_FRUSTUM:
        return frustum_normal(P, i, p)
    return (0.0, 1.0, 0.0)


@kernel(inline="always")
def uv_local(typ, P, i, p):
    """Texture coordinates of a core shape at point ``p`` in its own space (each shape's
    mapping is in its file, and in docs/scene-format.md's table)."""
    if typ == SHAPE_SPHERE:
        return sphere_uv(P, i, p)
    if typ == SHAPE_RECTANGLE:
        return rectangle_uv(P, i, p)
    if typ == SHAPE_PLANE:
        return plane_uv(P, i, p)
    if typ == SHAPE_DISK:
        return disk_uv(P, i, p)
    if typ == SHAPE_TRIANGLE:
        return triangle_uv(P, i, p)
    if typ == SHAPE_BOX:
        return box_uv(P, i, p)
    if typ == SHAPE_FRUSTUM:
        return frustum_uv(P, i, p)
    return 0.0, 0.0


@kernel(inline="always")
def extra_shape_t(typ, P, i, o, d, tmin, tmax):
    """:func:`intersect_local` of the shapes from ``FIRST_EXTRA_SHAPE`` on (the torus)."""
    if typ == SHAPE_TORUS:
        return intersect_torus(P, i, o, d, tmin, tmax)
    return INF


@kernel(inline="always")
def extra_shape_normal(typ, P, i, p, n):
    """:func:`normal_local` of the torus; ``n`` (the core shapes' answer) for the others."""
    if typ == SHAPE_TORUS:
        return torus_normal(P, i, p)
    return n


@kernel(inline="always")
def extra_shape_uv(typ, P, i, p):
    """:func:`uv_local` of the torus; (0, 0) for the others."""
    if typ == SHAPE_TORUS:
        return torus_uv(P, i, p)
    return 0.0, 0.0


@kernel(inline="always")
def has_crossings(typ):
    """Whether shape ``typ`` gives :func:`solid_crossings` (a sphere, a box, a torus, a
    frustum: in entering and leaving pairs, or an odd count that a CSG walk takes by
    normals)."""
    return (typ == SHAPE_SPHERE or typ == SHAPE_BOX or typ == SHAPE_TORUS
            or typ == SHAPE_FRUSTUM)


@kernel(inline="always")
def solid_crossings(typ, P, j, o, d):
    """Every crossing of the line ``o + t d`` (in row ``j``'s space) with solid row ``j``
    (sphere, box, frustum, torus): (count, t0, t1, t2, t3), sorted, inf-padded. A closed
    solid's line enters at t0 and leaves at t1 (a torus's again at t2 and t3); a tangent
    touch (two equal crossings) is none; a frustum's are its first and last."""
    t2 = INF
    t3 = INF
    if typ == SHAPE_TORUS:
        t0, t1, t2, t3 = torus_crossings(P, j, o, d)
    elif typ == SHAPE_SPHERE:
        t0, t1 = sphere_span(P, j, o, d)
    elif typ == SHAPE_BOX:
        t0, t1 = box_span(P, j, o, d)
    else:
        return frustum_solid_crossings(P, j, o, d)
    if t0 == t1:
        t0, t1, t2, t3 = t2, t3, INF, INF
    n = 0 if t0 == INF else (1 if t1 == INF else (2 if t2 == INF else (3 if t3 == INF else 4)))
    return n, t0, t1, t2, t3


@kernel(inline="always")
def solid_normal(typ, P, j, p):
    """Outward unit normal at ``p`` (row ``j``'s space) of solid row ``j``, the torus too."""
    if typ == SHAPE_TORUS:
        return torus_normal(P, j, p)
    return normal_local(typ, P, j, p)


# The kinds of rows, for the code outside this package that must tell them apart (each
# inlined: a comparison or two, as fast as writing it at the caller).


@kernel(inline="always")
def is_extra(typ):
    """Whether ``typ`` is a shape only some scenes have (a torus, a CSG object): asked
    through extras.py, compiled only for scenes that have one."""
    return typ >= FIRST_EXTRA_SHAPE


@kernel(inline="always")
def is_csg_object(typ):
    """Whether ``typ`` is a CSG object's root row, whose leaves kernels/csg.py walks."""
    return typ == SHAPE_CSG


@kernel(inline="always")
def is_csg_operation(typ):
    """Whether ``typ`` is an operation row of a CSG tree (not a leaf)."""
    return typ == SHAPE_CSG_OP


@kernel(inline="always")
def is_csg_mesh_leaf(typ):
    """Whether ``typ`` is a CSG leaf that is a closed mesh (walked by kernels/mesh.py)."""
    return typ == SHAPE_CSG_MESH


@kernel(inline="always")
def is_mesh_instance(typ):
    """Whether ``typ`` is a mesh instance, whose triangles' BVH kernels/mesh.py walks."""
    return typ == SHAPE_MESH


@kernel(inline="always")
def has_shading_normal(typ, P, i):
    """Whether row ``i`` of shape ``typ`` is a smooth-shaded triangle (of a flattened mesh)."""
    return typ == SHAPE_TRIANGLE and P[i, TRIANGLE_NORMALS] >= 0


@kernel(inline="always")
def is_world_plane(typ, xf):
    """Whether a row of shape ``typ`` and transform ``xf`` is a plane given in world space."""
    return typ == SHAPE_PLANE and xf < 0


@kernel(inline="always")
def crossed_twice(typ, solid):
    """Whether a line through a row of shape ``typ`` (``solid``: its ``PRIM_SOLID``) crosses
    its surface twice: a closed core body, not a triangle of a flattened solid mesh."""
    return solid != 0 and typ != SHAPE_TRIANGLE


@kernel(inline="always")
def bounding_ball(typ, P, i):
    """(whether it has one here, centre, radius): a ball holding row ``i`` of shape ``typ``
    and every point its hit test can find, in the row's own numbers (world space where its
    ``PRIM_XFORM`` is negative), for the spheres and triangles; other shapes: none."""
    if typ == SHAPE_SPHERE:
        c, r = sphere_ball(P, i)
        return True, c, r
    if typ == SHAPE_TRIANGLE:
        c, r = triangle_ball(P, i)
        return True, c, r
    return False, (0.0, 0.0, 0.0), 0.0
