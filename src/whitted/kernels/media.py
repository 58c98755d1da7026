"""The stack of media a ray is inside (material rows, innermost last).

Entering a closed body pushes its material; leaving it removes that material wherever it sits
(bodies may overlap or be left in any order). The current medium is the top of the stack, or
air (n = 1, no absorption) when it is empty.
"""

from __future__ import annotations

from .jit import kernel
from .layout import MAX_MEDIA


@kernel
def media_enter(media, count, material):
    """Push ``material``; returns the new count (a stack already full stays as it is)."""
    if count < MAX_MEDIA:
        media[count] = material
        return count + 1
    return count


@kernel
def media_leave(media, count, material):
    """Remove the innermost occurrence of ``material``; returns the new count."""
    for k in range(count - 1, -1, -1):
        if media[k] == material:
            for q in range(k, count - 1):
                media[q] = media[q + 1]
            return count - 1
    return count
