"""A hint to the CPU from inside the kernels: fetch a row of an array into the cache now,
because it will be read soon (``llvm.prefetch``; x86 ``prefetcht0``).

A prefetch changes no value: it only starts the memory access early, so that work done in the
meantime hides its latency. The mesh paths use it where a hit's triangle is known well before
its shading reads the triangle's corners (kernels/mesh.py).
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_I8P = ir.IntType(8).as_pointer()
_I32 = ir.IntType(32)
_PREFETCH = ir.FunctionType(ir.VoidType(), [_I8P, _I32, _I32, _I32])


@intrinsic
def prefetch_row(typingctx, array, row):
    """Start loading the first element of ``array[row]`` (a 2-D or 3-D array) into every
    level of the data cache. ``row`` must be a valid row: no bounds check is made (a
    prefetch of a bad address does not fault, but reads nothing useful)."""
    if not (isinstance(array, types.Array) and array.ndim >= 2
            and isinstance(row, types.Integer)):
        return None
    sig = types.void(array, row)

    def codegen(context, builder, signature, args):
        aryty, rowty = signature.args
        ary = context.make_array(aryty)(context, builder, args[0])
        zero = context.get_constant(types.intp, 0)
        first = [context.cast(builder, args[1], rowty, types.intp)] + [zero] * (aryty.ndim - 1)
        ptr = cgutils.get_item_pointer2(context, builder, data=ary.data,
                                        shape=cgutils.unpack_tuple(builder, ary.shape),
                                        strides=cgutils.unpack_tuple(builder, ary.strides),
                                        layout=aryty.layout, inds=first, wraparound=False,
                                        boundscheck=False)
        fn = cgutils.get_or_insert_function(builder.module, _PREFETCH, "llvm.prefetch.p0")
        # read (0), keep in every cache level (locality 3), data cache (1)
        builder.call(fn, [builder.bitcast(ptr, _I8P), ir.Constant(_I32, 0),
                          ir.Constant(_I32, 3), ir.Constant(_I32, 1)])
        return context.get_dummy_value()

    return sig, codegen
