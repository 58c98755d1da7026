"""Spheres and triangles scattered at random for the BVH walk tests (tests/test_ordered_walk.py,
tests/test_bvh_frame.py): clustered so that their boxes overlap and nest."""

from __future__ import annotations

import numpy as np

import whitted


def scattered_shapes(rng: np.random.Generator, n_spheres: int, n_tris: int, *, half: float,
                     radius_max: float, spread: float, scale: float, material=None) -> list:
    """``n_spheres`` spheres (radii 0.05 to ``radius_max``) and up to ``n_tris`` triangles
    (corners ``spread`` apart, normally; slivers left out) in a cube of half-side ``half``,
    everything times ``scale``; ``material``: a function making each shape's material (None:
    the default one)."""
    extra = (lambda: {}) if material is None else (lambda: {"material": material()})
    shapes = []
    for r in rng.uniform(0.05, radius_max, n_spheres):
        shapes.append(whitted.Sphere(center=tuple(rng.uniform(-half, half, 3) * scale),
                                     radius=float(r) * scale, **extra()))
    for _ in range(n_tris):
        a = rng.uniform(-half, half, 3)
        b = a + rng.normal(0, spread, 3)
        c = a + rng.normal(0, spread, 3)
        if np.linalg.norm(np.cross(b - a, c - a)) < 1e-3:
            continue
        shapes.append(whitted.Triangle(vertices=(tuple(a * scale), tuple(b * scale),
                                                 tuple(c * scale)), **extra()))
    return shapes
