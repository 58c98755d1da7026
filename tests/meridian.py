"""An independent reference for caustics of concentric spheres under a point light on their
axis: every ray from the light is traced in its meridian plane (the plane of the axis and the
ray, which it never leaves: every normal of a sphere centred on the axis lies in it), split
at each surface into its reflected and refracted parts by the exact Fresnel equations for
unpolarised light, and the power reaching the floor (y = 0) summed in rings. Nothing of
whitted is used: NumPy only.

Rays leave the light at polar angles theta (from straight down) in the cone around the
spheres; the ray at theta stands for the ring of rays at theta, of solid angle
2 pi sin(theta) dtheta, so a ray of a point light of intensity I carries I 2 pi sin(theta)
dtheta. Light that lands on the floor gives the irradiance of its ring, power / ring area.
"""

from __future__ import annotations

import math

import numpy as np


def _fresnel(cos_i, n1, n2):
    """(reflectance, cos of the refracted angle, refracted) for unpolarised light; total
    internal reflection: (1, 0, False)."""
    sin_t2 = (n1 / n2) ** 2 * (1.0 - cos_i * cos_i)
    ok = sin_t2 < 1.0
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin_t2))
    a, b = n1 * cos_i, n2 * cos_t
    c, e = n1 * cos_t, n2 * cos_i
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = (a - b) / (a + b)
        rp = (c - e) / (c + e)
    f = np.where(ok, 0.5 * (rs * rs + rp * rp), 1.0)
    return f, cos_t, ok


def floor_rings(light_height, centre_height, radii, iors, intensity=1.0, rays=200_000,
                edges=None, min_weight=1e-9, max_depth=200):
    """The light of a point light at (0, light_height, 0) on a floor y = 0 under spheres
    centred at (0, centre_height, 0) with ``radii`` (outermost first) and the ``iors`` of the
    shells inside each (outermost first; air outside): (ring edges, the irradiance each ring
    gets from light that crossed or met the spheres, the irradiance the light sends it along
    the same rays' straight paths, the spheres ignored). The floor's whole irradiance is
    I h / (rho^2 + h^2)^(3/2) less the second plus the first."""
    radii = [float(r) for r in radii]
    iors = [float(n) for n in iors]
    dist = light_height - centre_height
    theta_max = math.asin(min(1.0, radii[0] / dist))
    k = np.arange(rays)
    dtheta = theta_max / rays
    theta = (k + 0.5) * dtheta
    power = intensity * 2.0 * math.pi * np.sin(theta) * dtheta
    if edges is None:
        edges = np.linspace(0.0, 3.0, 301)
    # rays in the (x, y) meridian half plane, x >= 0 at the start
    ox = np.zeros(rays)
    oy = np.full(rays, float(light_height))
    dx = np.sin(theta)
    dy = -np.cos(theta)
    region = np.zeros(rays, np.int64)  # 0: air; k: inside sphere k - 1, outside sphere k
    landed_x, landed_w = [], []
    shadow = _land(ox, oy, dx, dy)  # where the straight paths meet the floor
    shadow_w = power.copy()
    w = power.copy()
    n_of = np.array([1.0] + iors)
    cx, cy = 0.0, float(centre_height)
    for _ in range(max_depth):
        if len(w) == 0:
            break
        # the candidate surfaces: the sphere the ray is inside (region k: sphere k - 1, from
        # inside) and the next one in (sphere k, from outside)
        px, py = ox - cx, oy - cy
        b = px * dx + py * dy
        c0 = px * px + py * py
        t_best = np.full(len(w), np.inf)
        hit_sphere = np.full(len(w), -1)
        for s, rad in enumerate(radii):
            disc = b * b - (c0 - rad * rad)
            sq = np.sqrt(np.maximum(disc, 0.0))
            # from outside (region s): the near root; from inside (region s + 1): the far one
            outside = region == s
            inside = region == s + 1
            t_near = -b - sq
            t_far = -b + sq
            t = np.where(outside, t_near, np.where(inside, t_far, np.inf))
            t = np.where((disc > 0.0) & (t > 1e-9), t, np.inf)
            better = t < t_best
            t_best = np.where(better, t, t_best)
            hit_sphere = np.where(better, s, hit_sphere)
        miss = ~np.isfinite(t_best)
        # rays that leave: in air, downward, onto the floor
        down = miss & (region == 0) & (dy < 0.0)
        landed_x.append(_land(ox[down], oy[down], dx[down], dy[down]))
        landed_w.append(w[down])
        keep = ~miss
        ox, oy, dx, dy, w = ox[keep], oy[keep], dx[keep], dy[keep], w[keep]
        region, t_best, hit_sphere = region[keep], t_best[keep], hit_sphere[keep]
        px = ox + t_best * dx
        py = oy + t_best * dy
        nx = (px - cx) / np.array(radii)[hit_sphere]
        ny = (py - cy) / np.array(radii)[hit_sphere]
        entering = region == hit_sphere  # from outside the sphere
        beyond = np.where(entering, hit_sphere + 1, hit_sphere)
        n1 = n_of[region]
        n2 = n_of[beyond]
        cos_i = np.abs(dx * nx + dy * ny)
        f, cos_t, ok = _fresnel(cos_i, n1, n2)
        # the normal facing the ray
        sgn = np.where(dx * nx + dy * ny < 0.0, 1.0, -1.0)
        fx, fy = nx * sgn, ny * sgn
        rx = dx + 2.0 * cos_i * fx
        ry = dy + 2.0 * cos_i * fy
        eta = n1 / n2
        tx = eta * dx + (eta * cos_i - cos_t) * fx
        ty = eta * dy + (eta * cos_i - cos_t) * fy
        wr = w * f
        wt = w * (1.0 - f)
        go_r = wr > min_weight
        go_t = ok & (wt > min_weight)
        ox = np.concatenate([px[go_r], px[go_t]])
        oy = np.concatenate([py[go_r], py[go_t]])
        dx = np.concatenate([rx[go_r], tx[go_t]])
        dy = np.concatenate([ry[go_r], ty[go_t]])
        w = np.concatenate([wr[go_r], wt[go_t]])
        region = np.concatenate([region[go_r], beyond[go_t]])
        norm = np.hypot(dx, dy)
        dx, dy = dx / norm, dy / norm
    x = np.abs(np.concatenate(landed_x))
    weights = np.concatenate(landed_w)
    area = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    traced = np.histogram(x, edges, weights=weights)[0] / area
    straight = np.histogram(np.abs(shadow), edges, weights=shadow_w)[0] / area
    return edges, traced, straight


def _land(ox, oy, dx, dy):
    return ox + dx * (-oy / dy)


def direct(rho, light_height, intensity=1.0):
    """A point light's irradiance on the floor at distance ``rho`` from under it."""
    return intensity * light_height / (rho * rho + light_height * light_height) ** 1.5
