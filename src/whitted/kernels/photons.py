"""Photon tracing for caustics (docs/caustics.md): photons leave the lights toward the
bodies that reflect or refract (the *targets*), follow reflections and refractions with
Fresnel, Beer-Lambert absorption and nested media exactly as camera rays do
(kernels/integrator.py), and are stored where they land on a diffuse surface after at least
one specular bounce. Rays are traced by the renderer's own ``closest_hit`` and normals.
A photon whose straight path meets a *clear* body (compile/photon_map.py clear_materials:
shadow rays pass those as if they were not there) also stores *shadow photons* of negative
power where that straight path, through the clear bodies, meets diffuse surfaces: the light
the direct term counts there and the bodies take away.

Each photon's path depends only on the seed, the pass and its index: its emission sample is
the index's point of the R2 low-discrepancy sequence, shifted per pass and emitter, and its
choices between reflection and refraction draw counter-based random numbers; the photon
writes its stored records into its own slots of the output. So the photon map is the same
whatever the thread count or the machine.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel, numba_object
from .accel import closest_hit, hit_material, surface_normals
from .integrator import split_at_surface
from .layout import (
    LIGHT_DIRECTION,
    LIGHT_DIRECTIONAL,
    LIGHT_DISK,
    LIGHT_DISK_U,
    LIGHT_DISK_V,
    LIGHT_DIST_SCALE,
    LIGHT_FALLOFF,
    LIGHT_POSITION,
    LIGHT_RADIANCE,
    LIGHT_RADIUS,
    LIGHT_TYPE,
    MAT_ATTEN,
    MAT_COLOR,
    MAT_KD,
    MAT_KR,
    MAT_KT,
)
from .media import absorbed
from .sampling import concentric_disk, random01, random_pair
from .vec import dot, madd, normalize, vload

geometry_ref_if_instances = numba_object(f"{__package__}.geometry_ref",
                                         "geometry_ref_if_instances")

# emitter rows (compile/photon_map.py): one per (light, target) pair
EMIT_LIGHT = 0  # row of the light table
EMIT_CENTRE = 1  # 1:4 the target's bounding sphere: centre
EMIT_RADIUS = 4  # and radius
EMIT_FIRST = 5  # first photon index of this emitter in a pass
EMIT_COUNT = 6  # photons it shoots per pass
EMIT_BACK = 7  # directional lights: how far behind the target its photons start
N_EMIT = 8

# photon settings (a float64 array): the seed, the pass, the path length, the ray offset
SET_SEED = 0
SET_PASS = 1
SET_DEPTH = 2
SET_EPSILON = 3
SET_SLOTS = 4  # records one photon may store
N_SET = 5
SHADOW_SLOTS = 2  # of which shadow photons (diffuse surfaces behind clear bodies) at most
SHADOW_STEPS = 64  # surfaces a shadow walk passes at most



def _r_steps(dims: int) -> tuple[float, ...]:
    """The steps of Roberts' R_d low-discrepancy sequence: 1 / g^k, g the root of
    x^(d+1) = x + 1 (the plastic number for d = 2)."""
    g = 2.0
    for _ in range(64):
        g = (1.0 + g) ** (1.0 / (dims + 1))
    return tuple(g ** -k for k in range(1, dims + 1))


#: a photon's emission is the point of its index in R_2 (the best spread in two
#: dimensions), and its first LD_BOUNCES choices between reflection and refraction further
#: coordinates of a low-discrepancy sequence (steps of R_6 that are not R_2's), so that
#: the choices of many photons come out in proportion; later choices draw counter-based
#: random numbers
LD_BOUNCES = 4
R_A1, R_A2 = _r_steps(2)
_, _, R_B1, R_B2, R_B3, R_B4 = _r_steps(6)
PHOTON_SAMPLE_BASE = 0x10000  # the random streams' "sample" of pass p: base + p
DISK_DIM = 0x40000  # random dimension of a disk light's point (+ emitter); bounces use 1, 2, ...
MIN_POWER = 1e-12  # a photon carrying less than this is dropped


@kernel
def _frame(w):
    """Two unit vectors completing unit ``w`` to an orthonormal frame."""
    if abs(w[0]) < 0.9:
        a = normalize((0.0, w[2], -w[1]))
    else:
        a = normalize((-w[2], 0.0, w[0]))
    b = (w[1] * a[2] - w[2] * a[1], w[2] * a[0] - w[0] * a[2], w[0] * a[1] - w[1] * a[0])
    return a, b


@kernel
def _cone(emitters, e, y):
    """(cosine of the half angle, solid angle, unit axis) of the cone from ``y`` around the
    target of emitter ``e`` (the whole sphere, cosine -1, when ``y`` is inside it)."""
    c = vload(emitters, e, EMIT_CENTRE)
    v = (c[0] - y[0], c[1] - y[1], c[2] - y[2])
    dist = math.sqrt(dot(v, v))
    r = emitters[e, EMIT_RADIUS]
    if dist <= r:
        return -1.0, 4.0 * math.pi, (0.0, 0.0, 1.0)
    s = r / dist
    cos_max = math.sqrt(max(0.0, 1.0 - s * s))
    return cos_max, 2.0 * math.pi * (1.0 - cos_max), (v[0] / dist, v[1] / dist, v[2] / dist)


@kernel
def _density(emitters, light, y, d, directional):
    """Photons per pass per unit of the light's measure (solid angle from ``y``, or area
    across a directional light's beam) in the direction ``d`` from ``y``: the sum over the
    light's emitters whose target the photon is aimed into of count / measure. A photon's
    power is the light's intensity (or radiance) divided by this."""
    total = 0.0
    for e in range(emitters.shape[0]):
        if int(emitters[e, EMIT_LIGHT]) != light or emitters[e, EMIT_COUNT] == 0.0:
            continue
        c = vload(emitters, e, EMIT_CENTRE)
        r = emitters[e, EMIT_RADIUS]
        v = (c[0] - y[0], c[1] - y[1], c[2] - y[2])
        if directional:
            along = dot(v, d)
            perp2 = dot(v, v) - along * along
            if perp2 <= r * r:
                total += emitters[e, EMIT_COUNT] / (math.pi * r * r)
        else:
            cos_max, omega, axis = _cone(emitters, e, y)
            if dot(d, axis) >= cos_max:
                total += emitters[e, EMIT_COUNT] / omega
    return total


