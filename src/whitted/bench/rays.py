"""Trace given rays, no shading: the ray-casting core that ``whitted bench --compare embree``
times beside Embree on the same rays.

Each kernel walks whitted's own acceleration structures exactly as a render does
(``closest_hit`` for camera rays, ``any_occluder`` for shadow rays), one ray after another on
the calling thread.
"""

from __future__ import annotations

import math

from ..jit import kernel
from ..kernels.accel import closest_hit
from ..kernels.camera import camera_ray
from ..kernels.geometry_ref import geometry_ref_if_instances
from ..kernels.lighting import any_occluder

TILE = 16  # the render's tile size: rays in the order a render lane traces them


@kernel
def camera_rays(params, origins, directions):
    """The camera ray through every pixel centre, tile by tile (16 x 16, row-major tiles,
    row-major pixels in each), as a render traces them."""
    width = params.width
    height = params.height
    k = 0
    for y0 in range(0, height, TILE):
        for x0 in range(0, width, TILE):
            for py in range(y0, min(y0 + TILE, height)):
                for px in range(x0, min(x0 + TILE, width)):
                    o, d = camera_ray(params, px + 0.5, py + 0.5)
                    for a in range(3):
                        origins[k, a] = o[a]
                        directions[k, a] = d[a]
                    k += 1


@kernel
def nearest_hits(geo, origins, directions, t_out, stack):
    """Distance to the nearest surface along each ray (inf where it hits nothing)."""
    geo = geometry_ref_if_instances(geo)  # as render_tiles passes it
    for k in range(origins.shape[0]):
        o = (origins[k, 0], origins[k, 1], origins[k, 2])
        d = (directions[k, 0], directions[k, 1], directions[k, 2])
        t, prim, _tri, _b1, _b2 = closest_hit(geo, o, d, 0.0, math.inf, stack)
        t_out[k] = t if prim >= 0 else math.inf


@kernel
def occluded(geo, mats, origins, directions, t_max, out, stack):
    """1 where something blocks the ray before ``t_max``, else 0."""
    geo = geometry_ref_if_instances(geo)
    for k in range(origins.shape[0]):
        o = (origins[k, 0], origins[k, 1], origins[k, 2])
        d = (directions[k, 0], directions[k, 1], directions[k, 2])
        out[k] = 1 if any_occluder(geo, mats, o, d, 0.0, t_max[k], stack) != 0 else 0
