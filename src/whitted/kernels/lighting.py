"""Direct illumination: ambient, Lambert diffuse and Phong/Blinn specular from every light,
with shadow rays that pass through transparent bodies (tinted, absorbed) and stop at opaque ones.
"""

from __future__ import annotations

import math

from ..jit import body, kernel, overload
from .accel import (
    closest_hit,
    geometric_normal,
    hit_analytic,
    hit_material,
    instance_occludes,
    occludes,
)
from .csg import csg_surfaces
from .extras import body_medium, extra_hit
from .features import extras_possible, has_extras, has_instances, instances_possible
from .hit_list import MAX_SHADOW_HITS, keep_nearest
from .layout import (
    CELL_COUNT,
    CELL_FIRST,
    CELL_OPAQUE,
    LIGHT_BUFFER,
    LIGHT_BUFFER_SIDE,
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
    LIGHT_SAMPLES,
    LIGHT_TYPE,
    MAT_ATTEN,
    MAT_BLINN,
    MAT_COLOR,
    MAT_KD,
    MAT_KS,
    MAT_KT,
    MAT_SHININESS,
    MAT_SPECULAR,
    PRIM_MATERIAL,
    PRIM_SOLID,
    PRIM_TYPE,
    PRIM_XFORM,
    RAY_SHADOW,
)
from .light_buffer import cube_cell
from .media import absorbed, media_enter, media_leave
from .mesh import OPAQUE_KT
from .sampling import SAMPLE_CHUNK, stratified_disk, stratum
from .shapes import INF
from .shapes.dispatch import (
    bounding_ball,
    crossed_twice,
    is_csg_object,
    is_extra,
    is_world_plane,
)
from .traverse import (
    box_entry,
    bvh_frame_point,
    bvh_frame_ray,
    cone_meets_box,
    inverse_direction,
    next_scene_candidate,
    start_scene_walk,
)
from .vec import cross, dot, madd, normalize, sub, vload


@kernel
def _instances_occlusion(geo, mats, o, d, inv, tmin, tmax, stack):
    """:func:`any_occluder` over the mesh instances' BVH (``inv``: the inverse direction)."""
    seen_transparent = 0
    box = geo.inst_box
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        if box_entry(box, node, o, inv, tmin, tmax) == INF:
            continue
        count = geo.inst_link[node, 1]
        if count == 0:
            top += 1
            stack[top] = node + 1
            top += 1
            stack[top] = geo.inst_link[node, 0]
            continue
        first = geo.inst_link[node, 0]
        for j in range(first, first + count):
            state = instance_occludes(geo, mats, geo.inst_prims[j], o, d, inv, tmin, tmax,
                                      stack)
            if state == 1:
                return 1
            seen_transparent = max(seen_transparent, state)
    return seen_transparent


def instances_occlusion_if_instances(geo, mats, o, d, inv, tmin, tmax, stack):
    """:func:`_instances_occlusion`, never compiled for scenes without instances."""
    return _instances_occlusion(geo, mats, o, d, inv, tmin, tmax, stack)


@overload(instances_occlusion_if_instances)
def _instances_occlusion_if_instances(geo, mats, o, d, inv, tmin, tmax, stack):
    if not instances_possible(geo):
        return lambda geo, mats, o, d, inv, tmin, tmax, stack: 0
    return body(_instances_occlusion)


@kernel
def listed_occlusion(geo, mats, occluders, first, count, o, d, tmin, tmax, stack):
    """:func:`any_occluder` over a light-buffer cell's list ``occluders[first:][:count]``
    instead of the BVHs (the walk itself when ``count`` is negative: no list): an entry
    ``i`` >= 0 is an analytic primitive, ``-1 - node`` a leaf of the instance BVH (its box
    tested as the walk tests it, then each of its instances). The answer does not depend on
    the order: 1 when any listed surface blocks opaquely, else 2 when any transparent one is
    met. (One call for both, so the shadow code inlined into the lighting stays small.)
    Called only for scenes with instances (:func:`_shadow_through_instances`)."""
    if count < 0:
        return any_occluder(geo, mats, o, d, tmin, tmax, stack)
    seen_transparent = 0
    inv = inverse_direction(d)
    for k in range(first, first + count):
        i = occluders[k]
        if i >= 0:
            state = occludes(geo, mats, i, o, d, tmin, tmax)
        else:
            state = _instance_leaf_occlusion(geo, mats, -1 - i, o, d, inv, tmin, tmax, stack)
        if state == 1:
            return 1
        seen_transparent = max(seen_transparent, state)
    return seen_transparent


@kernel
def _instance_leaf_occlusion(geo, mats, node, o, d, inv, tmin, tmax, stack):
    """:func:`instance_occludes` over the instances of leaf ``node`` of the instance BVH
    when the ray's segment meets its box."""
    if box_entry(geo.inst_box, node, o, inv, tmin, tmax) == INF:
        return 0
    seen_transparent = 0
    first = geo.inst_link[node, 0]
    for j in range(first, first + geo.inst_link[node, 1]):
        state = instance_occludes(geo, mats, geo.inst_prims[j], o, d, inv, tmin, tmax,
                                  stack)
        if state == 1:
            return 1
        seen_transparent = max(seen_transparent, state)
    return seen_transparent