@kernel
def emit_photon(table, emitters, e, i, seed, pass_index):
    """Photon ``i`` (an index within emitter ``e``'s photons of this pass): (origin, unit
    direction, power per channel, whether its light is directional, its light's position
    for the path length)."""
    j = int(emitters[e, EMIT_LIGHT])
    kind = table[j, LIGHT_TYPE]
    shift = random_pair(seed, e, PHOTON_SAMPLE_BASE + pass_index, 0)
    u1 = (shift[0] + (i + 1) * R_A1) % 1.0
    u2 = (shift[1] + (i + 1) * R_A2) % 1.0
    radiance = vload(table, j, LIGHT_RADIANCE)
    c = vload(emitters, e, EMIT_CENTRE)
    r = emitters[e, EMIT_RADIUS]
    if kind == LIGHT_DIRECTIONAL:
        d = vload(table, j, LIGHT_DIRECTION)
        a, b = _frame(d)
        dx, dy = concentric_disk(u1, u2)
        x = madd(madd(c, a, dx * r), b, dy * r)
        o = madd(x, d, -emitters[e, EMIT_BACK])
        density = _density(emitters, j, o, d, True)
    else:
        y = vload(table, j, LIGHT_POSITION)
        if kind == LIGHT_DISK:
            v1, v2 = random_pair(seed, i, PHOTON_SAMPLE_BASE + pass_index, DISK_DIM + e)
            px, py = concentric_disk(v1, v2)
            rad = table[j, LIGHT_RADIUS]
            y = madd(madd(y, vload(table, j, LIGHT_DISK_U), px * rad),
                     vload(table, j, LIGHT_DISK_V), py * rad)
        cos_max, _, axis = _cone(emitters, e, y)
        # the disk's point (dx, dy) -> a direction in the cone: uniform in solid angle,
        # with the sequence's even spread kept (equal areas of the disk, equal solid angles)
        dx, dy = concentric_disk(u1, u2)
        rho2 = dx * dx + dy * dy
        cos_t = 1.0 - rho2 * (1.0 - cos_max)
        sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
        if rho2 > 0.0:
            s = sin_t / math.sqrt(rho2)
            dx *= s
            dy *= s
        a, b = _frame(axis)
        d = normalize((cos_t * axis[0] + dx * a[0] + dy * b[0],
                       cos_t * axis[1] + dx * a[1] + dy * b[1],
                       cos_t * axis[2] + dx * a[2] + dy * b[2]))
        o = y
        density = _density(emitters, j, o, d, False)
    if density <= 0.0:
        return o, d, (0.0, 0.0, 0.0), kind == LIGHT_DIRECTIONAL
    return o, d, (radiance[0] / density, radiance[1] / density,
                  radiance[2] / density), kind == LIGHT_DIRECTIONAL


