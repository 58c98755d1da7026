"""Scene features that pick a specialised kernel when it is compiled, not while it runs.

A scene without mesh instances gets its ``inst_box`` array as float32 (and empty), one
with instances as float64. The two are different Numba types, so every kernel is compiled
once per kind of scene, and in the kind without instances :func:`has_instances` is the
constant False: the instance walks, and the mesh branches of shading that depend on a
triangle index, are removed from the machine code. Measured on the analytic benchmark: the
mere presence of that code cost a third of the speed.
"""

from __future__ import annotations

from numba import types
from numba.extending import overload

NO_INSTANCES_DTYPE = "float32"  # dtype of GeometryArrays.inst_box in scenes without


def has_instances(geo):
    """True when the scene has mesh instances (resolved at compile time where possible)."""
    return geo.inst_box.shape[0] > 0


@overload(has_instances, inline="always")
def _has_instances(geo):
    field_type = dict(zip(geo.fields, geo.types, strict=True))["inst_box"]
    if field_type.dtype == types.float32:
        return lambda geo: False
    return lambda geo: geo.inst_box.shape[0] > 0
