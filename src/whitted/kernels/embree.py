"""Calls into Embree from inside the kernels: one ray against one mesh's Embree scene.

The compiler (:mod:`..compile.embree`) hands the kernels two plain addresses, those of
``rtcIntersect1`` and ``rtcOccluded1``, and a scene handle per mesh (both in the mesh's
``mesh_info`` row: ``MESH_EMBREE`` in layout.py). The intrinsics below lay out Embree's
``RTCRayHit`` in 128 bytes of the kernel's own stack (16-byte aligned), call through the
address, and read the answer back: no Python, no allocation, nothing held across calls, so
any number of render threads may call at once (Embree's traversal is thread safe).

Addresses are arguments, never constants baked into the code, so the compiled kernels stay
in Numba's on-disk cache like every other (a pointer frozen into machine code would differ in
the next process).

``RTCRayHit`` (Embree 4, ``rtcore_ray.h``), in 32-bit words: the ray's origin 0-2, tnear 3,
direction 4-6, time 7, tfar 8, mask 9, id 10, flags 11; the hit's geometric normal 12-14,
u 15, v 16, primID 17, geomID 18, instID 19. Embree's barycentric (u, v) are whitted's
(b1, b2): hit = (1-u-v)·v0 + u·v1 + v·v2.

Embree's segment [tnear, tfar] is closed and in float32, whitted's (tmin, tmax) open, so the
callers round its ends inward to float32 (:func:`float32_above`, :func:`float32_below`): the
next float32 is found on the bits, in a few instructions, where ``np.nextafter`` was a call
into the C library per end and per Embree call.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_F32 = ir.FloatType()
_F64 = ir.DoubleType()
_I32 = ir.IntType(32)
_I64 = ir.IntType(64)
_BYTES = ir.IntType(8).as_pointer()
_CALL = ir.FunctionType(ir.VoidType(), [_BYTES, _BYTES, _BYTES])
_INVALID = 0xFFFFFFFF  # RTC_INVALID_GEOMETRY_ID


def _ray_block(builder, o, d, tnear, tfar):
    """A stack RTCRayHit holding the ray (o, d) on (tnear, tfar), in float32."""
    block = cgutils.alloca_once(builder, ir.ArrayType(ir.VectorType(_F32, 4), 8))
    words = builder.bitcast(block, _F32.as_pointer())

    def put(k, value):
        builder.store(value, builder.gep(words, [ir.Constant(_I32, k)]))

    def put_int(k, value):
        slot = builder.bitcast(builder.gep(words, [ir.Constant(_I32, k)]), _I32.as_pointer())
        builder.store(ir.Constant(_I32, value), slot)

    for k, v in enumerate(cgutils.unpack_tuple(builder, o, 3)):
        put(k, builder.fptrunc(v, _F32))
    put(3, builder.fptrunc(tnear, _F32))
    for k, v in enumerate(cgutils.unpack_tuple(builder, d, 3)):
        put(4 + k, builder.fptrunc(v, _F32))
    put(7, ir.Constant(_F32, 0.0))
    put(8, builder.fptrunc(tfar, _F32))
    put_int(9, _INVALID)  # mask: every geometry
    put_int(10, 0)
    put_int(11, 0)
    put_int(18, _INVALID)  # geomID: no hit yet
    put_int(19, _INVALID)  # instID[0]
    return block, words


def _call(builder, fn, scene, block):
    callee = builder.inttoptr(fn, _CALL.as_pointer())
    builder.call(callee, [builder.inttoptr(scene, _BYTES), builder.bitcast(block, _BYTES),
                          ir.Constant(_BYTES, None)])


def _load(builder, words, k):
    return builder.load(builder.gep(words, [ir.Constant(_I32, k)]))


def _load_int(builder, words, k):
    slot = builder.bitcast(builder.gep(words, [ir.Constant(_I32, k)]), _I32.as_pointer())
    return builder.load(slot)


def _step(builder, y, up):
    """The float32 next to ``y`` (not NaN, not the infinity it steps toward) toward +inf
    (``up``) or -inf, on the bits: magnitude one unit up or down, +-0 to the smallest
    subnormal of the direction's sign; what ``np.nextafter`` gives."""
    bits = builder.bitcast(y, _I32)
    positive = builder.fcmp_ordered(">", y, ir.Constant(_F32, 0.0))
    one = ir.Constant(_I32, 1)
    away = builder.add(bits, one)  # larger magnitude, same sign
    toward = builder.sub(bits, one)  # smaller magnitude (y != 0)
    if up:
        moved = builder.select(positive, away, toward)
        tiny = ir.Constant(_I32, 1)
    else:
        moved = builder.select(positive, toward, away)
        tiny = ir.Constant(_I32, -0x7FFFFFFF)  # bits 0x80000001: -(smallest subnormal)
    zero = builder.fcmp_ordered("==", y, ir.Constant(_F32, 0.0))
    return builder.bitcast(builder.select(zero, tiny, moved), _F32)


