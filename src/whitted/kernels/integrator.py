"""The Whitted integrator: follow a camera ray through reflections and refractions with an
explicit ray stack (no recursion), tracking the media each ray travels in."""

from __future__ import annotations

import math

from ..jit import kernel
from .accel import closest_hit, hit_material, surface_normals
from .caustics import add_caustic, caustics_on
from .layout import (
    MAT_AMBIENT,
    MAT_ATTEN,
    MAT_COLOR,
    MAT_FRESNEL,
    MAT_KA,
    MAT_KR,
    MAT_KT,
    MAT_TEXTURE,
    MAX_MEDIA,
    RAY_REFLECTION,
    RAY_REFRACTION,
)
from .lighting import direct_light
from .media import absorbed, crossing_media
from .texture import texture_color
from .uv import surface_uv
from .vec import dot, madd

# ray-stack columns: float part
F_ORIGIN = 0
F_DIR = 3
F_WEIGHT = 6
N_STACK_F = 9
# int part: depth, number of media, then the media (material rows), innermost last
I_DEPTH = 0
I_NMEDIA = 1
I_MEDIA = 2
N_STACK_I = 2 + MAX_MEDIA
# dimensions of the random sequence reserved per path vertex for area-light samples
RNG_DIMS_PER_HIT = 1 << 16


@kernel
def background(params, d):
    """Colour of a ray that escapes: the gradient from bottom (d.y = -1) to top (d.y = +1)."""
    t = 0.5 * (d[1] + 1.0)
    top = params.background_top
    bottom = params.background_bottom
    return (
        bottom[0] + t * (top[0] - bottom[0]),
        bottom[1] + t * (top[1] - bottom[1]),
        bottom[2] + t * (top[2] - bottom[2]),
    )


@kernel
def refract(d, n, eta):
    """Snell's law for unit ``d`` arriving at unit ``n`` (n·d < 0), eta = n1/n2.
    Returns (ok, T); ok is False on total internal reflection."""
    cos_i = -dot(d, n)
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    if k < 0.0:
        return False, (0.0, 0.0, 0.0)
    c = eta * cos_i - math.sqrt(k)
    return True, (eta * d[0] + c * n[0], eta * d[1] + c * n[1], eta * d[2] + c * n[2])


@kernel
def fresnel(cos_i, n1, n2, cos_t):
    """The exact Fresnel reflectance for unpolarised light at a surface between two
    dielectrics (indices ``n1`` on the side the ray arrives from, ``n2`` beyond), given the
    cosines of the angles of incidence and refraction (both >= 0; no total internal
    reflection): the mean of the s- and p-polarised reflectances. Equal indices reflect
    nothing; grazing incidence reflects everything."""
    a = n1 * cos_i
    b = n2 * cos_t
    c = n1 * cos_t
    e = n2 * cos_i
    if a + b <= 0.0 or c + e <= 0.0:
        return 1.0
    rs = (a - b) / (a + b)
    rp = (c - e) / (c + e)
    return min(1.0, 0.5 * (rs * rs + rp * rp))


@kernel(inline="always")
def split_at_surface(geo, mats, prim, m, entering, media, n_media, scratch, d, n_shade, kr,
                     kt):
    """How a surface of material ``m`` with kt > 0 splits a ray arriving along ``d``:
    (refracted, transmitted direction, kr, kt as they share the light (total internal
    reflection gives kt to kr; Fresnel moves some of kt to kr), the media count past the
    surface, whose media crossing_media wrote to ``scratch``)."""
    n1, n2, n_out = crossing_media(geo, mats, prim, m, entering, media, n_media, scratch)
    ok, tdir = refract(d, n_shade, n1 / n2)
    if not ok:  # total internal reflection: the reflected ray carries it all
        return False, tdir, kr + kt, 0.0, n_out
    if mats[m, MAT_FRESNEL] != 0.0:
        f = fresnel(-dot(d, n_shade), n1, n2, -dot(tdir, n_shade))
        return True, tdir, kr + kt * f, kt * (1.0 - f), n_out
    return True, tdir, kr, kt, n_out


@kernel(inline="always")
def surface_colour(geo, mats, m, prim, tri, b1, b2, p):
    """(texture factor, diffuse colour) at a hit: the material's colour times its texture's
    value at the point's (u, v); the factor is white when the material has no texture."""
    k = int(mats[m, MAT_TEXTURE])
    if k < 0:
        return (1.0, 1.0, 1.0), (mats[m, MAT_COLOR], mats[m, MAT_COLOR + 1], mats[m, MAT_COLOR + 2])
    u, v = surface_uv(geo, prim, tri, b1, b2, p)
    tex = texture_color(geo.tex_info, geo.tex_pixels, k, u, v)
    return tex, (
        tex[0] * mats[m, MAT_COLOR],
        tex[1] * mats[m, MAT_COLOR + 1],
        tex[2] * mats[m, MAT_COLOR + 2],
    )


@kernel
def _push(st_f, st_i, top, o, d, w, depth, media_src, n_media):
    top += 1
    for k in range(3):
        st_f[top, F_ORIGIN + k] = o[k]
        st_f[top, F_DIR + k] = d[k]
        st_f[top, F_WEIGHT + k] = w[k]
    st_i[top, I_DEPTH] = depth
    st_i[top, I_NMEDIA] = n_media
    for k in range(n_media):
        st_i[top, I_MEDIA + k] = media_src[k]
    return top


