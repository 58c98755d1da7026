"""The render kernel's largest callees, with the argument types ``render_tiles`` calls them
with.

Numba compiles a kernel's callees one after another in the same process. On a cold cache the
render API starts a second process that compiles these (and the builders) into the on-disk
cache while the first compiles ``render_tiles``, which then loads them instead of compiling
them (``render/warm_up.py``). The types must be exactly the ones ``render_tiles`` asks for, or
the second process's work is wasted: ``tests/test_warm_up.py`` checks them. Integers are
int64 everywhere (``jit.KernelDispatcher`` widens them).

Ordered by when ``render_tiles`` first calls them. ``closest_hit`` is left out: it is the
first thing ``render_tiles`` needs, before the second process could finish it.
"""

from __future__ import annotations

from numba import typeof, types

from .accel import surface_normals
from .features import instances_possible
from .geometry_ref import GeometryRef
from .layout import GeometryArrays
from .lighting import any_occluder
from .texture import texture_color
from .uv import surface_uv

VEC3 = types.UniTuple(types.float64, 3)
INT = types.int64
REAL = types.float64
STACK = types.int32[::1]  # a lane's traversal stack: int32, one dimension, contiguous


def render_callees(geometry: GeometryArrays, materials):
    """(kernel, argument types) pairs for a scene with these arrays (their types pick the
    variant: with or without mesh instances)."""
    geo = typeof(geometry)
    if instances_possible(geo):  # render_tiles passes the geometry by reference
        geo = GeometryRef(geo)
    mats = typeof(materials)
    callees = [
        (surface_normals, (geo, INT, INT, REAL, REAL, VEC3)),
        (surface_uv, (geo, INT, INT, REAL, REAL, VEC3)),
        (texture_color, (typeof(geometry.tex_info), typeof(geometry.tex_pixels), INT, REAL,
                         REAL)),
    ]
    if instances_possible(geo):  # without instances shadow rays never take the any-hit walk
        callees.append((any_occluder, (geo, mats, VEC3, VEC3, REAL, REAL, STACK)))
    return callees
