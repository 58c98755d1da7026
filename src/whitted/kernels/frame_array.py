"""Small fixed-size arrays in a kernel's own stack frame.

The kernels run without Numba's runtime (no ``np.empty`` inside them); a walk that needs a
few slots per call (the CSG walk keeps each leaf's next crossing) takes them from its frame:
``frame_floats()`` and ``frame_ints()`` are ``FRAME_SLOTS`` float64 / int64 slots, left
uninitialised, living as long as the calling kernel's frame (LLVM places the allocation in
the function's entry block, so a loop does not grow the stack).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from .jit import _jit_disabled
from .layout import CSG_MAX_LEAVES

FRAME_SLOTS = CSG_MAX_LEAVES + 1


def _frame_array(dtype):
    array_type = types.Array(dtype, 1, "C")

    def codegen(context, builder, sig, args):
        item = context.get_value_type(dtype)
        data = cgutils.alloca_once(builder, item,
                                   size=context.get_constant(types.intp, FRAME_SLOTS))
        array = make_array(array_type)(context, builder)
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(item))
        populate_array(array, data=data,
                       shape=[context.get_constant(types.intp, FRAME_SLOTS)],
                       strides=[itemsize], itemsize=itemsize, meminfo=None)
        return array._getvalue()

    return array_type(), codegen


@intrinsic
def _frame_floats(typingctx):
    return _frame_array(types.float64)


@intrinsic
def _frame_ints(typingctx):
    return _frame_array(types.int64)


def _new_floats():
    return np.empty(FRAME_SLOTS)


def _new_ints():
    return np.empty(FRAME_SLOTS, np.int64)


# ``frame_floats()``: FRAME_SLOTS float64 slots in the caller's frame; ``frame_ints()``:
# int64 ones. Kernels run as plain Python (NUMBA_DISABLE_JIT) get new arrays instead.
frame_floats, frame_ints = ((_new_floats, _new_ints) if _jit_disabled()
                            else (_frame_floats, _frame_ints))
