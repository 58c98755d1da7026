"""A shadow ray's list of surface crossings: (t, primitive) pairs in a flat float array,
kept sorted by t and at most :data:`MAX_SHADOW_HITS` long (the nearest ones)."""

from __future__ import annotations

from ..jit import kernel

MAX_SHADOW_HITS = 32  # transparent surfaces one shadow ray gathers in one walk (hits buffer)


@kernel
def keep_nearest(hits, n, t, prim, full):
    """Insert (t, prim) into the first n pairs of ``hits``, kept sorted by t and at most
    MAX_SHADOW_HITS long (the farthest pair drops out). Returns (n, full): full once a pair
    was dropped or refused."""
    if n == MAX_SHADOW_HITS:
        if t >= hits[2 * (n - 1)]:
            return n, True
        n -= 1
        full = True
    k = n
    while k > 0 and hits[2 * (k - 1)] > t:
        hits[2 * k] = hits[2 * (k - 1)]
        hits[2 * k + 1] = hits[2 * (k - 1) + 1]
        k -= 1
    hits[2 * k] = t
    hits[2 * k + 1] = prim
    return n + 1, full
