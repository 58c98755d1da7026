"""The machinery that compiles and caches whitted's Numba kernels: the bottom layer every
package with kernels compiles through (``kernels/``, ``compile/``, ``assets/obj_scan.py``,
``stefan/``).

- ``decorators.py``: ``@kernel``, ``@builder``, deferred ``@overload`` (and :func:`body`),
  :func:`numba_object`, and :func:`load_numba` (Numba imported, and the cache checked, on
  first need);
- ``dispatcher.py``: Numba's side of a kernel (stock ``numba.njit`` or the tuned dispatcher,
  the one module that uses names Numba does not document);
- ``cache.py``: the per-user kernel cache folder, its checksums, lock and fallbacks;
- ``collector.py``: Python's cyclic garbage collector paused while Numba compiles;
- ``lean_numba.py``: Numba imported without its SciPy, PyYAML and coverage.py probes.

Importing this package imports no Numba.
"""

from __future__ import annotations

from .decorators import (
    FAST_MATH,
    Kernel,
    _jit_disabled,
    body,
    builder,
    kernel,
    load_numba,
    numba_object,
    overload,
    seal_cache,
)

__all__ = ["FAST_MATH", "Kernel", "_jit_disabled", "body", "builder", "kernel", "load_numba",
           "numba_object", "overload", "seal_cache"]
