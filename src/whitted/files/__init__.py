"""The bottom layer of file handling, shared by every layer that touches the disk: reading
the files users name safely (:mod:`.reading`) and writing files atomically (:mod:`.atomic`).
It imports nothing of whitted but :mod:`whitted.errors`."""

from .atomic import atomic_write, remove_stale_temporaries
from .reading import (
    head_bytes,
    kind_of,
    map_limited,
    open_regular,
    path_problem,
    read_limited,
    same_file,
)

__all__ = [
    "atomic_write", "head_bytes", "kind_of", "map_limited", "open_regular", "path_problem",
    "read_limited", "remove_stale_temporaries", "same_file",
]
