"""The shapes beyond the core ones (tori, CSG objects), reached from the scene-level queries
only in kernels compiled for scenes that have them (features.py ``has_extras``). A CSG object
is walked by csg.py; the shapes are asked through shapes/dispatch.py's ``extra_shape_*``.

Each ``*_if_extras`` function is an overload that resolves, while its caller is typed, to the
real kernel or to a stand-in of the same types, so the kernels of the default scene never
compile the torus's quartic or the CSG walk. The real kernel is its own body, compiled as the
overload's implementation (``jit.body``) in each caller's process: ``extra_hit``'s callers
(the closest hit, the shadow rays' tests) link the CSG walk and the quartic through it with no
level of their own between."""

from __future__ import annotations

import numpy as np

from ..jit import body, kernel, overload
from .csg import csg_hit
from .features import extras_possible
from .layout import PRIM_FLIP, PRIM_MEDIUM, PRIM_TYPE, PRIM_XFORM
from .shapes import INF
from .shapes.dispatch import extra_shape_normal, extra_shape_t, extra_shape_uv, is_csg_object
from .xform import to_object


@kernel
def extra_hit(geo, i, o, d, inv, tmin, tmax):
    """(t, the primitive whose surface it is) of the nearest visible crossing in
    (tmin, tmax) of extra shape ``i``, or (INF, -1) for a CSG object the ray misses: a
    torus (the world ray mapped into its row's space here) or a CSG object (the leaf whose
    surface shows; a CSG root row has no transform of its own, and ``inv`` is the ray's
    inverse direction). The one call site of the CSG walk and the torus's quartic for both
    the closest hit and the shadow rays' tests (accel.py ``closest_hit``, ``hit_analytic``)."""
    typ = geo.prim_info[i, PRIM_TYPE]
    if is_csg_object(typ):
        return csg_hit(geo, i, o, d, inv, tmin, tmax)
    xf = geo.prim_info[i, PRIM_XFORM]
    if xf >= 0:
        o, d = to_object(geo.xforms, xf, o, d)
    return extra_shape_t(typ, geo.prim_params, i, o, d, tmin, tmax), np.int64(i)


def extra_hit_if_extras(geo, i, o, d, inv, tmin, tmax):
    return extra_hit(geo, i, o, d, inv, tmin, tmax)


@overload(extra_hit_if_extras)
def _extra_hit_if_extras(geo, i, o, d, inv, tmin, tmax):
    if not extras_possible(geo):
        return lambda geo, i, o, d, inv, tmin, tmax: (INF, np.int64(-1))
    return body(extra_hit)


@kernel
def extra_normal(geo, i, p, n):
    """Outward normal of extra shape ``i`` at ``p`` (its row's space); ``n``: the core
    shapes' answer, kept for the others."""
    return extra_shape_normal(geo.prim_info[i, PRIM_TYPE], geo.prim_params, i, p, n)


def extra_normal_if_extras(geo, i, p, n):
    return extra_normal(geo, i, p, n)


@overload(extra_normal_if_extras)
def _extra_normal_if_extras(geo, i, p, n):
    if not extras_possible(geo):
        return lambda geo, i, p, n: n
    return body(extra_normal)


@kernel
def flipped(geo, i, n):
    """``n`` turned over where primitive ``i`` is the cut of a CSG difference."""
    if geo.prim_info[i, PRIM_FLIP]:
        return (-n[0], -n[1], -n[2])
    return n


def flipped_if_extras(geo, i, n):
    return flipped(geo, i, n)


@overload(flipped_if_extras, inline="always")
def _flipped_if_extras(geo, i, n):
    if not extras_possible(geo):
        return lambda geo, i, n: n
    return lambda geo, i, n: flipped(geo, i, n)


def body_medium(geo, i, m):
    """Material row of the medium behind the surface of primitive ``i`` whose own material
    is ``m``: a CSG leaf's whole body's, else ``m``."""
    r = geo.prim_info[i, PRIM_MEDIUM]
    return m if r < 0 else r


@overload(body_medium, inline="always")
def _body_medium(geo, i, m):
    if not extras_possible(geo):
        return lambda geo, i, m: m

    def impl(geo, i, m):
        r = geo.prim_info[i, PRIM_MEDIUM]
        return m if r < 0 else r

    return impl


@kernel
def extra_uv(geo, i, p):
    return extra_shape_uv(geo.prim_info[i, PRIM_TYPE], geo.prim_params, i, p)


def extra_uv_if_extras(geo, i, p):
    return extra_uv(geo, i, p)


@overload(extra_uv_if_extras)
def _extra_uv_if_extras(geo, i, p):
    if not extras_possible(geo):
        return lambda geo, i, p: (0.0, 0.0)
    return body(extra_uv)
