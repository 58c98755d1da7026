"""Scene features that pick a specialised kernel when it is compiled, not while it runs.

A scene without mesh instances gets its ``inst_box`` array as float32 (and empty), one
with instances as float64. The two are different Numba types, so every kernel is compiled
once per kind of scene, and in the kind without instances :func:`has_instances` is the
constant False: the instance walks, and the mesh branches of shading that depend on a
triangle index, are removed from the machine code. Measured on the analytic benchmark: the
mere presence of that code cost a third of the speed.

Numba types (and so compiles) the code behind a branch even when the branch is constant
False, so the kinds without instances call the instance walks and the mesh lookups through
the ``*_if_instances`` functions (in accel.py, lighting.py and uv.py): overloads that resolve,
while the caller is typed, to the real kernel or to a stand-in returning the same types. The
default scene's cold compile then never compiles the mesh kernels (2 s of it).

The same way, ``unbounded`` as int64 (int32 otherwise) makes :func:`has_extras` the
constant True, and int32 the constant False: the torus's quartic and the CSG walk
(kernels/extras.py) stay out of the default scene's kernels and cold compile.

There are two kinds, not four: compile/scene.py gives a scene with mesh instances, with tori
or CSG objects, or with both the *general* kernels (float64 ``inst_box``, int64
``unbounded``: the instance walks behind a run-time test of the instance count, the extra
shapes behind their primitive types), and a scene with neither the *plain* ones. Measured
side by side (docs/performance.md, the variant table): the kernels specialised for instances
only or for extras only were within 3 % of the general ones on the scenes they served, and
each cost a full compile of the render kernels; the plain ones are 4-12 % faster than the
others on the scenes without either, so they stay.
"""

from __future__ import annotations

from ..jit import overload

NO_INSTANCES_DTYPE = "float32"  # dtype of GeometryArrays.inst_box in scenes without
# dtype of GeometryArrays.unbounded in scenes with the shapes from layout.FIRST_EXTRA_SHAPE
# on (tori, CSG): the other kinds never compile their code (kernels/extras.py)
EXTRAS_DTYPE = "int64"


def has_instances(geo):
    """True when the scene has mesh instances (resolved at compile time where possible)."""
    return geo.inst_box.shape[0] > 0


def instances_possible(geo_type) -> bool:
    """Whether a GeometryArrays of this Numba type may hold mesh instances (False for the
    kind without, whose ``inst_box`` is float32)."""
    from numba import types

    # a GeometryRef (kernels/geometry_ref.py) names the tuple type it points to as
    # ``geometry``; the tuple type itself has no such attribute
    geo_type = getattr(geo_type, "geometry", geo_type)
    field_type = dict(zip(geo_type.fields, geo_type.types, strict=True))["inst_box"]
    return field_type.dtype != types.float32


@overload(has_instances, inline="always")
def _has_instances(geo):
    if not instances_possible(geo):
        return lambda geo: False
    return lambda geo: geo.inst_box.shape[0] > 0


def has_extras(geo):
    """True when the scene may hold tori or CSG objects (resolved at compile time)."""
    return geo.unbounded.dtype == EXTRAS_DTYPE


def extras_possible(geo_type) -> bool:
    """Whether a GeometryArrays of this Numba type may hold tori or CSG objects (its
    ``unbounded`` is int64)."""
    from numba import types

    geo_type = getattr(geo_type, "geometry", geo_type)  # as instances_possible
    field_type = dict(zip(geo_type.fields, geo_type.types, strict=True))["unbounded"]
    return field_type.dtype == types.int64


@overload(has_extras, inline="always")
def _has_extras(geo):
    if extras_possible(geo):
        return lambda geo: True
    return lambda geo: False
