"""Entry points called from Python: render a batch of tiles in parallel, or the AOVs.

The kernels release the GIL, so the render API runs one *lane* per Python thread, each taking
runs of tiles from a shared counter until none is left (``render_tiles`` can also split a
batch itself: lane k of n renders tiles k, k + n, ...). Each pixel's value depends only on
the scene, the seed and its coordinates, so the image is bit-identical whatever the thread
count.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel, numba_object
from .accel import closest_hit, surface_normals
from .integrator import N_STACK_F, N_STACK_I, trace_path
from .layout import (
    BVH_STACK,
    MAX_MEDIA,
    N_RAY_KINDS,
    PRIM_OBJECT,
    RAY_PRIMARY,
)
from .lighting import HITS_BUFFER, SHADOW_LIST_CAP
from .sampling import concentric_disk, random_pair, stratum
from .vec import dot, madd, normalize, sub

# kernels/geometry_ref.py is a Numba extension: imported with Numba (jit/decorators.py)
geometry_ref_if_instances = numba_object(f"{__package__}.geometry_ref",
                                         "geometry_ref_if_instances")


CACHE_LINE = 128  # bytes: the longest cache line of the cores whitted runs on (Apple's
# ARM cores; x86-64 cores have 64), so arrays apart by this are apart on all of them


def own_lines(shape, dtype=np.float64) -> np.ndarray:
    """A zeroed array on cache lines no other array shares: its first byte starts a line and
    a line of padding follows its last. Lanes write their scratch memory for every ray; two
    lanes writing into one line pass it between their cores at each write (ray counts of
    neighbouring tiles in one line made the kernel's interleaved lanes 14 % slower)."""
    dtype = np.dtype(dtype)
    nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    raw = np.zeros(nbytes + 3 * CACHE_LINE, np.uint8)
    start = -raw.ctypes.data % CACHE_LINE
    return raw[start:start + nbytes].view(dtype).reshape(shape)


def lane_workspace(max_depth: int):
    """Scratch arrays one lane reuses for every ray: the ray stack (float and int parts), two
    media lists, the BVH traversal stack, a shadow ray's sorted surface hits (and after them
    an area light's points drawn ahead, lighting.DISK_POINTS), the list of
    what may block an area light's bundle of shadow rays and the tile's ray counts by kind.
    Allocated in Python: the kernels run without the Numba runtime's reference counting,
    which would otherwise cost a third of the time. Each on cache lines of its own
    (:func:`own_lines`)."""
    return (
        own_lines((max_depth + 2, N_STACK_F)),
        own_lines((max_depth + 2, N_STACK_I), np.int32),
        own_lines(MAX_MEDIA, np.int32),
        own_lines(MAX_MEDIA, np.int32),
        own_lines(BVH_STACK, np.int32),
        own_lines(HITS_BUFFER),
        own_lines(SHADOW_LIST_CAP, np.int32),
        own_lines(N_RAY_KINDS, np.int64),
    )


@kernel
def camera_ray(params, x, y):
    """Ray through image-plane position (x, y) in pixels from the top-left corner."""
    sx = 2.0 * x / params.width - 1.0
    sy = 1.0 - 2.0 * y / params.height
    right = params.camera_right
    up = params.camera_up
    fwd = params.camera_forward
    offset = (sx * right[0] + sy * up[0], sx * right[1] + sy * up[1], sx * right[2] + sy * up[2])
    if params.orthographic:
        return madd(params.camera_origin, offset, 1.0), fwd
    return params.camera_origin, normalize(
        (fwd[0] + offset[0], fwd[1] + offset[1], fwd[2] + offset[2])
    )


@kernel
def lens_ray(params, o, d, pixel, sample):
    """The camera ray (o, d) through a thin lens (focal blur): from a point of the lens
    drawn by the pixel's sampler (dimension 1, concentric disk), toward the point where (o, d)
    meets the plane in focus. Points on that plane stay as sharp as through a pinhole."""
    u, v = random_pair(params.seed, pixel, sample, 1)
    lx, ly = concentric_disk(u, v)
    lu = params.lens_u
    lv = params.lens_v
    start = (o[0] + lx * lu[0] + ly * lv[0], o[1] + lx * lu[1] + ly * lv[1],
             o[2] + lx * lu[2] + ly * lv[2])
    f = params.focal_distance / dot(d, params.camera_forward)
    focus = madd(o, d, f)
    return start, normalize(sub(focus, start))


@kernel(entry=True)  # called from Python
def render_tiles(tiles, framebuffer, geo, mats, lights, params, counters, work, lane, lanes):
    """Render this lane's share of ``tiles`` (rows of x0, y0, x1, y1) into ``framebuffer``
    (H, W, 3 float32); ``counters[t]`` receives the rays traced for tile t by kind. ``work`` is
    the lane's scratch memory from :func:`lane_workspace`; rays are counted there, in the
    lane's own memory, and stored in ``counters`` once a tile (rows of neighbouring tiles
    share cache lines, and lanes render neighbouring tiles)."""
    n_tiles = tiles.shape[0]
    spp = params.samples
    geo = geometry_ref_if_instances(geo)  # one pointer for every call, not 28 arrays
    st_f, st_i, media, scratch, stack, hits, listed, cnt = work
    for t in range(lane, n_tiles, lanes):
        for k in range(N_RAY_KINDS):
            cnt[k] = 0
        for py in range(tiles[t, 1], tiles[t, 3]):
            for px in range(tiles[t, 0], tiles[t, 2]):
                pixel = py * params.width + px
                r = 0.0
                g = 0.0
                b = 0.0
                for s in range(spp):
                    if spp == 1:
                        jx = 0.5
                        jy = 0.5
                    else:
                        cx, cy, m, rows = stratum(s, spp)
                        ux, uy = random_pair(params.seed, pixel, s, 0)
                        jx = (cx + ux) / m
                        jy = (cy + uy) / rows
                    o, d = camera_ray(params, px + jx, py + jy)
                    if params.focal_distance > 0.0:  # focal blur (0: a pinhole)
                        o, d = lens_ray(params, o, d, pixel, s)
                    cnt[RAY_PRIMARY] += 1
                    c = trace_path(geo, mats, lights, params, o, d, pixel, s, st_f, st_i,
                                   media, scratch, stack, hits, listed, cnt)
                    r += c[0]
                    g += c[1]
                    b += c[2]
                inv = 1.0 / spp
                framebuffer[py, px, 0] = r * inv
                framebuffer[py, px, 1] = g * inv
                framebuffer[py, px, 2] = b * inv
        for k in range(N_RAY_KINDS):
            counters[t, k] = cnt[k]


@kernel(entry=True)  # called from Python
def render_aovs(geo, params, depth, normal, object_id, work, lane, lanes):
    """Depth (distance along the unit primary ray, inf on a miss), outward geometric normal
    (zeros on a miss) and object index (-1 on a miss) through every pixel centre of the rows
    lane, lane + lanes, ..."""
    geo = geometry_ref_if_instances(geo)  # as render_tiles: its callees' variants serve both
    for py in range(lane, params.height, lanes):
        stack = work[4]
        for px in range(params.width):
            o, d = camera_ray(params, px + 0.5, py + 0.5)
            t, prim, tri, b1, b2 = closest_hit(geo, o, d, 0.0, math.inf, stack)
            if prim < 0:
                depth[py, px] = math.inf
                object_id[py, px] = -1
                for k in range(3):
                    normal[py, px, k] = 0.0
                continue
            depth[py, px] = t
            object_id[py, px] = geo.prim_info[prim, PRIM_OBJECT]
            n, _ = surface_normals(geo, prim, tri, b1, b2, madd(o, d, t))
            for k in range(3):
                normal[py, px, k] = n[k]