@kernel
def _choice(seed, photon, index, emitter, pass_index, bounce):
    """The number in [0, 1) that decides a photon's ``bounce``: a coordinate of its R_d point
    (``index`` within its emitter) for the first LD_BOUNCES, else a random one."""
    if bounce < LD_BOUNCES:
        step = R_B1 if bounce == 0 else (R_B2 if bounce == 1 else (R_B3 if bounce == 2
                                                                    else R_B4))
        shift = random01(seed, emitter, PHOTON_SAMPLE_BASE + pass_index, 1 + bounce)
        return (shift + (index + 1) * step) % 1.0
    return random01(seed, photon, PHOTON_SAMPLE_BASE + pass_index, 1 + bounce)


@kernel
def falloff_scale(table, j, length):
    """What a point or disk light's photon carrying intensity x solid angle is multiplied
    by when it lands after a path of ``length``: the light's falloff times length^2, so that
    an unobstructed path gives exactly the light's direct term (1 for inverse-square)."""
    mode = table[j, LIGHT_FALLOFF]
    if mode == 2.0:
        return 1.0
    if mode == 1.0:
        return table[j, LIGHT_DIST_SCALE] * length
    return length * length


@kernel
def _store(out, row, p, w, f, d, pass_index):
    out[row, 0] = p[0]
    out[row, 1] = p[1]
    out[row, 2] = p[2]
    out[row, 3] = w[0] * f
    out[row, 4] = w[1] * f
    out[row, 5] = w[2] * f
    out[row, 6] = d[0]
    out[row, 7] = d[1]
    out[row, 8] = d[2]
    out[row, 9] = pass_index


