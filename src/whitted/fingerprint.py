"""Which renderer made a picture: whitted's version and a hash of its kernel sources.

Two processes with the same fingerprint render the same pixels from the same scene (the
kernels are the code that decides them; the version names the rest). The render farm checks
every worker's fingerprint against the client's when the worker joins, and a film's frame
records the fingerprint of the process that rendered it, so a frame made by another renderer
is never taken for a finished one.
"""

from __future__ import annotations

import functools

#: the PNG text key of a frame's record that holds the renderer's fingerprint
FINGERPRINT_KEY = "whitted:renderer"


@functools.cache
def renderer_fingerprint() -> str:
    """``whitted <version> kernels <16 hex digits>`` of this process (computed once)."""
    import whitted

    from .jit.cache import kernel_source_hash

    return f"whitted {whitted.__version__} kernels {kernel_source_hash()}"
