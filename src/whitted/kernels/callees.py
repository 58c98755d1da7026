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
the builders and the OBJ reader. What remains here is two of ``direct_light``'s own
callees, compiled first (:func:`callees_here_first`), then ``closest_hit``, normals, colour,
the caustics, the adaptive sampler and ``render_tiles``, which inlines them all (work only
this process can do, as it needs everything below it). For the general kernels (mesh
instances, tori, CSG objects; the builders are already cached) the helper takes the extra
shapes' intersections (``csg_hit``, the CSG walk, and ``extra_shape_t``, the torus's: the
closest hit and the shadow rays both reach them through ``extra_hit``, an overload's body
that each caller's process compiles, so that one process compiles the walk, not both),
``hit_analytic`` and ``direct_light``; this process the rest.
"""

from __future__ import annotations

from numba import typeof, types

from .accel import closest_hit, hit_analytic, surface_normals
from .caustics import add_caustic
from .csg import csg_hit, csg_surfaces
from .features import instances_possible
from .geometry_ref import GeometryRef
from .integrator import split_at_surface, surface_colour
from .layout import GeometryArrays
from .lighting import direct_light, disk_left_out, list_bundle_occluders
from .shapes.dispatch import extra_shape_t

VEC3 = types.UniTuple(types.float64, 3)
INT = types.int64
REAL = types.float64
INT32S = types.int32[::1]  # a lane's scratch lists and traversal stack: contiguous int32
REALS = types.float64[::1]
INT64S = types.int64[::1]  # a lane's ray counts
PARAMS = types.float64[:, ::1]  # GeometryArrays.prim_params


def _direct_light_types(geo, mats, lights, params):
    return (geo, mats, typeof(lights), typeof(params), VEC3, VEC3, VEC3, INT, VEC3, INT32S,
            INT, INT32S, INT32S, REALS, INT32S, INT64S, types.UniTuple(INT, 3))


def render_callees(geometry: GeometryArrays, materials, lights, params):
    """(kernel, argument types) pairs for a scene with these arrays, lights and render
    parameters (their types pick the variant: plain, or general with mesh instances, tori
    and CSG objects), in the order the helper compiles them."""
    geo = typeof(geometry)
    if instances_possible(geo):  # render_tiles passes the geometry by reference
        geo = GeometryRef(geo)
    mats = typeof(materials)
    if instances_possible(geo):
        # the general kernels: first the extra shapes' intersections (the CSG walk and the
        # torus's quartic, a third of the variant's compile), which both the closest hit
        # here and the helper's shadow rays reach (through extras.py's extra_hit, compiled
        # in each caller's process: an overload's body; the shadow rays' gathering of a
        # torus's crossings calls the extra_hit kernel itself, a second compile of the same
        # code in the helper, about a second); then the shadow rays
        return [(csg_hit, (geo, INT, VEC3, VEC3, VEC3, REAL, REAL)),
                (extra_shape_t, (INT, PARAMS, INT, VEC3, VEC3, REAL, REAL)),
                (hit_analytic, (geo, INT, VEC3, VEC3, REAL, REAL)),
                (direct_light, _direct_light_types(geo, mats, lights, params))]
    return [(hit_analytic, (geo, INT, VEC3, VEC3, REAL, REAL)),
            (surface_normals, (geo, INT, INT, REAL, REAL, VEC3)),
            (direct_light, _direct_light_types(geo, mats, lights, params))]


def callees_here_first(geometry: GeometryArrays, materials, lights, params):
    """(kernel, argument types) pairs the render process compiles before ``render_tiles``
    while the helper compiles its share.

    Plain kernels: first two of ``direct_light``'s own callees (an area light's bundle list
    and its disk test, 2.1 s of the helper's 5.1-s ``direct_light`` on the 2-core AMD EPYC
    VM): the helper, reaching them later, loads them from the cache, so its chain ends about
    as early as this process reaches ``direct_light``. Then the callees the render kernel
    reaches after ``direct_light`` (the caustic term and the refraction), so that it reaches
    ``direct_light`` later, when the helper has it ready, instead of waiting for it with
    those still to do.

    General kernels: what needs none of the helper's extra shapes (the bundle list, the
    refraction, the colour) while the helper compiles the CSG walk; then, once it has
    (waiting for it and the torus's test, and loading them), the closest hit (waiting for
    the helper's ``hit_analytic`` too, about a second later; the helper's shadow walk
    through the instances calls the closest hit after its any-hit test, with the same types,
    and loads it when this process has finished it first, as it had on the 2-core VM), the
    normals and the CSG objects' every-crossing walk of the shadow rays (``csg_surfaces``),
    which the helper's ``direct_light`` reaches only after its shadow walk through the
    instances, and loads. The helper's chain (the CSG walk, ``hit_analytic``, the shadow
    walk, ``direct_light``) is the critical path: each needs the one before it."""
    geo = typeof(geometry)
    mats = typeof(materials)
    if instances_possible(geo):
        geo = GeometryRef(geo)
        return [(list_bundle_occluders, (geo, mats, VEC3, VEC3, REAL, REAL, INT32S, INT32S)),
                (split_at_surface, (geo, mats, INT, INT, types.boolean, INT32S, INT, INT32S,
                                    VEC3, VEC3, REAL, REAL)),
                (surface_colour, (geo, mats, INT, INT, INT, REAL, REAL, VEC3)),
                # the helper's: waited for here, so that what follows loads the CSG walk's
                # pieces (the leaves' crossings and normals) and the torus's instead of
                # compiling them too
                (csg_hit, (geo, INT, VEC3, VEC3, VEC3, REAL, REAL)),
                (extra_shape_t, (INT, PARAMS, INT, VEC3, VEC3, REAL, REAL)),
                (closest_hit, (geo, VEC3, VEC3, REAL, REAL, INT32S)),
                (surface_normals, (geo, INT, INT, REAL, REAL, VEC3)),
                (csg_surfaces, (geo, INT, VEC3, VEC3, VEC3, REAL, REAL, REALS, INT,
                                types.boolean))]
    return [(list_bundle_occluders, (geo, mats, VEC3, VEC3, REAL, REAL, INT32S, INT32S)),
            (disk_left_out, (typeof(lights.table), INT, mats, INT, VEC3, VEC3, VEC3, VEC3,
                             REAL)),
            (add_caustic, (typeof(lights), mats, INT, VEC3, VEC3, VEC3, VEC3)),
            (split_at_surface, (geo, mats, INT, INT, types.boolean, INT32S, INT, INT32S, VEC3,
                                VEC3, REAL, REAL))]
