"""The shapes: what every kind of object provides the renderer, written down once.

A shape kind (a ``type`` of the scene format, ``scene/shapes.py``) is whole when it has:

- **rows and bounds** (compile side): ``compile/shapes.py`` ``add_shape`` writes its row of
  ``prim_params`` (the columns listed beside its ``SHAPE_*`` code in ``kernels/layout.py``),
  its transform baked in or kept as ``PRIM_XFORM``, and the world box the BVH holds it in;
- **hit**: ``intersect_<shape>(P, i, o, d, tmin, tmax) -> t`` (``INF`` for a miss), the
  nearest crossing in (tmin, tmax) of the ray ``o + t d`` in the primitive's own space;
- **crossings** (solids only: what CSG and the media need): ``<shape>_span`` /
  ``<shape>_crossings(P, i, o, d)``, every crossing of the whole line in order, entering and
  leaving, computed from the ray alone so that asking again from past one gives the next;
- **normal**: the outward unit normal at a point on it (``normal_local``'s branch, or
  ``<shape>_normal(P, i, p)``);
- **uv**: its texture coordinates at a point on it (``kernels/uv.py``'s mapping, or
  ``<shape>_uv(P, i, p)``), documented in docs/scene-format.md's table;
- its POV-Ray export, its editor entry and Shape section, its ``whitted info`` line and its
  docs (tests/test_shape_completeness.py checks every kind has all of them).

The dispatch on the ``SHAPE_*`` code is in one place per query: ``intersect.py``
``intersect_local`` / ``normal_local`` and ``uv.py`` ``surface_uv`` for the core shapes,
``extras.py`` for the shapes compiled only into kernels for scenes that have them (tori, CSG
objects), ``csg.py`` ``leaf_crossings`` / ``leaf_normal`` for CSG leaves.

One file per shape is the aim: ``torus.py`` here is the template (its hit, crossings, normal
and uv together); ``sphere.py`` and ``box.py`` hold theirs (the sphere's normal stays
written in place in ``normal_local``, the hottest path); ``quadric.py`` the quadratics the
quadrics share. :data:`PIECES` names, for every kind, the function of each piece (one named
hop), wherever it lives now.
"""

from __future__ import annotations

#: kind -> piece -> "module:function" (module under ``whitted``); ``None``: the kind has no
#: such piece (a flat or open shape bounds no volume, so CSG refuses it: no crossings)
PIECES: dict[str, dict[str, str | None]] = {
    "sphere": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.shapes.sphere:intersect_sphere",
        "crossings": "kernels.shapes.sphere:sphere_span",
        "normal": "kernels.intersect:normal_local", "uv": "kernels.shapes.sphere:sphere_uv",
    },
    "plane": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.intersect:intersect_plane",
        "crossings": None, "normal": "kernels.intersect:normal_local",
        "uv": "kernels.uv:surface_uv",
    },
    "rectangle": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.intersect:intersect_rectangle",
        "crossings": None, "normal": "kernels.intersect:normal_local",
        "uv": "kernels.uv:surface_uv",
    },
    "disk": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.intersect:intersect_disk",
        "crossings": None, "normal": "kernels.intersect:normal_local",
        "uv": "kernels.uv:surface_uv",
    },
    "triangle": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.shapes.triangle:intersect_triangle",
        "crossings": None, "normal": "kernels.intersect:normal_local",
        "uv": "kernels.shapes.triangle:triangle_uv",
    },
    "box": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.shapes.box:intersect_box",
        "crossings": "kernels.shapes.box:box_span", "normal": "kernels.shapes.box:box_normal",
        "uv": "kernels.shapes.box:box_uv",
    },
    "cylinder": {  # a frustum with equal radii
        "rows": "compile.shapes:add_shape", "hit": "kernels.intersect:intersect_frustum",
        "crossings": "kernels.intersect:frustum_crossings",
        "normal": "kernels.intersect:_solid_normal", "uv": "kernels.uv:_frustum_uv",
    },
    "cone": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.intersect:intersect_frustum",
        "crossings": "kernels.intersect:frustum_crossings",
        "normal": "kernels.intersect:_solid_normal", "uv": "kernels.uv:_frustum_uv",
    },
    "torus": {
        "rows": "compile.shapes:add_shape", "hit": "kernels.shapes.torus:intersect_torus",
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
