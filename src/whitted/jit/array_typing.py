"""Numba's typing of NumPy array arguments without importing NumPy's masked arrays.

Numba types an array argument by asking first whether it is a masked array
(``isinstance(value, np.ma.MaskedArray)``), and NumPy imports ``numpy.ma`` on that first
look: 8-13 ms of every warm render (AMD EPYC, Python 3.11), for a module no render uses.
No masked array can exist before ``numpy.ma`` is imported, so :func:`install` registers,
through Numba's public ``typeof_impl`` (``numba.extending``), a typing of ``np.ndarray``
that types a plain array as Numba does (``numba.from_dtype``, the layout from the array's
contiguity flags, ``types.Array``) while ``numpy.ma`` is not imported, and hands every other
case (``numpy.ma`` imported, a dtype Numba cannot take) to Numba's own typing, which then
answers (or raises) exactly as before.
"""

from __future__ import annotations

import sys

_installed = False


def install() -> None:
    """Register the typing (once a process; after Numba is imported)."""
    global _installed
    if _installed:
        return
    import numpy as np
    from numba import from_dtype, types
    from numba.extending import typeof_impl

    # Numba's own, for every other case (typeof_impl is a functools.singledispatch function:
    # ``dispatch`` is the standard library's documented look-up of its registered one)
    numbas = typeof_impl.dispatch(np.ndarray)

    def typeof_array(value, context):
        if "numpy.ma" in sys.modules:  # masked arrays may exist: Numba's own typing
            return numbas(value, context)
        try:
            dtype = from_dtype(value.dtype)
        except Exception:  # noqa: BLE001 - a dtype Numba cannot take: its own error
            return numbas(value, context)
        flags = value.flags
        layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
        return types.Array(dtype, value.ndim, layout, readonly=not flags.writeable)

    typeof_impl.register(np.ndarray)(typeof_array)
    _installed = True
