"""The stack of media a ray is inside (material rows, innermost last).

Entering a closed body pushes its material; leaving it removes that material wherever it sits
(bodies may overlap or be left in any order). The current medium is the top of the stack, or
air (n = 1, no absorption) when it is empty.
"""

from __future__ import annotations

import math

from ..jit import kernel
from .extras import body_medium
from .layout import MAT_IOR, MAT_OUTSIDE, MAX_MEDIA, PRIM_SOLID


@kernel(inline="always")
def absorbed(weight, attenuation, length):
    """``weight`` after ``length`` in a medium of this attenuation (Beer-Lambert); a clear
    medium (attenuation 0, glass by default) costs no exponential."""
    if attenuation > 0.0:
        return weight * math.exp(-attenuation * length)
    return weight


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


@kernel(numba_inline=True)  # inlined by Numba at each call site (jit.py): a hot path
def crossing_media(geo, mats, prim, m, entering, media, n_media, scratch):
    """A ray crossing the surface of primitive ``prim`` (material ``m``), inside the media
    ``media[:n_media]`` (material rows, innermost last): the refractive indices on both
    sides and the media on the far side (into ``scratch``): entering a solid pushes its
    body's medium, leaving pops it; a surface between two named media (a water cavity in
    ice) leaves the outside medium on the way in and enters it on the way out; a thin sheet
    changes nothing. Returns (n1, n2, media count on the far side). Camera paths
    (integrator.py) and photons (photons.py) alike."""
    n_out = n_media
    for k in range(n_media):
        scratch[k] = media[k]
    if not geo.prim_info[prim, PRIM_SOLID]:  # a thin sheet: light passes straight through
        return 1.0, 1.0, n_out
    n1 = mats[media[n_media - 1], MAT_IOR] if n_media > 0 else 1.0
    outside = int(mats[m, MAT_OUTSIDE])
    body = body_medium(geo, prim, m)  # a CSG object is one body (extras.py)
    if entering:
        if outside >= 0:
            n_out = media_leave(scratch, n_out, outside)
            n1 = mats[outside, MAT_IOR]
        n_out = media_enter(scratch, n_out, body)
        n2 = mats[body, MAT_IOR]
    else:
        n_out = media_leave(scratch, n_out, body)
        n1 = mats[body, MAT_IOR]
        if n_out < n_media and media[n_media - 1] != body:
            # leaving a body that is not the innermost (overlapping bodies: a water ball
            # reaching a hair into the ice around it): the ray travels in the innermost one,
            # on both sides
            n1 = mats[media[n_media - 1], MAT_IOR]
        if outside >= 0:
            n_out = media_enter(scratch, n_out, outside)
            n2 = mats[outside, MAT_IOR]
        else:
            n2 = mats[scratch[n_out - 1], MAT_IOR] if n_out > 0 else 1.0
    return n1, n2, n_out