@kernel
def any_occluder(geo, mats, o, d, tmin, tmax, stack):
    """0: nothing on the segment (tmin, tmax) of the ray; 1: an opaque occluder (the search
    stops at the first one); 2: only transparent ones. Analytic shapes first (one call site
    of the intersection routines), then the mesh instances when there are any."""
    seen_transparent = 0
    inv = inverse_direction(d)
    fo, finv = bvh_frame_ray(geo, o, d, inv)  # the ray the boxes see
    j, leaf, leaf_end, top = start_scene_walk(geo, stack, False)
    while True:
        i, j, leaf, leaf_end, top = next_scene_candidate(geo, fo, finv, tmin, tmax, stack, j,
                                                         leaf, leaf_end, top, False)
        if i < 0:
            break
        state = occludes(geo, mats, i, o, d, tmin, tmax)
        if state == 1:
            return 1
        seen_transparent = max(seen_transparent, state)
    if has_instances(geo):
        state = instances_occlusion_if_instances(geo, mats, o, d, inv, tmin, tmax, stack)
        if state == 1:
            return 1
        seen_transparent = max(seen_transparent, state)
    return seen_transparent


SHADOW_LIST_CAP = 48  # primitives a soft-shadow bundle may list; past that its rays walk the BVH
MIN_BUNDLE_SAMPLES = 4  # area lights with fewer samples per point skip the bundle listing
# a light sample whose unshadowed contribution to a highlight-only surface (no diffuse term)
# is below this, per channel, is left out without a shadow ray: far below a float32 pixel's
# own precision at any visible brightness (2**-24 of the value) and 16-bit output's step
NEGLIGIBLE_LIGHT = 1e-15
# an area light's points on its disk, drawn ahead of their shadow rays, wait in the shadow
# rays' hits buffer past its MAX_SHADOW_HITS (t, primitive) pairs: SAMPLE_CHUNK (x, y) pairs
DISK_POINTS = 2 * MAX_SHADOW_HITS
HITS_BUFFER = DISK_POINTS + 2 * SAMPLE_CHUNK  # the length of a lane's hits buffer


@kernel
def _plane_clear_of_bundle(P, i, p, centre, radius, tmin):
    """True when no ray from ``p`` to the ball of ``radius`` around ``centre`` can meet plane
    primitive ``i`` beyond ``tmin``: the ball lies wholly on one side and ``p`` on the same
    side, or so close to the plane that the crossing comes before ``tmin`` (a point on the
    plane itself, shaded on the side facing the light)."""
    nrm = vload(P, i, 3)
    s_p = dot(sub(p, vload(P, i, 0)), nrm)
    s_c = dot(sub(centre, vload(P, i, 0)), nrm)
    if s_c < 0.0:  # look from the light's side
        s_p = -s_p
        s_c = -s_c
    s_min = s_c - radius
    if s_min <= 0.0:
        return False  # the light straddles the plane
    if s_p >= 0.0:
        return True
    reach = math.sqrt(dot(sub(centre, p), sub(centre, p))) + radius
    return -s_p * reach < 0.5 * tmin * (s_min - s_p)


@kernel(inline="always")
def list_bundle_occluders(geo, mats, p, centre, radius, tmin, stack, listed):
    """Every analytic primitive that could block a ray from ``p`` to the ball of ``radius``
    around ``centre`` (an area light seen from a shaded point) beyond ``tmin``: the unbounded
    ones the light does not lie clear of, and those in the scene BVH's leaves whose boxes meet
    the cone of such rays. They go into ``listed``. Returns (their count, whether all are
    opaque); the count is -1 when there are more than SHADOW_LIST_CAP (the bundle's rays then
    walk the BVH one by one). The shadow rays of the bundle test only the listed primitives:
    the same hits as a walk, found without one."""
    n = 0
    opaque = n == 0  # True, typed bool: a literal True compiles list_cone_leaves twice
    for j in range(geo.unbounded.shape[0]):
        i = geo.unbounded[j]
        if (is_world_plane(geo.prim_info[i, PRIM_TYPE], geo.prim_info[i, PRIM_XFORM])
                and _plane_clear_of_bundle(geo.prim_params, i, p, centre, radius, tmin)):
            continue
        if n == SHADOW_LIST_CAP:
            return -1, False
        listed[n] = i
        n += 1
        opaque = opaque and mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT
    n, opaque = list_cone_leaves(geo, mats, p, sub(centre, p), radius * (1.0 + 1e-7) + 1e-12,
                                 stack, listed, n, SHADOW_LIST_CAP, opaque)
    if n <= 0:
        return n, opaque
    return _keep_bundle_occluders(geo, mats, p, centre, radius, listed, n)


