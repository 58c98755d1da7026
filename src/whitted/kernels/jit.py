"""The one decorator every kernel uses, so the compilation options live in one place.

``cache=True`` keeps compiled machine code on disk (``NUMBA_CACHE_DIR``, see the README);
``error_model="numpy"`` lets 1/0 give inf instead of raising; ``nogil=True`` lets the editor's
UI thread run while a render is in flight.
"""

from __future__ import annotations

from numba import njit


def kernel(fn=None, **options):
    opts = {"cache": True, "error_model": "numpy", "nogil": True}
    opts.update(options)
    if fn is None:
        return lambda f: njit(**opts)(f)
    return njit(**opts)(fn)
