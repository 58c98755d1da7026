"""Light left out of highlight-only surfaces (kernels/lighting.py ``NEGLIGIBLE_LIGHT``): a
surface without diffuse reflection (water, glass) reflects a light only in its highlight,
and gets a shadow ray only where that light would add at least NEGLIGIBLE_LIGHT. The image
is the one the full computation gives wherever the light counts, and 0 where it does not."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import whitted
from whitted.compile.scene import compile_scene
from whitted.kernels.layout import MAT_KD
from whitted.kernels.lighting import NEGLIGIBLE_LIGHT
from whitted.render.api import RenderJob

# a diffuse coefficient too small to change any highlight the test sees (spec·1 + 1e-300 is
# spec in float64 for every spec above about 1e-284): the full computation, every light
# sample traced, for the same picture
NO_DIFFUSE_BUT_TRACED = 1e-300


def _scene(shininess, height, model):
    shiny = whitted.Material(color=(1, 1, 1), ka=0.0, kd=0.0, ks=1.0, shininess=shininess,
                             specular_model=model)
    matte = whitted.Material(color=(0.8, 0.3, 0.2), ka=0.0, kd=0.9)
    return whitted.Scene(
        objects=[whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0), material=shiny),
                 # an opaque ball shadowing part of the plane's highlight
                 whitted.Sphere(center=(0.2, 0.45 * height, 0.1), radius=0.08 * height,
                                material=matte)],
        lights=[whitted.PointLight(position=(0.0, height, 0.0), intensity=0.9)],
        camera=whitted.Camera(position=(0, 2.5, 3.5), look_at=(0, 0, 0), fov=60),
        render=whitted.RenderSettings(width=40, height=30, max_depth=0))


def _both(scene):
    """(framebuffer, shadow rays) of the scene as it is (the plane without diffuse term) and
    of the same scene with every light sample traced."""
    compiled = compile_scene(scene)
    traced = compiled.materials.copy()
    traced[traced[:, MAT_KD] == 0.0, MAT_KD] = NO_DIFFUSE_BUT_TRACED
    out = []
    for c in (compiled, dataclasses.replace(compiled, materials=traced)):
        job = RenderJob(scene, compiled=c, threads=1)
        job.run()
        out.append((job.framebuffer.copy(), job.stats.rays["shadow"]))
    return out


def _check(shininess, height, model):
    (cut, cut_rays), (full, full_rays) = _both(_scene(shininess, height, model))
    value = full.max(axis=-1)
    counts = value >= NEGLIGIBLE_LIGHT * (1 + 1e-6)
    faint = value < NEGLIGIBLE_LIGHT * (1 - 1e-6)
    # where the light counts, the same bits; where it is negligible, nothing (not unshadowed
    # light) or, on the matte ball (which has a diffuse term), the same bits
    assert np.array_equal(cut[counts], full[counts])
    assert np.all((cut[faint] == 0.0) | (cut[faint] == full[faint]))
    assert cut_rays <= full_rays
    return cut, full, cut_rays, full_rays


@settings(max_examples=12, deadline=None)
@given(shininess=st.floats(1.0, 5000.0), height=st.floats(0.5, 6.0),
       model=st.sampled_from(["blinn", "phong"]))
def test_left_out_light_is_only_light_that_would_not_count(shininess, height, model):
    _check(shininess, height, model)


def test_a_sharp_highlight_needs_few_shadow_rays():
    cut, full, cut_rays, full_rays = _check(2000.0, 2.0, "blinn")
    assert full.max() > 0.5  # the highlight is there
    # the plane's shadow rays outside the highlight are gone (the ball's stay)
    assert cut_rays < full_rays / 2
    lit = full.max(axis=-1) > 0.01  # a highlight, not a lit plane
    assert 0 < lit.sum() < lit.size / 4
