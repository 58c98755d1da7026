"""The one decorator every kernel uses, so the compilation options live in one place.

``cache=True`` keeps compiled machine code on disk (``NUMBA_CACHE_DIR``, see the README);
``error_model="numpy"`` lets 1/0 give inf instead of raising; ``nogil=True`` lets the editor's
UI thread run while a render is in flight; ``_nrt=False`` compiles without the Numba runtime:
arrays are passed without atomic reference counting (measured at about a third of the render
time), so kernels never allocate: callers pass in every array they need.
"""

from __future__ import annotations

from numba import njit


def kernel(fn=None, **options):
    opts = {"cache": True, "error_model": "numpy", "nogil": True, "_nrt": False}
    opts.update(options)
    if fn is None:
        return lambda f: njit(**opts)(f)
    return njit(**opts)(fn)
