"""The render kernel's callees that a helper process compiles, with the argument types their
callers call them with.

Numba compiles a kernel's callees one after another, depth first, in the process that
compiles it. On a cold cache the render API starts a second process that compiles these
(and then the builders) into the on-disk cache while the first compiles ``render_tiles``;
when the first reaches one of them it waits for the helper and loads it instead of compiling
it too (``render/warm_up.py``, ``dispatcher.KernelCache.wait_for_helper``; only with the tuned
dispatcher of jit/dispatcher.py). The types must be
exactly the ones the callers ask for, or the helper's work is wasted: ``tests/test_warm_up.py``
checks them. Integers are int64 everywhere (``dispatcher.KernelDispatcher`` widens them); what is
compiled is each kernel's twin for calls from kernels (``callee``).

The share is chosen by measured compile times (docs/performance.md, "the first compile's two
processes"): for scenes without mesh instances the helper takes ``hit_analytic`` (the
analytic shapes' intersections, which ``closest_hit`` reaches late), ``surface_normals``
(the direct light's shadow rays call both: compiled once, by the helper) and then the
direct light with its shadow rays (``direct_light``, one function down to the shadow rays'
walks, which the render kernel reaches after the hit's normals and colour), then compiles
the builders and the OBJ reader; for scenes with mesh
instances (the builders are already cached) it takes ``direct_light`` alone. What remains
here is two of ``direct_light``'s own callees, compiled first (:func:`callees_here_first`),
then ``closest_hit``, normals, colour, the caustics, the adaptive sampler and
``render_tiles``, which inlines them all (work only this process can do, as it needs
everything below it).
"""

from __future__ import annotations

from numba import typeof, types

from .accel import hit_analytic, surface_normals
from .caustics import add_caustic
from .features import instances_possible
from .geometry_ref import GeometryRef
from .integrator import split_at_surface
from .layout import GeometryArrays
from .lighting import direct_light, disk_left_out, list_bundle_occluders

VEC3 = types.UniTuple(types.float64, 3)
INT = types.int64
REAL = types.float64
INT32S = types.int32[::1]  # a lane's scratch lists and traversal stack: contiguous int32
REALS = types.float64[::1]
INT64S = types.int64[::1]  # a lane's ray counts


def render_callees(geometry: GeometryArrays, materials, lights, params):
    """(kernel, argument types) pairs for a scene with these arrays, lights and render
    parameters (their types pick the variant: with or without mesh instances), in the order
    the render kernel needs them."""
    geo = typeof(geometry)
    if instances_possible(geo):  # render_tiles passes the geometry by reference
        geo = GeometryRef(geo)
    mats = typeof(materials)
    if instances_possible(geo):
        return [(direct_light, (geo, mats, typeof(lights), typeof(params), VEC3, VEC3, VEC3,
                                INT, VEC3, INT32S, INT, INT32S, INT32S, REALS, INT32S, INT64S,
                                types.UniTuple(INT, 3)))]
    return [(hit_analytic, (geo, INT, VEC3, VEC3, REAL, REAL)),
            (surface_normals, (geo, INT, INT, REAL, REAL, VEC3)),
            (direct_light, (geo, mats, typeof(lights), typeof(params), VEC3, VEC3, VEC3,
                            INT, VEC3, INT32S, INT, INT32S, INT32S, REALS, INT32S, INT64S,
                            types.UniTuple(INT, 3)))]


def callees_here_first(geometry: GeometryArrays, materials, lights, params):
    """(kernel, argument types) pairs the render process compiles before ``render_tiles``
    while the helper compiles its share (scenes without mesh instances). First two of
    ``direct_light``'s own callees (an area light's bundle list and its disk test, 2.1 s of
    the helper's 5.1-s ``direct_light`` on the 2-core AMD EPYC VM): the helper, reaching them
    later, loads them from the cache, so its chain ends about as early as this process
    reaches ``direct_light``. Then the callees the render kernel reaches after
    ``direct_light`` (the caustic term and the refraction), so that it reaches
    ``direct_light`` later, when the helper has it ready, instead of waiting for it with
    those still to do."""
    geo = typeof(geometry)
    if instances_possible(geo):
        return []
    mats = typeof(materials)
    return [(list_bundle_occluders, (geo, mats, VEC3, VEC3, REAL, REAL, INT32S, INT32S)),
            (disk_left_out, (typeof(lights.table), INT, mats, INT, VEC3, VEC3, VEC3, VEC3,
                             REAL)),
            (add_caustic, (typeof(lights), mats, INT, VEC3, VEC3, VEC3, VEC3)),
            (split_at_surface, (geo, mats, INT, INT, types.boolean, INT32S, INT, INT32S, VEC3,
                                VEC3, REAL, REAL))]