@kernel(numba_inline=True)  # Numba inlines it into render_tiles, its one caller (jit.py)
def trace_path(geo, mats, lights, params, o, d, pixel, sample, st_f, st_i, media, scratch,
               stack, hits, listed, counters):
    """Radiance arriving along the camera ray (o, d) with unit d: I = ka·Ia + direct light +
    kr·Ir + kt·It, the secondary terms traced while their weight stays above min_weight."""
    r = 0.0
    g = 0.0
    b = 0.0
    # the ray being followed lives in these locals, not on the stack: a row written to the
    # stack and read back at once (the camera ray, the reflection ray, next in line) made
    # the CPU wait for each of its stores (store forwarding fails on the wider loads)
    w = (1.0, 1.0, 1.0)
    depth = 0
    n_media = 0
    top = -1
    vertex = 0
    while True:
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, 0.0, math.inf, stack)
        if n_media > 0:  # Beer-Lambert absorption in the medium the ray crossed
            cur = media[n_media - 1]
            # a clear medium absorbs nothing, even over the infinite path of a ray that leaves
            # the scene inside it (0 * inf would be NaN)
            w = (
                absorbed(w[0], mats[cur, MAT_ATTEN], t),
                absorbed(w[1], mats[cur, MAT_ATTEN + 1], t),
                absorbed(w[2], mats[cur, MAT_ATTEN + 2], t),
            )
        reflected = False  # the reflection ray, followed next (in o, d, w, depth)
        if prim < 0:
            bg = background(params, d)
            r += w[0] * bg[0]
            g += w[1] * bg[1]
            b += w[2] * bg[2]
        else:
            m = hit_material(geo, prim, tri)
            p = madd(o, d, t)
            n_geo, n_shade = surface_normals(geo, prim, tri, b1, b2, p)
            entering = dot(d, n_geo) < 0.0
            if entering:  # both normals turned to face the ray
                n = n_geo
            else:
                n = (-n_geo[0], -n_geo[1], -n_geo[2])
                n_shade = (-n_shade[0], -n_shade[1], -n_shade[2])
            v = (-d[0], -d[1], -d[2])
            if dot(n_shade, v) <= 0.0:  # interpolated normal turned away from the eye
                n_shade = n
            tex, albedo = surface_colour(geo, mats, m, prim, tri, b1, b2, p)
            ka = mats[m, MAT_KA]
            amb = params.ambient
            # with caustics, shadow rays pass clear bodies (photons add and take away)
            shadow_mats = lights.shadow_materials if caustics_on(lights) else mats
            local = direct_light(geo, shadow_mats, lights, params, p, n_shade, v, m, albedo,
                                 media, n_media, scratch, stack, hits, listed, counters,
                                 (pixel, sample, 2 + vertex * RNG_DIMS_PER_HIT))
            local = add_caustic(lights, mats, m, albedo, p, n, local)  # caustics.py
            vertex += 1
            r += w[0] * (ka * amb[0] * tex[0] * mats[m, MAT_AMBIENT] + local[0])
            g += w[1] * (ka * amb[1] * tex[1] * mats[m, MAT_AMBIENT + 1] + local[1])
            b += w[2] * (ka * amb[2] * tex[2] * mats[m, MAT_AMBIENT + 2] + local[2])
            kr = mats[m, MAT_KR]
            kt = mats[m, MAT_KT]
            if depth < params.max_depth and (kr != 0.0 or kt != 0.0):
                reflect_dir = madd(d, n_shade, -2.0 * dot(d, n_shade))
                kr_eff = kr
                if kt > 0.0:
                    # media on the far side: entering a solid pushes its material, leaving
                    # pops it
                    ok, tdir, kr_eff, kt_eff, n_out = split_at_surface(
                        geo, mats, prim, m, entering, media, n_media, scratch, d, n_shade, kr,
                        kt)
                    if ok:
                        wt = (
                            w[0] * kt_eff * mats[m, MAT_COLOR],
                            w[1] * kt_eff * mats[m, MAT_COLOR + 1],
                            w[2] * kt_eff * mats[m, MAT_COLOR + 2],
                        )
                        if max(wt[0], max(wt[1], wt[2])) >= params.min_weight:
                            counters[RAY_REFRACTION] += 1
                            top = _push(st_f, st_i, top, madd(p, n, -params.epsilon), tdir,
                                        wt, depth + 1, scratch, n_out)
                if kr_eff > 0.0:
                    wr = (w[0] * kr_eff, w[1] * kr_eff, w[2] * kr_eff)
                    if max(wr[0], max(wr[1], wr[2])) >= params.min_weight:
                        counters[RAY_REFLECTION] += 1
                        # in the media of this ray (``media`` is unchanged)
                        o = madd(p, n, params.epsilon)
                        d = reflect_dir
                        w = wr
                        depth += 1
                        reflected = True
        if reflected:
            continue
        if top < 0:
            break
        o = (st_f[top, 0], st_f[top, 1], st_f[top, 2])
        d = (st_f[top, 3], st_f[top, 4], st_f[top, 5])
        w = (st_f[top, 6], st_f[top, 7], st_f[top, 8])
        depth = st_i[top, I_DEPTH]
        n_media = st_i[top, I_NMEDIA]
        for k in range(n_media):
            media[k] = st_i[top, I_MEDIA + k]
        top -= 1
    return r, g, b