@kernel
def photon_bounce(geo, mats, clear, table, j, directional, settings, photon, index, emitter,
                  out, slot0, slots, stored, media, n_media, scratch, bounce, hit, o, d, w,
                  length, specular):
    """One bounce of a photon's path (:func:`trace_photons`): the photon left ``o`` along
    ``d`` with power ``w`` and met ``hit`` (closest_hit's answer, a primitive hit). Stores a
    record (layout.PHOTON_* columns) if it reaches a diffuse surface after a specular bounce,
    at most ``slots`` into ``out[slot0:]`` (``stored`` so far), and chooses between reflection
    and refraction. Returns (whether the path goes on, o, d, w, length, stored, specular,
    n_media). A refraction counts as specular at a clear material (``clear[m]``): elsewhere
    shadow rays pass it and carry that light already."""
    seed = int(settings[SET_SEED])
    pass_index = int(settings[SET_PASS])
    eps = settings[SET_EPSILON]
    t, prim, tri, b1, b2 = hit
    if n_media > 0:  # Beer-Lambert absorption in the medium it crossed
        cur = media[n_media - 1]
        w = (absorbed(w[0], mats[cur, MAT_ATTEN], t),
             absorbed(w[1], mats[cur, MAT_ATTEN + 1], t),
             absorbed(w[2], mats[cur, MAT_ATTEN + 2], t))
    length += t
    m = hit_material(geo, prim, tri)
    p = madd(o, d, t)
    n_geo, n_shade = surface_normals(geo, prim, tri, b1, b2, p)
    entering = dot(d, n_geo) < 0.0
    if entering:
        n = n_geo
    else:
        n = (-n_geo[0], -n_geo[1], -n_geo[2])
        n_shade = (-n_shade[0], -n_shade[1], -n_shade[2])
    if dot(n_shade, d) >= 0.0:
        n_shade = n
    if specular and mats[m, MAT_KD] > 0.0 and stored < slots:
        f = 1.0 if directional else falloff_scale(table, j, length)
        _store(out, slot0 + stored, p, w, f, d, pass_index)
        stored += 1
    kr = mats[m, MAT_KR]
    kt = mats[m, MAT_KT]
    if kr == 0.0 and kt == 0.0:
        return False, o, d, w, length, stored, specular, n_media
    kr_eff = kr
    bt = (0.0, 0.0, 0.0)
    tdir = d
    n_out = n_media
    if kt > 0.0:
        ok, tdir, kr_eff, kt_eff, n_out = split_at_surface(
            geo, mats, prim, m, entering, media, n_media, scratch, d, n_shade, kr, kt)
        if ok:
            bt = (kt_eff * mats[m, MAT_COLOR], kt_eff * mats[m, MAT_COLOR + 1],
                  kt_eff * mats[m, MAT_COLOR + 2])
    b_mean = (bt[0] + bt[1] + bt[2]) / 3.0
    total = kr_eff + b_mean
    if total <= 0.0:
        return False, o, d, w, length, stored, specular, n_media
    u = _choice(seed, photon, index, emitter, pass_index, bounce)
    if u * total < b_mean:  # refracted, with probability b_mean / total
        s = total / b_mean
        w = (w[0] * bt[0] * s, w[1] * bt[1] * s, w[2] * bt[2] * s)
        o = madd(p, n, -eps)
        d = tdir
        n_media = n_out
        for k in range(n_out):
            media[k] = scratch[k]
        specular = specular or clear[m] != 0
    else:  # reflected
        w = (w[0] * total, w[1] * total, w[2] * total)
        o = madd(p, n, eps)
        d = madd(d, n_shade, -2.0 * dot(d, n_shade))
        specular = True
    go_on = not max(w[0], max(w[1], w[2])) < MIN_POWER  # a NaN power goes on
    return go_on, o, d, w, length, stored, specular, n_media


@kernel
def shadow_step(geo, mats, clear, table, j, directional, settings, out, slot0, slots, stored,
                hit, o, d, w, length, crossed):
    """One step of a photon's shadow walk (:func:`trace_photons`): its straight path, passing
    clear bodies as shadow rays do (as if they were not there), from ``o`` along ``d`` met
    ``hit`` (closest_hit's answer, a primitive hit). Where it meets a diffuse surface after
    crossing a clear body, a record of minus the power the direct term counts there
    (``w``, negative; layout.PHOTON_* columns, at most ``slots`` into ``out[slot0:]``).
    Other transparent surfaces (unbounded planes) dim it by kt·colour as they dim shadow
    rays; an opaque surface ends it. Returns (whether the walk goes on, o, w, length,
    stored, crossed)."""
    pass_index = int(settings[SET_PASS])
    eps = settings[SET_EPSILON]
    t, prim, tri, _, _ = hit
    length += t
    m = hit_material(geo, prim, tri)
    p = madd(o, d, t)
    if crossed and mats[m, MAT_KD] > 0.0:
        f = 1.0 if directional else falloff_scale(table, j, length)
        _store(out, slot0 + stored, p, w, f, d, pass_index)
        stored += 1
        if stored >= slots:
            return False, o, w, length, stored, crossed
    if clear[m] != 0:
        crossed = True
    elif mats[m, MAT_KT] > 0.0:
        kt = mats[m, MAT_KT]
        w = (w[0] * kt * mats[m, MAT_COLOR], w[1] * kt * mats[m, MAT_COLOR + 1],
             w[2] * kt * mats[m, MAT_COLOR + 2])
    else:
        return False, o, w, length, stored, crossed
    o = madd(p, d, eps)
    length += eps
    return True, o, w, length, stored, crossed


