"""``GeometryArrays`` passed by reference between kernels.

Numba passes a tuple of arrays to a function that is not inlined as all of its parts: each
array is seven to eleven machine words (data pointer, shape, strides, ...), so the scene's
``GeometryArrays`` of 28 arrays is some 470 words, copied from the caller's frame into the
callee's at every call. A profile of the mesh benchmark showed those copies as the hottest
instructions of ``closest_hit``, ``any_occluder`` and the instance walks.

``geometry_ref(geo)`` stores the tuple once in the calling kernel's stack frame and gives a
:class:`GeometryRef`, one pointer, that every kernel takes in place of the tuple: reading a
field (``geo.prim_info``) loads just that field through the pointer. The kernels are written
once for either (attribute access is the same); ``render_tiles`` makes the reference at its
start in scenes with mesh instances (:func:`geometry_ref_if_instances`), so every call below
it passes one word. The pointer lives as long as that kernel's
frame, which outlives every call it makes. Only the tuned kernels (jit/dispatcher.py),
which run without Numba's runtime, make references; with stock Numba the tuple is passed.
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.core.typing.templates import AttributeTemplate
from numba.extending import (
    infer_getattr,
    intrinsic,
    lower_builtin,
    lower_getattr_generic,
    models,
    overload,
    register_model,
    type_callable,
)


class GeometryRef(types.Type):
    """A pointer to a ``GeometryArrays`` tuple (``geometry``: the tuple's Numba type)."""

    def __init__(self, geometry: types.BaseNamedTuple) -> None:
        self.geometry = geometry
        super().__init__(name=f"GeometryRef({geometry})")


@register_model(GeometryRef)
class _GeometryRefModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        pointee = dmm.lookup(fe_type.geometry).get_value_type()
        super().__init__(dmm, fe_type, pointee.as_pointer())


@infer_getattr
class _GeometryRefAttributes(AttributeTemplate):
    key = GeometryRef

    def generic_resolve(self, ref, attr):
        fields = ref.geometry.fields
        if attr in fields:
            return ref.geometry.types[fields.index(attr)]
        return None


@lower_getattr_generic(GeometryRef)
def _geometry_ref_field(context, builder, ref, value, attr):
    index = ref.geometry.fields.index(attr)
    field = builder.load(cgutils.gep_inbounds(builder, value, 0, index))
    # the tuple never changes once stored: loads of it may be merged and hoisted freely
    field.set_metadata("invariant.load", builder.module.add_metadata([]))
    return field  # borrowed: made only by kernels without Numba's runtime (no counts)


@intrinsic
def geometry_ref(typingctx, geo):
    """A :class:`GeometryRef` to ``geo`` (stored in this kernel's frame), or ``geo`` itself
    when it is one already."""
    if isinstance(geo, GeometryRef):
        return geo(geo), lambda context, builder, sig, args: args[0]
    if not isinstance(geo, types.BaseNamedTuple):
        return None

    def codegen(context, builder, sig, args):
        slot = cgutils.alloca_once(builder, context.get_value_type(geo))
        builder.store(args[0], slot)
        return slot

    return GeometryRef(geo)(geo), codegen


def geometry_type(geo_type):
    """The ``GeometryArrays`` Numba type behind ``geo_type`` (a reference or the tuple)."""
    return geo_type.geometry if isinstance(geo_type, GeometryRef) else geo_type


def geometry_ref_if_instances(geo):
    """:func:`geometry_ref` in kernels for scenes with mesh instances (or tori and CSG
    objects); ``geo`` itself in the kind without (see below)."""
    return geo


def _kept_as_is(geo) -> bool:
    """Whether :func:`geometry_ref_if_instances` gives ``geo`` (a Numba type) itself in tuned
    kernels."""
    # Measured, CPU time, 1 thread, interleaved (AMD EPYC Zen 4): sphere1m at 640x360 0.242 ->
    # 0.094 s with the reference; but seed000, a scene without instances, 0.69 -> 0.79 s: there
    # LLVM inlines the walks into render_tiles and nothing was copied
    from .features import extras_possible, instances_possible

    # scenes with tori or CSG too: their walks are calls, not inlined (csg.py)
    return isinstance(geo, GeometryRef) or not (instances_possible(geo) or extras_possible(geo))


def _register() -> None:
    """Numba's typing and lowering of :func:`geometry_ref_if_instances`. Tuned kernels run
    without Numba's runtime, so a field read through the pointer is a plain borrowed value,
    and so is the tuple itself: the call is typed and lowered directly (Numba's low-level
    extension API). An ``overload``'s implementation is a function Numba compiles for its
    type even where it inlines it, and the identity's, taking the whole tuple of arrays, was
    a 0.2-s compile on the way to every first render. Stock Numba (reference counts) passes
    the tuple itself, through an inlined overload."""
    from ..jit.dispatcher import tuned

    if not tuned():
        @overload(geometry_ref_if_instances, inline="always")
        def _the_tuple_itself(geo):
            return lambda geo: geo

        return

    @type_callable(geometry_ref_if_instances)
    def _type_geometry_ref_if_instances(context):
        def typer(geo):
            if _kept_as_is(geo):
                return geo
            if isinstance(geo, types.BaseNamedTuple):
                return GeometryRef(geo)
            return None

        return typer

    @lower_builtin(geometry_ref_if_instances, types.Any)
    def _lower_geometry_ref_if_instances(context, builder, sig, args):
        if context.enable_nrt:  # not a tuned kernel: its references would be counted
            raise NotImplementedError("geometry_ref_if_instances in a kernel with Numba's "
                                      "runtime")
        if sig.return_type == sig.args[0]:  # the tuple (or the reference) itself
            return args[0]
        slot = cgutils.alloca_once(builder, context.get_value_type(sig.args[0]))
        builder.store(args[0], slot)
        return slot


_register()