# a ball is kept in a bundle's list when it comes within this much more than its radius of
# the bundle (relative to the radius, and to the bundle's length): far more than the
# rounding of the tests that could find it hit (a ray passing farther than this outside a
# sphere has a discriminant below -1e-12 of its squared distances: no rounding makes it a hit)
BALL_SLACK = 1e-6


@kernel
def ball_meets_bundle(c, r, p, axis, length, sin_a, cos_a, reach):
    """Could a segment from ``p`` to a point of the light's ball meet the ball of radius ``r``
    around ``c``? Those segments lie in the cone from apex ``p`` along ``axis`` (unit
    direction times ``length``) of half-angle ``a`` (its sine and cosine) cut at ``reach``
    from the apex: the ball is tested against that solid cone, with BALL_SLACK to spare."""
    v = sub(c, p)
    along = dot(v, axis) / length
    side = cross(v, axis)
    q = math.sqrt(dot(side, side)) / length  # the distance of c from the cone's axis
    r = r * (1.0 + BALL_SLACK) + BALL_SLACK * reach
    if along - r > reach:
        return False  # beyond the light
    off = q * cos_a - along * sin_a  # c's distance from the cone's side (inside: <= 0)
    if off <= r:
        if along * cos_a + q * sin_a >= 0.0:
            return True  # within r of the side, or inside
        return dot(v, v) <= r * r  # behind the apex: the apex is its nearest point
    return False


@kernel
def _keep_bundle_occluders(geo, mats, p, centre, radius, listed, n):
    """Of ``listed[:n]`` (a bundle's list from its BVH leaves) keep, in order, those that a
    ray of the bundle could meet: spheres and triangles whose own bounding ball misses the
    bundle's cone (:func:`ball_meets_bundle`) are left out, every other shape is kept.
    Returns (the count kept, whether all kept are opaque)."""
    axis = sub(centre, p)
    length = math.sqrt(dot(axis, axis))
    grown = radius * (1.0 + BALL_SLACK) + 1e-12
    near = length <= 2.0 * grown  # the point is (nearly) within the light's ball: keep all
    sin_a = grown / length if not near else 0.0
    cos_a = math.sqrt(1.0 - sin_a * sin_a)
    reach = length + grown
    kept = 0
    opaque = True
    P = geo.prim_params
    for k in range(n):
        i = listed[k]
        meets = True
        typ = geo.prim_info[i, PRIM_TYPE]
        if not near and geo.prim_info[i, PRIM_XFORM] < 0:  # its numbers are in world space
            has_ball, c, r = bounding_ball(typ, P, i)
            if has_ball:
                meets = ball_meets_bundle(c, r, p, axis, length, sin_a, cos_a, reach)
        if meets:
            listed[kept] = i
            kept += 1
            opaque = opaque and mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT
    return kept, opaque


@kernel(inline="always")
def list_cone_leaves(geo, mats, apex, axis, radius, stack, out, n, cap, opaque):
    """Append to ``out[n:]`` the primitives of the scene BVH's leaves whose boxes meet the
    cone from ``apex`` to the ball of ``radius`` around ``apex + axis`` (see
    :func:`cone_meets_box`). ``opaque`` says whether those already listed are all opaque.
    Returns (the new count, whether all listed are opaque); the count is -1 when they would
    be more than ``cap``."""
    if geo.node_box.shape[0] == 0:
        return n, opaque
    apex = bvh_frame_point(geo, apex)  # the cone as the boxes see it (rotation keeps radius)
    axis = bvh_frame_point(geo, axis)
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        if not cone_meets_box(geo.node_box, node, apex, axis, radius):
            continue
        count = geo.node_link[node, 1]
        if count == 0:
            top += 1
            stack[top] = node + 1
            top += 1
            stack[top] = geo.node_link[node, 0]
            continue
        if n + count > cap:
            return -1, False
        first = geo.node_link[node, 0]
        for leaf in range(first, first + count):
            i = geo.node_prims[leaf]
            out[n] = i
            n += 1
            opaque = opaque and mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT
    return n, opaque


@kernel
def list_cone_instance_leaves(geo, apex, axis, radius, stack, out, n, cap, opaque):
    """Append to ``out[n:]``, as ``-1 - node``, the leaves of the instance BVH whose boxes
    meet the cone of :func:`list_cone_leaves` (world space: the instance boxes are not in
    the scene BVH's frame). Returns (the new count, whether all listed are opaque: False once
    a leaf is listed, the instances' triangles may have materials of their own); the count
    is -1 when they would be more than ``cap``."""
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        if not cone_meets_box(geo.inst_box, node, apex, axis, radius):
            continue
        if geo.inst_link[node, 1] == 0:
            top += 1
            stack[top] = node + 1
            top += 1
            stack[top] = geo.inst_link[node, 0]
            continue
        if n == cap:
            return -1, False
        out[n] = -1 - node
        n += 1
        opaque = False
    return n, opaque