@kernel(entry=True)  # called from Python, one call per lane
def trace_photons(geo, mats, clear, table, emitters, settings, first, last, out, counts,
                  stack, media, scratch):
    """Photons ``first`` .. ``last - 1`` of a pass (``settings``: SET_* values): photon
    ``i`` writes its records into rows ``(i - first) * slots ...`` of ``out`` (the calls'
    own rows, ``(last - first) * slots`` of them) and their number into ``counts[i]``: its
    shadow photons first (at most SHADOW_SLOTS, :func:`shadow_step`), then the records of its
    own path (:func:`photon_bounce`).

    The two walks of a photon are one loop around one call of ``closest_hit``: every
    function compiled above the intersection code optimises all of it again, and each call
    site of the inlined ``closest_hit`` is a copy of it (the general geometry's torus and
    CSG walk among it): one call site and no level between this kernel and the steps halve
    what the compile of the general tracer optimises (docs/performance.md, the
    general-tracer round)."""
    geo = geometry_ref_if_instances(geo)
    slots = int(settings[SET_SLOTS])
    seed = int(settings[SET_SEED])
    pass_index = int(settings[SET_PASS])
    bounces = int(settings[SET_DEPTH]) + 1
    e = 0
    for i in range(first, last):
        while (e < emitters.shape[0] - 1
               and i >= emitters[e, EMIT_FIRST] + emitters[e, EMIT_COUNT]):
            e += 1
        while e > 0 and i < emitters[e, EMIT_FIRST]:
            e -= 1
        index = i - int(emitters[e, EMIT_FIRST])
        o, d, power, directional = emit_photon(table, emitters, e, index, seed, pass_index)
        counts[i] = 0
        if max(power[0], max(power[1], power[2])) <= 0.0:
            continue
        j = int(emitters[e, EMIT_LIGHT])
        row = (i - first) * slots
        # the shadow walk first, then the photon's own path from the same start
        shadow = True
        ro = o
        rd = d
        w = (-power[0], -power[1], -power[2])
        slot0 = row
        room = SHADOW_SLOTS
        stored = 0
        # (typed bool, not the literal False: a step compiled for that type too otherwise)
        flag = np.bool_(False)  # the shadow walk: a clear body crossed; the path: specular
        length = 0.0
        n_media = 0
        step = 0
        n_shadow = 0
        while True:
            go_on = step < (SHADOW_STEPS if shadow else bounces)
            if go_on:
                hit = closest_hit(geo, ro, rd, 0.0, math.inf, stack)
                go_on = hit[1] >= 0
            if go_on:
                if shadow:
                    go_on, ro, w, length, stored, flag = shadow_step(
                        geo, mats, clear, table, j, directional, settings, out, slot0, room,
                        stored, hit, ro, rd, w, length, flag)
                else:
                    go_on, ro, rd, w, length, stored, flag, n_media = photon_bounce(
                        geo, mats, clear, table, j, directional, settings, i, index, e, out,
                        slot0, room, stored, media, n_media, scratch, step, hit, ro, rd, w,
                        length, flag)
                step += 1
            if go_on:
                continue
            if not shadow:
                break
            shadow = False  # the photon's own path
            n_shadow = stored
            ro = o
            rd = d
            w = power
            slot0 = row + n_shadow
            room = slots - n_shadow
            stored = 0
            flag = np.bool_(False)
            length = 0.0
            n_media = 0
            step = 0
        counts[i] = n_shadow + stored
