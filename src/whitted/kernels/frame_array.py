"""Small fixed-size arrays in a kernel's own stack frame.

The kernels run without Numba's runtime (no ``np.empty`` inside them); a walk that needs a
few slots per call (the CSG walk keeps each leaf's next crossing) takes them from its frame:

    next_t = slots(float_slots(), FRAME_SLOTS)

``float_slots()`` and ``int_slots()`` are intrinsics (``numba.extending.intrinsic``) that
reserve ``FRAME_SLOTS`` float64 / int64 slots in the calling kernel's frame, left
uninitialised (``cgutils.alloca_once``: LLVM places the allocation in the function's entry
block, so a loop does not grow the stack), and give their address; ``slots`` views the
address as an array: Numba's public ``numba.carray`` with stock Numba, and the tuned
dispatcher's ``frame_view`` for kernels compiled without Numba's runtime (whose returned
arrays ``numba.carray`` cannot make; jit/dispatcher.py lists the names it relies on).
Both must be called in the kernel that uses the array: the slots live as long as its frame.
Kernels run as plain Python (NUMBA_DISABLE_JIT) get new NumPy arrays instead.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from ..jit.decorators import _jit_disabled
from ..jit.dispatcher import frame_view, tuned
from .layout import CSG_MAX_LEAVES

FRAME_SLOTS = CSG_MAX_LEAVES + 1


def _reserve(dtype):
    def codegen(context, builder, sig, args):
        return cgutils.alloca_once(builder, context.get_value_type(dtype),
                                   size=context.get_constant(types.intp, FRAME_SLOTS))

    return types.CPointer(dtype)(), codegen


@intrinsic
def _float_slots(typingctx):
    return _reserve(types.float64)


@intrinsic
def _int_slots(typingctx):
    return _reserve(types.int64)


def _new_floats():
    return np.empty(FRAME_SLOTS)


def _new_ints():
    return np.empty(FRAME_SLOTS, np.int64)


def _as_is(array, count):
    return array


if _jit_disabled():
    float_slots, int_slots, slots = _new_floats, _new_ints, _as_is
else:
    float_slots, int_slots = _float_slots, _int_slots
    slots = frame_view() if tuned() else numba.carray
