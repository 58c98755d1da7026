"""Where compiled kernels are kept between runs.

Numba's ``cache=True`` keys each cached function on its own source file only, so a change in
a helper it calls would leave a stale machine-code copy behind. whitted therefore puts its
cache in a folder named after a hash of all kernel sources: any change to any kernel starts a
fresh cache, and different whitted versions never share one.

The folder is ``$WHITTED_CACHE_DIR/numba-<hash>`` (default ``~/.cache/whitted``). An explicit
``NUMBA_CACHE_DIR`` set by the user wins.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

KERNEL_DIRS = ("kernels", "compile", "assets")


def kernel_source_hash() -> str:
    root = Path(__file__).parent
    h = hashlib.sha256()
    for folder in KERNEL_DIRS:
        for path in sorted((root / folder).glob("*.py")):
            h.update(path.name.encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    base = os.environ.get("WHITTED_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "whitted"
    )
    return Path(base) / f"numba-{kernel_source_hash()}"


def configure_kernel_cache() -> str:
    """Point Numba's on-disk cache at whitted's folder (unless the user chose one)."""
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if not chosen:
        chosen = str(cache_dir())
        os.environ["NUMBA_CACHE_DIR"] = chosen
        if "numba" in sys.modules:  # numba already read its settings: tell it directly
            import numba

            numba.config.CACHE_DIR = chosen
    return chosen