@kernel
def gather_extra_hits(geo, i, o, d, inv, tmin, tmax, step, hits, n, full):
    """A shadow ray's walk (:func:`direct_light`) at a torus or CSG object ``i``: its crossings in
    (tmin, tmax), a CSG object's as (t, leaf) pairs from one walk (:func:`.csg.csg_surfaces`),
    a torus's each found from past the one before (up to four)."""
    if is_csg_object(geo.prim_info[i, PRIM_TYPE]):
        return csg_surfaces(geo, i, o, d, inv, tmin, tmax, hits, n, full)
    # the torus straight through extras.py's test (hit_analytic would bring every core
    # shape's test in twice)
    t, _ = extra_hit(geo, i, o, d, inv, tmin, tmax)
    for _ in range(4):
        if t == INF:
            break
        n, full = keep_nearest(hits, n, t, i, full)
        t, _ = extra_hit(geo, i, o, d, inv, t * (1.0 + 1e-12) + step, tmax)
    return n, full


def gather_extra_hits_if_extras(geo, i, o, d, inv, tmin, tmax, step, hits, n, full):
    return gather_extra_hits(geo, i, o, d, inv, tmin, tmax, step, hits, n, full)


@overload(gather_extra_hits_if_extras)
def _gather_extra_hits_if_extras(geo, i, o, d, inv, tmin, tmax, step, hits, n, full):
    if not extras_possible(geo):
        return lambda geo, i, o, d, inv, tmin, tmax, step, hits, n, full: (n, full)
    return body(gather_extra_hits)


@kernel(specialise_constants=True)  # a variant per call site: LLVM inlines each
def _pass_surface(geo, mats, prim, tri, b1, b2, o, d, t, scratch, count, trans):
    """Light crossing the transparent surface hit at t: media pushed or popped, kt·colour
    applied where it enters. Returns (media count, transmittance)."""
    m = hit_material(geo, prim, tri)
    kt = mats[m, MAT_KT]
    entering = True
    if geo.prim_info[prim, PRIM_SOLID]:
        n = geometric_normal(geo, prim, tri, b1, b2, madd(o, d, t))
        entering = dot(d, n) < 0.0
        body = body_medium(geo, prim, m)  # a CSG object is one body (extras.py)
        if entering:
            count = media_enter(scratch, count, body)
        else:
            count = media_leave(scratch, count, body)
    if entering:
        trans = (trans[0] * kt * mats[m, MAT_COLOR], trans[1] * kt * mats[m, MAT_COLOR + 1],
                 trans[2] * kt * mats[m, MAT_COLOR + 2])
    return count, trans


@kernel
def _absorb(mats, scratch, count, length, trans):
    """Beer-Lambert absorption over ``length`` in the innermost medium, if any."""
    if count == 0:
        return trans
    m = scratch[count - 1]
    return (absorbed(trans[0], mats[m, MAT_ATTEN], length),
            absorbed(trans[1], mats[m, MAT_ATTEN + 1], length),
            absorbed(trans[2], mats[m, MAT_ATTEN + 2], length))


@kernel(inline="always")  # as when it was written inside the shadow ray's code
def _shadow_through_instances(geo, mats, params, o, d, dist, media, n_media, scratch, stack,
                              occluders, list_first, n_listed):
    """A shadow ray's transmittance (:func:`direct_light`) in scenes with mesh instances, from
    ``epsilon`` to ``dist`` along unit ``d``: an any-hit test first (over the light-buffer
    cell's list ``occluders[list_first:][:n_listed]`` when ``n_listed`` >= 0, else a walk of
    both BVHs), then, only when it met transparent surfaces, the crossings one nearest hit at
    a time. ``scratch[:n_media]`` already holds a copy of ``media[:n_media]``."""
    count = n_media
    trans = (1.0, 1.0, 1.0)
    t_from = params.epsilon
    state = listed_occlusion(geo, mats, occluders, list_first, n_listed, o, d, params.epsilon,
                             dist, stack)
    if state == 0:  # only the medium the point is in, if any, dims the light
        return _absorb(mats, media, n_media, dist - params.epsilon, (1.0, 1.0, 1.0)), -1
    if state == 1:
        return (0.0, 0.0, 0.0), -1
    for _ in range(64):
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, t_from, dist, stack)
        seg_end = t if prim >= 0 else dist
        trans = _absorb(mats, scratch, count, seg_end - t_from, trans)
        if prim < 0:
            break
        if mats[hit_material(geo, prim, tri), MAT_KT] < OPAQUE_KT:
            return (0.0, 0.0, 0.0), -1
        count, trans = _pass_surface(geo, mats, prim, tri, b1, b2, o, d, t, scratch, count,
                                     trans)
        if max(trans[0], max(trans[1], trans[2])) < 1e-4:
            return (0.0, 0.0, 0.0), -1
        t_from = t * (1.0 + 1e-12) + params.epsilon
    return trans, -1


