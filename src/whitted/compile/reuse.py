"""BVHs reused between compiles of scenes that share geometry (the frames of a film).

Inside ``with BvhMemo() as memo:`` every BVH the compiler builds is remembered by a hash of
its inputs (the primitives' bounds and the build options); a later build with the same
inputs gets a copy of the remembered tree instead of building it again. A film whose camera,
lights or materials move keeps every BVH; one whose object moves rebuilds the scene BVH
(cheap: a few primitives per object) but keeps every mesh's own BVH (the expensive ones).
The trees are bit-identical to fresh builds: the builder is deterministic.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from contextvars import ContextVar

import numpy as np

from .bvh import BVH, build_bvh

_active: ContextVar[BvhMemo | None] = ContextVar("whitted_bvh_memo", default=None)


class BvhMemo:
    """Remembers the last ``keep`` BVHs built while it is active (``with memo:``)."""

    def __init__(self, keep: int = 16) -> None:
        self.keep = keep
        self._trees: OrderedDict[bytes, BVH] = OrderedDict()
        # Embree scenes of meshes (compile/embree.py), by a hash of their triangles: the
        # memo holds one reference of each (Embree's own counting), released on eviction
        self._embree: OrderedDict[bytes, tuple[object, list[int]]] = OrderedDict()
        self.built = 0  # BVHs built while active
        self.reused = 0  # BVHs served from the memo
        self.primitives_built = 0
        self.primitives_reused = 0
        self._token = None

    def __enter__(self) -> BvhMemo:
        self._token = _active.set(self)
        return self

    def __exit__(self, *exc: object) -> None:
        _active.reset(self._token)

    def lookup_or_build(self, bounds_min: np.ndarray, bounds_max: np.ndarray,
                        **options: object) -> BVH:
        lo = np.ascontiguousarray(bounds_min, dtype=np.float64)
        hi = np.ascontiguousarray(bounds_max, dtype=np.float64)
        h = hashlib.blake2b(digest_size=16)
        h.update(repr((lo.shape, sorted(options.items()))).encode())
        h.update(lo.tobytes())
        h.update(hi.tobytes())
        key = h.digest()
        n = len(lo)
        tree = self._trees.get(key)
        if tree is not None:
            self._trees.move_to_end(key)
            self.reused += 1
            self.primitives_reused += n
        else:
            tree = build_bvh(lo, hi, **options)
            self._trees[key] = tree
            while len(self._trees) > self.keep:
                self._trees.popitem(last=False)
            self.built += 1
            self.primitives_built += n
        return BVH(*(a.copy() if isinstance(a, np.ndarray) else a for a in tree))


    def embree_row(self, key: bytes, library, build) -> list[int]:
        """The Embree scene handles of a mesh with hash ``key`` (``build()`` makes them when
        not remembered). The caller gets its own reference to each handle."""
        import weakref

        found = self._embree.get(key)
        if found is not None:
            self._embree.move_to_end(key)
            self.reused += 1
            row = found[1]
        else:
            row = build()
            if not self._embree:  # the first one: release what is held when the memo goes
                weakref.finalize(self, _release_held, self._embree)
            self._embree[key] = (library, row)
            self.built += 1
            while len(self._embree) > self.keep:
                _, (old_library, old_row) = self._embree.popitem(last=False)
                for h in {h for h in old_row if h}:
                    old_library.release(h)
        for h in {h for h in row if h}:
            library.retain(h)  # the caller's reference (the memo keeps the one build made)
        return list(row)


def _release_held(held: OrderedDict) -> None:
    while held:
        _, (library, row) = held.popitem()
        for h in {h for h in row if h}:
            library.release(h)


def active_memo() -> BvhMemo | None:
    """The :class:`BvhMemo` of the enclosing ``with``, if any."""
    return _active.get()


def cached_build_bvh(bounds_min: np.ndarray, bounds_max: np.ndarray, **options: object) -> BVH:
    """:func:`~whitted.compile.bvh.build_bvh`, through the active :class:`BvhMemo` if any."""
    memo = _active.get()
    if memo is None:
        return build_bvh(bounds_min, bounds_max, **options)
    return memo.lookup_or_build(bounds_min, bounds_max, **options)