@intrinsic
def float32_above(typingctx, x):
    """The smallest float32 above ``x`` (as a float64): ``x`` rounded to float32, stepped up
    once when the rounding did not land above it (inf stays inf, NaN stays NaN)."""
    sig = types.float64(types.float64)

    def codegen(context, builder, signature, args):
        (x_,) = args
        y = builder.fptrunc(x_, _F32)
        step = builder.and_(builder.fcmp_ordered("<=", builder.fpext(y, _F64), x_),
                            builder.fcmp_ordered("!=", y, ir.Constant(_F32, float("inf"))))
        return builder.fpext(builder.select(step, _step(builder, y, True), y), _F64)

    return sig, codegen


@intrinsic
def float32_below(typingctx, x):
    """The largest float32 below ``x`` (as a float64; +inf stays +inf, NaN stays NaN): as
    :func:`float32_above`, stepped down."""
    sig = types.float64(types.float64)

    def codegen(context, builder, signature, args):
        (x_,) = args
        y = builder.fptrunc(x_, _F32)
        step = builder.and_(builder.fcmp_ordered(">=", builder.fpext(y, _F64), x_),
                            builder.fcmp_ordered("!=", y, ir.Constant(_F32, float("-inf"))))
        step = builder.and_(step, builder.fcmp_ordered("!=", x_, ir.Constant(_F64, float("inf"))))
        return builder.fpext(builder.select(step, _step(builder, y, False), y), _F64)

    return sig, codegen


_VEC3 = types.UniTuple(types.float64, 3)
_HIT = types.Tuple((types.float64, types.int64, types.float64, types.float64))


@intrinsic
def embree_intersect(typingctx, fn, scene, o, d, tnear, tfar):
    """(t, primID, u, v) of the nearest triangle of Embree scene ``scene`` on the ray (o, d)
    within [tnear, tfar], calling ``rtcIntersect1`` at address ``fn``; (inf, -1, 0, 0) on a
    miss. Traced in float32, as Embree does."""
    sig = _HIT(types.int64, types.int64, _VEC3, _VEC3, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        fn_, scene_, o_, d_, tnear_, tfar_ = args
        block, words = _ray_block(builder, o_, d_, tnear_, tfar_)
        _call(builder, fn_, scene_, block)
        hit = builder.icmp_unsigned("!=", _load_int(builder, words, 18),
                                    ir.Constant(_I32, _INVALID))
        t = builder.select(hit, builder.fpext(_load(builder, words, 8), _F64),
                           ir.Constant(_F64, float("inf")))
        prim = builder.select(hit, builder.zext(_load_int(builder, words, 17), _I64),
                              ir.Constant(_I64, -1))
        u = builder.fpext(_load(builder, words, 15), _F64)
        v = builder.fpext(_load(builder, words, 16), _F64)
        return context.make_tuple(builder, signature.return_type, [t, prim, u, v])

    return sig, codegen


@intrinsic
def embree_occluded(typingctx, fn, scene, o, d, tnear, tfar):
    """Does any triangle of Embree scene ``scene`` lie on the ray (o, d) within [tnear,
    tfar]? Calls ``rtcOccluded1`` at address ``fn`` (it sets tfar to -inf when so)."""
    sig = types.boolean(types.int64, types.int64, _VEC3, _VEC3, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        fn_, scene_, o_, d_, tnear_, tfar_ = args
        block, words = _ray_block(builder, o_, d_, tnear_, tfar_)
        _call(builder, fn_, scene_, block)
        return builder.fcmp_ordered("==", _load(builder, words, 8),
                                    ir.Constant(_F32, float("-inf")))

    return sig, codegen
