"""A disk light left out of a point's shading at once (kernels/lighting.py: where
``disk_below_horizon``, or ``disk_highlight_bound`` is under half NEGLIGIBLE_LIGHT) only
where every one of its samples would have been left out by the per-sample tests of
``direct_light``: below the surface's horizon (n·l <= 0), or, on a surface without diffuse
reflection, a highlight's light under NEGLIGIBLE_LIGHT. Checked against those per-sample
tests at many points of the disk, its rim and the points nearest the bound, at scales from
1e-3 to 1e4."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from whitted.compile.scene import compile_scene
from whitted.kernels.layout import (
    LIGHT_DISK_U,
    LIGHT_DISK_V,
    LIGHT_POSITION,
    LIGHT_RADIANCE,
    LIGHT_RADIUS,
)
from whitted.kernels.lighting import (
    NEGLIGIBLE_LIGHT,
    _brdf,
    _falloff,
    disk_below_horizon,
    disk_highlight_bound,
)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _setup(centre, normal, radius, falloff, shininess, model):
    glass = whitted.Material(color=(1, 1, 1), ka=0.0, kd=0.0, ks=0.6, shininess=shininess,
                             specular_model=model, kt=0.9)
    scene = whitted.Scene(
        objects=[whitted.Sphere(center=(0, -50, 0), radius=1, material=glass)],
        lights=[whitted.DiskLight(center=tuple(centre), normal=tuple(normal), radius=radius,
                                  samples=64, falloff=falloff)])
    compiled = compile_scene(scene)
    return compiled.lights.table, compiled.materials, 0


def _disk_points(table, j, extra):
    """Points of the disk: its rim densely, a grid inside, and ``extra`` (x, y) offsets."""
    c = table[j, LIGHT_POSITION:LIGHT_POSITION + 3]
    u = table[j, LIGHT_DISK_U:LIGHT_DISK_U + 3]
    v = table[j, LIGHT_DISK_V:LIGHT_DISK_V + 3]
    rad = table[j, LIGHT_RADIUS]
    offsets = [(math.cos(a), math.sin(a)) for a in np.linspace(0, 2 * math.pi, 181)]
    offsets += [(x, y) for x in np.linspace(-1, 1, 9) for y in np.linspace(-1, 1, 9)
                if x * x + y * y <= 1]
    offsets += extra
    return [c + u * (x * rad) + v * (y * rad) for x, y in offsets]


def _per_sample(table, j, mats, m, p, n, v, target):
    """(n·l > 0, the sample's largest channel of light) as direct_light computes them."""
    to_light = target - p
    dist = math.sqrt(float(to_light @ to_light))
    ldir = tuple(to_light / dist)
    weight = (1.0 / 64) * _falloff(table, j, dist)
    f = _brdf(mats, m, (1.0, 1.0, 1.0), tuple(n), tuple(v), ldir)
    radiance = table[j, LIGHT_RADIANCE:LIGHT_RADIANCE + 3]
    return (float(np.dot(n, ldir)) > 0.0,
            max(weight * radiance[k] * f[k] for k in range(3)))


directions = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda t: sum(c * c for c in t) > 1e-3)
scales = st.sampled_from([1e-3, 1.0, 1e4])


@settings(max_examples=150, deadline=None)
@given(lift=st.floats(-0.3, 1.5), normal=directions, light_normal=directions,
       radius=st.floats(0.05, 2.0), view=directions, scale=scales,
       shininess=st.sampled_from([20.0, 300.0, 37.5]), model=st.sampled_from(["phong", "blinn"]),
       falloff=st.sampled_from(["none", "inverse_square", "linear"]),
       verge=st.floats(-3.0, 3.0))
