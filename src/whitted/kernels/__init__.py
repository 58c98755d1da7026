"""Numba kernels: the only layer that traces rays. Everything here is ``@njit(cache=True)`` and
works on the flat arrays built by :mod:`whitted.compile`; no Python objects come in."""
