"""The one decorator every kernel uses, so the compilation options live in one place.

``cache=True`` keeps compiled machine code on disk (``NUMBA_CACHE_DIR``, see the README);
``error_model="numpy"`` lets 1/0 give inf instead of raising; ``nogil=True`` lets the editor's
UI thread run while a render is in flight; ``_nrt=False`` compiles without the Numba runtime:
arrays are passed without atomic reference counting (measured at about a third of the render
time), so kernels never allocate: callers pass in every array they need.

``fastmath`` takes the flags that let LLVM reorder and fuse arithmetic (``reassoc``,
``contract``, ``arcp``, ``nsz``, ``afn``: +17 % on the analytic benchmark) but not ``nnan``
or ``ninf``: kernels use inf as the "no hit" sentinel. The watertight triangle test opts out
(``@kernel(fastmath=False)``): its edge functions must round exactly alike for both triangles
that share an edge.

Numba leaves LLVM's SLP vectoriser off; whitted turns it on (unless ``NUMBA_SLP_VECTORIZE``
is set in the environment) before its kernels compile: it packs the three lanes of the vector
arithmetic and the slab tests into SIMD instructions. Measured, CPU-time medians on this
2-core VM: seed000 0.75 -> 0.60 s, mesh1m 0.81 -> 0.72 s, ice 4.65 -> 4.50 s, softshadow at
half size 2.65 -> 2.60 s. The setting is Numba's process-wide one, read when a kernel is
optimised; code already in the on-disk cache keeps the setting it was compiled with.
"""

from __future__ import annotations

import os

from numba import config, njit

if "NUMBA_SLP_VECTORIZE" not in os.environ:
    config.SLP_VECTORIZE = 1

FAST_MATH = {"reassoc", "contract", "arcp", "nsz", "afn"}


def kernel(fn=None, **options):
    opts = {"cache": True, "error_model": "numpy", "nogil": True, "_nrt": False,
            "fastmath": FAST_MATH}
    opts.update(options)
    if fn is None:
        return lambda f: njit(**opts)(f)
    return njit(**opts)(fn)
