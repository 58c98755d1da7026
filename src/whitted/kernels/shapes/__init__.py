"""The shapes: what every kind of object provides the renderer, written down once.

Each analytic kind has one file here holding all of its kernel pieces (``frustum.py`` serves
the cylinder and the cone, both frustum rows); ``flat.py`` and ``quadric.py`` hold what
several shapes share. A shape kind (a ``type`` of the scene format, ``scene/shapes.py``) is
whole when it has:

- **rows and bounds** (compile side, one named hop): ``compile/shapes.py`` ``ROWS`` maps
  its scene class to ``<shape>_rows(b, shape, placement, material, obj)``, which writes its
  row of ``prim_params`` (the columns listed in its file's docstring and beside its
  ``SHAPE_*`` code in ``kernels/layout.py``), its transform baked in or kept as
  ``PRIM_XFORM``, and the world box the BVH holds it in (a plane: none, it is unbounded);
- **hit**: ``intersect_<shape>(P, i, o, d, tmin, tmax) -> t``, the nearest crossing in
  (tmin, tmax) of the ray ``o + t d`` in the row's own space (:data:`INF` for a miss);
- **crossings** (solids only: what CSG needs): ``<shape>_span`` / ``<shape>_crossings(P, i,
  o, d)``, every crossing of the whole line in order, entering and leaving, computed from
  the ray alone so that asking again from past one gives the next (``dispatch.py``
  ``solid_crossings`` counts them for the CSG walk; the frustum, convex, gives its first and
  last: ``frustum_solid_crossings``); a flat or open shape bounds no volume, has none, and
  CSG refuses it (``scene/shapes.py``);
- **normal**: ``<shape>_normal(P, i, p)``, the outward unit normal at a point on it;
- **uv**: ``<shape>_uv(P, i, p)``, its texture coordinates at a point on it, the mapping said
  in its docstring and in docs/scene-format.md's table;
- its POV-Ray export, its editor entry and Shape section, its ``whitted info`` line and its
  docs.

``dispatch.py`` is the one place the shape code picks these functions (hit, normal, uv,
crossings): the walks (accel.py), the uv of a hit (uv.py), the kernels of the shapes only
some scenes have (extras.py) and the CSG walk (csg.py) all ask there. It also holds the
named predicates (``is_extra``, ``is_csg_object``, ``has_shading_normal``, ``crossed_twice``,
...) through which every kernel outside this package tells kinds of rows apart; none of
them compares a row's type with a ``SHAPE_*`` code. Two kinds are
composites walked elsewhere: a mesh (its triangles flattened into triangle rows, or kept
whole as an instance, whose BVH kernels/mesh.py walks with the triangle test of this
package's ``mesh.py``) and a CSG object (kernels/csg.py walks its leaves, each an ordinary
solid row).

:data:`PIECES` names, for every kind, the function of each piece (one named hop);
tests/test_shape_completeness.py checks that each exists, lives in the kind's own file, is
reached from ``dispatch.py`` (or the composite's walk), that no kernel outside this package
compares a row's type with a shape code, and that every kind has its export,
editor entry, ``whitted info`` line and docs.
"""

from __future__ import annotations

import math

INF = math.inf  # the t of a miss: what every hit returns when the ray misses

#: kind -> piece -> "module:function" (module under ``whitted``); ``None``: the kind has no
#: such piece (a flat or open shape bounds no volume, so CSG refuses it: no crossings)
PIECES: dict[str, dict[str, str | None]] = {
    "sphere": {
        "rows": "compile.shapes:sphere_rows", "hit": "kernels.shapes.sphere:intersect_sphere",
        "crossings": "kernels.shapes.sphere:sphere_span",
        "normal": "kernels.shapes.sphere:sphere_normal", "uv": "kernels.shapes.sphere:sphere_uv",
    },
    "plane": {
        "rows": "compile.shapes:plane_rows", "hit": "kernels.shapes.plane:intersect_plane",
        "crossings": None, "normal": "kernels.shapes.plane:plane_normal",
        "uv": "kernels.shapes.plane:plane_uv",
    },
    "rectangle": {
        "rows": "compile.shapes:rectangle_rows",
        "hit": "kernels.shapes.rectangle:intersect_rectangle", "crossings": None,
        "normal": "kernels.shapes.rectangle:rectangle_normal",
        "uv": "kernels.shapes.rectangle:rectangle_uv",
    },
    "disk": {
        "rows": "compile.shapes:disk_rows", "hit": "kernels.shapes.disk:intersect_disk",
        "crossings": None, "normal": "kernels.shapes.disk:disk_normal",
        "uv": "kernels.shapes.disk:disk_uv",
    },
    "triangle": {
        "rows": "compile.shapes:triangle_rows",
        "hit": "kernels.shapes.triangle:intersect_triangle", "crossings": None,
        "normal": "kernels.shapes.triangle:triangle_normal",
        "uv": "kernels.shapes.triangle:triangle_uv",
    },
    "box": {
        "rows": "compile.shapes:box_rows", "hit": "kernels.shapes.box:intersect_box",
        "crossings": "kernels.shapes.box:box_span", "normal": "kernels.shapes.box:box_normal",
        "uv": "kernels.shapes.box:box_uv",
    },
    "cylinder": {  # a frustum with equal radii
        "rows": "compile.shapes:frustum_rows", "hit": "kernels.shapes.frustum:intersect_frustum",
        "crossings": "kernels.shapes.frustum:frustum_solid_crossings",
        "normal": "kernels.shapes.frustum:frustum_normal",
        "uv": "kernels.shapes.frustum:frustum_uv",
    },
    "cone": {
        "rows": "compile.shapes:frustum_rows", "hit": "kernels.shapes.frustum:intersect_frustum",
        "crossings": "kernels.shapes.frustum:frustum_solid_crossings",
        "normal": "kernels.shapes.frustum:frustum_normal",
        "uv": "kernels.shapes.frustum:frustum_uv",
    },
    "torus": {
        "rows": "compile.shapes:torus_rows", "hit": "kernels.shapes.torus:intersect_torus",
        "crossings": "kernels.shapes.torus:torus_crossings",
        "normal": "kernels.shapes.torus:torus_normal", "uv": "kernels.shapes.torus:torus_uv",
    },
    "mesh": {  # flattened triangles (small meshes) or instances of a stored mesh (big ones)
        "rows": "compile.mesh_objects:add_flat_mesh",
        "hit": "kernels.shapes.mesh:intersect_mesh_triangle",
        "crossings": "kernels.csg:mesh_leaf_t", "normal": "kernels.shapes.mesh:mesh_normals",
        "uv": "kernels.shapes.mesh:mesh_uv",
    },
    "csg": {  # its leaves are the solids above; the object walks them
        "rows": "compile.csg:add_csg", "hit": "kernels.csg:csg_hit",
        "crossings": "kernels.csg:leaf_crossings", "normal": "kernels.csg:leaf_normal",
        "uv": "kernels.uv:surface_uv",
    },
}