def test_a_disk_left_out_at_once_would_have_lost_every_sample(lift, normal, light_normal,
                                                               radius, view, scale, shininess,
                                                               model, falloff, verge):
    """``lift`` places the light near the point's horizon: its centre ``lift`` light radii
    above the tangent plane (negative: below), 5 radii away; its intensity puts the
    highlight's bound at 10^``verge`` times the threshold (where a bound too low shows)."""
    n = _unit(normal)
    side = _unit(np.cross(n, _unit(view) + 0.1))
    p = np.array([0.3, -0.2, 0.7]) * scale
    centre = p + scale * radius * (5.0 * side + lift * n)
    table, mats, m = _setup(centre, light_normal, radius * scale, falloff, shininess, model)
    v = _unit(view)
    if np.dot(v, n) <= 0:
        v = v - 2 * np.dot(v, n) * n  # the eye on the normal's side, as direct_light has it
    below = disk_below_horizon(table, 0, tuple(p), tuple(n))
    radiance = tuple(table[0, LIGHT_RADIANCE:LIGHT_RADIANCE + 3])
    bound = disk_highlight_bound(table, 0, mats, m, tuple(p), tuple(n), tuple(v), radiance,
                                 1.0 / 64)
    if 0.0 < bound < math.inf:  # the light made as bright as puts the bound at the verge
        table[0, LIGHT_RADIANCE:LIGHT_RADIANCE + 3] *= 0.5 * NEGLIGIBLE_LIGHT * 10**verge / bound
        radiance = tuple(table[0, LIGHT_RADIANCE:LIGHT_RADIANCE + 3])
        bound = disk_highlight_bound(table, 0, mats, m, tuple(p), tuple(n), tuple(v),
                                     radiance, 1.0 / 64)
    faint = bound < 0.5 * NEGLIGIBLE_LIGHT
    if not (below or faint):
        return
    # the disk's points nearest the bound: highest above the horizon, nearest the mirror
    # direction of the eye
    u_ax = table[0, LIGHT_DISK_U:LIGHT_DISK_U + 3]
    v_ax = table[0, LIGHT_DISK_V:LIGHT_DISK_V + 3]
    extra = []
    for w in (n, v - 2 * np.dot(v, n) * n + 0.0, _unit(v) + n):
        a, b = float(np.dot(w, u_ax)), float(np.dot(w, v_ax))
        norm = math.hypot(a, b)
        if norm > 0:
            extra.append((a / norm, b / norm))
    for target in _disk_points(table, 0, extra):
        lit, light = _per_sample(table, 0, mats, m, p, n, v, target)
        if below:
            assert not lit
        if faint:
            assert not lit or light < NEGLIGIBLE_LIGHT


def test_the_skips_take_what_they_should():
    """Below the horizon: left out; above it, lit: kept. On glass, far from the highlight:
    left out; in the highlight: kept (Phong and Blinn)."""
    n = (0.0, 1.0, 0.0)
    p = (0.0, 0.0, 0.0)
    for model in ("phong", "blinn"):
        table, mats, m = _setup((5.0, -2.0, 0.0), (0, 1, 0), 1.0, "none", 300.0, model)
        assert disk_below_horizon(table, 0, p, n)
        table, mats, m = _setup((5.0, 5.0, 0.0), (0, 1, 0), 1.0, "none", 300.0, model)
        assert not disk_below_horizon(table, 0, p, n)
        radiance = tuple(table[0, LIGHT_RADIANCE:LIGHT_RADIANCE + 3])
        mirror_eye = tuple(_unit((-5.0, 5.0, 0.0)))  # the light's mirror image: the highlight
        bound = disk_highlight_bound(table, 0, mats, m, p, n, mirror_eye, radiance, 1 / 64)
        assert bound > 1e-3  # ks 0.6 of 1/64 of the light, nearly all of it
        away = tuple(_unit((5.0, 1.0, 0.0)))  # looking from the light's side: 80° off
        bound = disk_highlight_bound(table, 0, mats, m, p, n, away, radiance, 1 / 64)
        assert bound < 0.5 * NEGLIGIBLE_LIGHT
