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
from .adaptive import N_STATE, next_sample
from .camera import camera_ray, lens_ray
from .integrator import N_STACK_F, N_STACK_I, trace_path
from .layout import (
    BVH_STACK,
    MAX_MEDIA,
    N_RAY_KINDS,
    PRIM_OBJECT,
    RAY_PRIMARY,
)
from .lighting import HITS_BUFFER, SHADOW_LIST_CAP
from .sampling import random_pair, stratum
from .vec import madd

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


def adaptive_workspace(tile_width: int = 0, tile_height: int = 0, levels: int = 0):
    """Scratch memory of one lane for adaptive anti-aliasing (kernels/adaptive.py): the
    corners of a tile's pixels, one pixel's sample grid and its marks, the stack of squares
    to visit (three per level and the first), the walk's state and a pixel's sums so far.
    With no arguments: the few bytes a render of uniform samples passes in its place."""
    side = (1 << levels) + 1
    return (own_lines((tile_height + 1, tile_width + 1, 3)), own_lines((side, side, 3)),
            own_lines((side, side), np.int8), own_lines((3 * levels + 2, 3), np.int32),
            own_lines(N_STATE, np.int64), own_lines(3))


@kernel(entry=True)  # called from Python
def render_tiles(tiles, framebuffer, geo, mats, lights, params, counters, work, aa, threshold,
                 levels, lane, lanes):
    """Render this lane's share of ``tiles`` (rows of x0, y0, x1, y1) into ``framebuffer``
    (H, W, 3 float32); ``counters[t]`` receives the rays traced for tile t by kind. ``work`` is
    the lane's scratch memory from :func:`lane_workspace`; rays are counted there, in the
    lane's own memory, and stored in ``counters`` once a tile (rows of neighbouring tiles
    share cache lines, and lanes render neighbouring tiles).

    ``levels`` < 0: ``params.samples`` stratified samples a pixel; ``levels`` >= 0: adaptive
    anti-aliasing (kernels/adaptive.py) with ``threshold``, splitting a pixel ``levels``
    times at most, ``aa`` the lane's scratch memory from :func:`adaptive_workspace` made
    for these ``levels`` and tiles no wider or taller than its arguments (the kernel checks
    no bounds; the render API makes it so), or any of them for uniform samples. Both trace
    their samples at the one call of the path tracer below, so that it is compiled into this
    kernel once: the next sample is picked (a pixel's next stratum, or what
    adaptive.next_sample asks for), traced, then accounted for."""
    n_tiles = tiles.shape[0]
    spp = params.samples
    uniform = levels < 0
    geo = geometry_ref_if_instances(geo)  # one pointer for every call, not 28 arrays
    st_f, st_i, media, scratch, stack, hits, listed, cnt = work
    state = aa[4]
    for t in range(lane, n_tiles, lanes):
        for k in range(N_RAY_KINDS):
            cnt[k] = 0
        x0 = tiles[t, 0]
        y0 = tiles[t, 1]
        x1 = tiles[t, 2]
        y1 = tiles[t, 3]
        px = x0  # uniform samples: the pixel, its sample and their sums
        py = y0
        s = np.int64(0)  # typed int64 from the start: see trace_path's call below
        r = 0.0
        g = 0.0
        b = 0.0
        for k in range(N_STATE):  # adaptive: the walk from the tile's first corner
            state[k] = 0
        c = (0.0, 0.0, 0.0)  # adaptive: the sample traced last, kept by next_sample
        while True:
            if uniform:
                if py >= y1 or px >= x1:
                    break
                pixel = py * params.width + px
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
            else:  # a point of the finest grid: its index there is its sampler's "pixel"
                o, d, pixel = next_sample(params, x0, y0, x1, y1, levels, threshold,
                                          framebuffer, aa, c)
                if pixel < 0:
                    break
            cnt[RAY_PRIMARY] += 1
            # s: the sample's number (adaptive: always 0), never typed as a literal 0, for
            # which Numba would compile direct_light a second time (the tuple (pixel, 0, ...)
            # that trace_path hands it is typed with its items' types, literals included)
            c = trace_path(geo, mats, lights, params, o, d, pixel, s, st_f, st_i, media,
                           scratch, stack, hits, listed, cnt)
            if not uniform:
                continue
            r += c[0]
            g += c[1]
            b += c[2]
            s += 1
            if s >= spp:  # the pixel's last sample
                inv = 1.0 / spp
                framebuffer[py, px, 0] = r * inv
                framebuffer[py, px, 1] = g * inv
                framebuffer[py, px, 2] = b * inv
                r = 0.0
                g = 0.0
                b = 0.0
                s = np.int64(0)
                px += 1
                if px == x1:
                    px = x0
                    py += 1
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