def shadow_through_instances_if_instances(geo, mats, params, o, d, dist, media, n_media,
                                          scratch, stack, occluders, list_first, n_listed):
    """:func:`_shadow_through_instances`, never compiled for scenes without instances (see
    features.py)."""
    return _shadow_through_instances(geo, mats, params, o, d, dist, media, n_media, scratch,
                                     stack, occluders, list_first, n_listed)


@overload(shadow_through_instances_if_instances, forceinline=True)  # as the kernel
def _shadow_through_instances_if_instances(geo, mats, params, o, d, dist, media, n_media,
                                           scratch, stack, occluders, list_first, n_listed):
    if not instances_possible(geo):
        return (lambda geo, mats, params, o, d, dist, media, n_media, scratch, stack,
                occluders, list_first, n_listed: ((1.0, 1.0, 1.0), -1))
    return body(_shadow_through_instances)


@kernel
def disk_below_horizon(table, j, p, n):
    """True when every point of disk light ``j`` lies below the plane through ``p`` normal
    to ``n`` (the shaded surface's horizon) by more than the rounding of any sample's test
    ``n·l <= 0``: no sample of it can light ``p``. The disk's points are centre + rad·(x·U +
    y·V) with x² + y² <= 1, so n·(point - p) is at most n·(centre - p) + rad·|(n·U, n·V)|."""
    to_centre = sub(vload(table, j, LIGHT_POSITION), p)
    rad = table[j, LIGHT_RADIUS]
    nu = dot(n, vload(table, j, LIGHT_DISK_U))
    nv = dot(n, vload(table, j, LIGHT_DISK_V))
    highest = dot(n, to_centre) + rad * math.sqrt(nu * nu + nv * nv)
    # far above the rounding of the samples' points and directions, at any coordinates
    margin = 1e-9 * (math.sqrt(dot(to_centre, to_centre)) + rad + abs(p[0]) + abs(p[1])
                     + abs(p[2]))
    return highest < -margin


@kernel
def _cone_cos_max(w, axis, length, sin_a, cos_a):
    """The largest cosine between unit-free ``w`` and a direction of the cone about ``axis``
    (its length ``length``) of half-angle a, times |w|: |w| cos(max(0, b - a)), b the angle
    from ``w`` to the axis."""
    w_len = math.sqrt(dot(w, w))
    if w_len == 0.0:
        return 0.0
    cos_b = min(1.0, max(-1.0, dot(w, axis) / (w_len * length)))
    if cos_b >= cos_a:
        return w_len
    return w_len * (cos_b * cos_a + math.sqrt(1.0 - cos_b * cos_b) * sin_a)


@kernel
def disk_highlight_bound(table, j, mats, m, p, n, v, radiance, share):
    """At least the most (in any channel) that one sample of disk light ``j`` adds to the
    highlight of material ``m`` at ``p`` (the only light a surface without diffuse
    reflection reflects; ``n`` the normal, ``v`` the unit direction to the eye), or INF
    where it is not bounded. The highlight's cosine is bounded over the
    cone of directions l from ``p`` to the disk's ball: Phong's r·v = l·rv (rv: v mirrored
    about n) by the cone's nearest direction to rv; Blinn's n·h = (n·l + n·v) / |l + v| by
    the largest n·l over the smallest |l + v|; generously (1e-9 added to the cosine)."""
    to_centre = sub(vload(table, j, LIGHT_POSITION), p)
    length = math.sqrt(dot(to_centre, to_centre))
    rad = table[j, LIGHT_RADIUS] * (1.0 + 1e-9)
    if length <= 2.0 * rad:
        return INF
    sin_a = rad / length  # the cone's half-angle a
    cos_a = math.sqrt(1.0 - sin_a * sin_a)
    ndv = dot(n, v)
    if mats[m, MAT_BLINN] != 0.0:
        top = _cone_cos_max(n, to_centre, length, sin_a, cos_a) + ndv
        # the smallest l·v: the cone's farthest direction from v
        far = -_cone_cos_max((-v[0], -v[1], -v[2]), to_centre, length, sin_a, cos_a)
        bottom = 2.0 + 2.0 * far
        if top <= 0.0:
            c_max = 0.0
        elif bottom <= 1e-6:
            return INF
        else:
            c_max = top / math.sqrt(bottom)
    else:
        rv = (2.0 * ndv * n[0] - v[0], 2.0 * ndv * n[1] - v[1], 2.0 * ndv * n[2] - v[2])
        c_max = _cone_cos_max(rv, to_centre, length, sin_a, cos_a)
    c_max += 1e-9
    spec = 0.0
    if c_max > 0.0:
        spec = mats[m, MAT_KS] * highlight_power(c_max, mats[m, MAT_SHININESS])
    weight = share * _falloff(table, j, length - rad)  # the nearest point of the ball
    most = 0.0
    for k in range(3):
        most = max(most, weight * radiance[k] * spec * mats[m, MAT_SPECULAR + k])
    return most


