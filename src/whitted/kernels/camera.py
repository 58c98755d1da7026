"""Camera rays: through a point of the image plane, and through a thin lens (focal blur)."""

from __future__ import annotations

from ..jit import kernel
from .sampling import concentric_disk, random_pair
from .vec import dot, madd, normalize, sub


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