@kernel
def disk_left_out(table, j, mats, m, p, n, v, radiance, share):
    """True when no sample of disk light ``j`` would pass :func:`direct_light`'s tests at
    ``p`` (material ``m``, normal ``n``, toward the eye ``v``): the disk below the horizon,
    or a surface without diffuse reflection whose highlight it lights negligibly."""
    if disk_below_horizon(table, j, p, n):
        return True
    return (mats[m, MAT_KD] == 0.0 and disk_highlight_bound(table, j, mats, m, p, n, v,
                                                            radiance, share)
            < 0.5 * NEGLIGIBLE_LIGHT)


@kernel
def _falloff(lights, j, dist):
    mode = lights[j, LIGHT_FALLOFF]
    if mode == 1.0:
        return lights[j, LIGHT_DIST_SCALE] / dist
    if mode == 2.0:
        return 1.0 / (dist * dist)
    return 1.0


MAX_SQUARING_EXPONENT = 4096  # whole shininess up to this is raised by repeated squaring


@kernel
def highlight_power(c, shininess):
    """c ** shininess for the highlight (0 < c <= 1). A whole exponent, as shininess nearly
    always is, takes a few multiplications by repeated squaring (a general ``pow`` cost about
    a tenth of the benchmark's render time); any other goes to ``pow``."""
    k = int(shininess)
    if k != shininess or k <= 0 or k > MAX_SQUARING_EXPONENT:
        return c**shininess
    result = 1.0
    base = c
    while True:
        if k & 1:
            result *= base
        k >>= 1
        if k == 0:
            return result
        base *= base


@kernel(inline="always")
def _brdf(mats, m, albedo, n, v, ldir):
    """Diffuse + specular response (per channel) for unit light direction ``ldir``; n·l > 0.
    ``albedo`` is the diffuse colour at the point (the material's, times its texture)."""
    ndl = dot(n, ldir)
    kd = mats[m, MAT_KD] * ndl
    ks = mats[m, MAT_KS]
    spec = 0.0
    if ks > 0.0:
        shin = mats[m, MAT_SHININESS]
        if mats[m, MAT_BLINN] != 0.0:
            h = normalize((ldir[0] + v[0], ldir[1] + v[1], ldir[2] + v[2]))
            c = dot(n, h)
        else:
            r = (2.0 * ndl * n[0] - ldir[0], 2.0 * ndl * n[1] - ldir[1], 2.0 * ndl * n[2] - ldir[2])
            c = dot(r, v)
        if c > 0.0:
            spec = ks * highlight_power(c, shin)
    return (
        kd * albedo[0] + spec * mats[m, MAT_SPECULAR],
        kd * albedo[1] + spec * mats[m, MAT_SPECULAR + 1],
        kd * albedo[2] + spec * mats[m, MAT_SPECULAR + 2],
    )


@kernel(inline="always")
def direct_light(
    geo, mats, lights, params, p, n, v, m, albedo, media, n_media, scratch, stack, hits,
    listed, counters, rng
):
    """Light reflected toward ``v`` at point ``p`` with shading normal ``n`` (facing ``v``) by
    every non-ambient light; ``albedo`` is the diffuse colour there. ``rng`` = (pixel, sample,
    first dimension) for area-light samples. A point light's shadow ray tests the list of its
    light-buffer cell; an area light's samples share the list of their bundle.

    One function from the lights down to the walks of the shadow rays, in three nested parts:
    each light's samples; each sample's shadow ray (its transmittance); the walks that gather
    that ray's surface crossings. Numba compiles every separately compiled function on its
    own and LLVM optimises, in each, the whole of the code it calls once more: written as
    functions calling functions, the shadow code was optimised and turned into machine code
    once per level, here once (docs/performance.md, the flat-tree round). Leaves with no deep
    callees (the BRDF, the media, the bundle's list) stay functions.

    **The shadow ray** runs from ``epsilon`` along ``ldir`` (not offset along the normal) to
    ``tmax``, so it passes exactly where the geometry says: a point whose light path grazes an
    occluder's edge is shadowed as the lecture computes it. Each transparent occluder
    multiplies by its ``kt·color`` where the ray enters it, and the medium the ray is in
    absorbs ``exp(-attenuation·length)`` segment by segment (it starts in the media
    ``media[:n_media]`` of the point being shaded). ``blocker`` is an opaque analytic
    primitive that blocked a previous sample's ray from ``p`` (the same area light's): it is
    tried first, and when it blocks this ray too no walk is needed. When ``n_listed`` >= 0,
    the ray's possible occluders are ``occluders[list_first:][:n_listed]`` (a bundle's list,
    see :func:`list_bundle_occluders`, or a light-buffer cell's) and no BVH walk is made;
    when they are all opaque (``listed_opaque``) the first one hit ends the search.

    **A walk** gathers the analytic surface crossings on (t_from, tmax), from the scene BVH
    (or the listed primitives), into ``hits`` as (t, primitive) pairs sorted by t: both
    crossings of a closed body (they are convex: at most two, the second searched from
    ``epsilon`` past the first), the nearest MAX_SHADOW_HITS of them; ``full`` when there were
    more (walk again from past the last one). An opaque surface hit ends it (``opaque``)."""
    r = 0.0
    g = 0.0
    b = 0.0
    if mats[m, MAT_KD] == 0.0 and mats[m, MAT_KS] == 0.0:
        return (r, g, b)
    dim = rng[2]
    table = lights.table
    eps = params.epsilon
    for j in range(table.shape[0]):
        kind = table[j, LIGHT_TYPE]
        radiance = vload(table, j, LIGHT_RADIANCE)
        n_samples = int(table[j, LIGHT_SAMPLES]) if kind == LIGHT_DISK else 1
        share = 1.0 / n_samples
        centre = vload(table, j, LIGHT_POSITION)
        if kind == LIGHT_DISK and disk_left_out(table, j, mats, m, p, n, v, radiance, share):
            # none of its samples would pass the tests below (n·l > 0, a highlight's light
            # not negligible): left out at once, with the random numbers they would have used
            dim += 2 * n_samples
            continue
        blocker = -1  # what shadowed this light's previous sample from p
        occluders = listed  # the array holding the list of possible occluders
        list_first = 0
        n_listed = -1  # the samples' shared list of possible occluders (-1: none, walk)
        listed_opaque = False
        if kind == LIGHT_DISK and n_samples >= MIN_BUNDLE_SAMPLES and not has_instances(geo):
            n_listed, listed_opaque = list_bundle_occluders(
                geo, mats, p, centre, table[j, LIGHT_RADIUS], eps, stack, listed)
        # samples are stratified over a grid of m_cols x m_rows cells, walked cell by cell
        _, _, m_cols, m_rows = stratum(0, n_samples)
        cx = -1
        cy = 0
        for _s in range(n_samples):
            chunk = _s % SAMPLE_CHUNK
            if kind == LIGHT_DISK and chunk == 0:  # the next points of the disk, drawn ahead
                dim, cx, cy = stratified_disk(params.seed, rng[0], rng[1], dim, cx, cy, m_cols,
                                              m_rows, min(SAMPLE_CHUNK, n_samples - _s), hits,
                                              DISK_POINTS)
            # one shadow ray per sample (one call site: the shadow code is inlined once)
            if kind == LIGHT_DIRECTIONAL:
                travel = vload(table, j, LIGHT_DIRECTION)
                ldir = (-travel[0], -travel[1], -travel[2])
                to_light = ldir
                dist = INF
                tmax = INF
                weight = 1.0
            else:
                target = centre
                if kind == LIGHT_DISK:
                    dx = hits[DISK_POINTS + 2 * chunk]
                    dy = hits[DISK_POINTS + 2 * chunk + 1]
                    rad = table[j, LIGHT_RADIUS]
                    target = madd(madd(centre, vload(table, j, LIGHT_DISK_U), dx * rad),
                                  vload(table, j, LIGHT_DISK_V), dy * rad)
                to_light = sub(target, p)
                dist = math.sqrt(dot(to_light, to_light))
                if dist == 0.0:
                    continue
                ldir = (to_light[0] / dist, to_light[1] / dist, to_light[2] / dist)
                tmax = dist - eps
                weight = share * _falloff(table, j, dist)
            if dot(n, ldir) <= 0.0:
                continue
            # a surface without diffuse reflection (water, glass, air) reflects a light only
            # in its highlight, a narrow lobe (c ** shininess); outside it the light would add
            # less than NEGLIGIBLE_LIGHT to the colour even unshadowed, and no shadow ray is
            # traced for it
            highlight_only = mats[m, MAT_KD] == 0.0
            f = (0.0, 0.0, 0.0)
            if highlight_only:
                f = _brdf(mats, m, albedo, n, v, ldir)
                if max(weight * radiance[0] * f[0], max(weight * radiance[1] * f[1],
                       weight * radiance[2] * f[2])) < NEGLIGIBLE_LIGHT:
                    continue
            buffer = int(table[j, LIGHT_BUFFER])
            if buffer >= 0:
                cell = buffer + cube_cell((-to_light[0], -to_light[1], -to_light[2]),
                                          int(table[j, LIGHT_BUFFER_SIDE]))
                occluders = lights.buffer_prims
                list_first = lights.buffer_cells[cell, CELL_FIRST]
                n_listed = lights.buffer_cells[cell, CELL_COUNT]
                listed_opaque = lights.buffer_cells[cell, CELL_OPAQUE] != 0
            counters[RAY_SHADOW] += 1

            # the shadow ray: its transmittance ``vis``; a sample whose ray an opaque surface
            # blocks is left (that surface becomes the next sample's ``blocker``)
            if blocker >= 0 and hit_analytic(geo, blocker, p, ldir, eps, tmax) < INF:
                continue
            opaque = -1  # an opaque primitive found on the ray
            # (a cell listing instance leaves is never ``listed_opaque``)
            if n_listed >= 0 and listed_opaque:
                for k in range(list_first, list_first + n_listed):
                    if hit_analytic(geo, occluders[k], p, ldir, eps, tmax) < INF:
                        opaque = occluders[k]
                        break
                if opaque >= 0:
                    blocker = opaque
                    continue
                vis = _absorb(mats, media, n_media, tmax - eps, (1.0, 1.0, 1.0))
            else:
                for k in range(n_media):
                    scratch[k] = media[k]
                if has_instances(geo):
                    vis, _ = shadow_through_instances_if_instances(
                        geo, mats, params, p, ldir, tmax, media, n_media, scratch, stack,
                        occluders, list_first, n_listed)
                else:
                    # walks gather the surfaces on the segment, sorted, a buffer-full at a
                    # time; one closer than ``epsilon`` to the previous crossing is the same
                    # crossing (a shared edge, a touching pair) and is skipped, as the
                    # stepping walk of instance scenes would
                    count = n_media
                    vis = (1.0, 1.0, 1.0)
                    t_from = eps
                    inv = inverse_direction(ldir)
                    fo, finv = bvh_frame_ray(geo, p, ldir, inv)  # the ray the boxes see
                    for _ in range(64):
                        # a walk (see the docstring) over (t_from, tmax)
                        n_hits = 0
                        full = n_hits < 0  # False, typed bool (a literal: keep_nearest twice)
                        cand, leaf, leaf_end, top = start_scene_walk(geo, stack, False)
                        k = 0
                        while True:
                            if n_listed >= 0:
                                if k == n_listed:
                                    break
                                i = occluders[list_first + k]
                                k += 1
                            else:
                                i, cand, leaf, leaf_end, top = next_scene_candidate(
                                    geo, fo, finv, t_from, tmax, stack, cand, leaf, leaf_end,
                                    top, False)
                                if i < 0:
                                    break
                            if (has_extras(geo) and is_extra(geo.prim_info[i, PRIM_TYPE])
                                    and mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT]
                                    >= OPAQUE_KT):
                                # a clear torus or CSG object: every crossing (a CSG
                                # object's as its leaves)
                                n_hits, full = gather_extra_hits_if_extras(
                                    geo, i, p, ldir, inv, t_from, tmax, eps, hits, n_hits, full)
                                continue
                            t = hit_analytic(geo, i, p, ldir, t_from, tmax)
                            if t == INF:
                                continue
                            # the material is looked up only for the surfaces hit (most
                            # candidates miss)
                            if mats[geo.prim_info[i, PRIM_MATERIAL], MAT_KT] < OPAQUE_KT:
                                opaque = i
                                break
                            n_hits, full = keep_nearest(hits, n_hits, t, i, full)
                            # a closed analytic body is crossed twice (the triangles of a
                            # flattened solid mesh are each crossed once: their body's other
                            # side is other triangles)
                            if crossed_twice(geo.prim_info[i, PRIM_TYPE],
                                             geo.prim_info[i, PRIM_SOLID]):
                                t = hit_analytic(geo, i, p, ldir, t * (1.0 + 1e-12) + eps, tmax)
                                if t < INF:
                                    n_hits, full = keep_nearest(hits, n_hits, t, i, full)
                        if opaque >= 0:
                            break
                        # the light through the crossings gathered, nearest first
                        for k in range(n_hits):
                            t = hits[2 * k]
                            if t <= t_from:
                                continue
                            vis = _absorb(mats, scratch, count, t - t_from, vis)
                            count, vis = _pass_surface(geo, mats, int(hits[2 * k + 1]), -1, 0.0,
                                                       0.0, p, ldir, t, scratch, count, vis)
                            if max(vis[0], max(vis[1], vis[2])) < 1e-4:
                                vis = (0.0, 0.0, 0.0)
                                full = False  # no light left: no more walks
                                break
                            t_from = t * (1.0 + 1e-12) + eps
                        if not full:
                            break
                    if opaque >= 0:
                        blocker = opaque
                        continue
                    if vis[0] == 0.0 and vis[1] == 0.0 and vis[2] == 0.0:
                        continue
                    vis = _absorb(mats, scratch, count, tmax - t_from, vis)
            if vis[0] == 0.0 and vis[1] == 0.0 and vis[2] == 0.0:
                continue

            if not highlight_only:
                f = _brdf(mats, m, albedo, n, v, ldir)
            r += weight * radiance[0] * vis[0] * f[0]
            g += weight * radiance[1] * vis[1] * f[1]
            b += weight * radiance[2] * vis[2] * f[2]
    return (r, g, b)
