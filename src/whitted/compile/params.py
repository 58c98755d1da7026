"""Render settings and the camera -> the kernels' ``RenderParams``."""

from __future__ import annotations

import numpy as np

from ..kernels.layout import RenderParams
from ..scene.scene import RenderSettings, Scene
from .scene import CompiledScene

# Embree intersects in float32: a hit point is off its triangle by a few float32 steps of the
# coordinates (2^-24 relative), so a secondary ray needs to start further away or it finds
# its own triangle again: a bumpy reflective sphere rendered speckled at 1e-7 (2.5 % of its
# pixels off whitted's walk by more than 1/255), 0.05 % at 1e-6, 0.008 % at 1e-5 (166 steps)
EMBREE_EPSILON = 1e-5


def auto_epsilon(scene: Scene, compiled: CompiledScene) -> float:
    """Offset of secondary-ray origins: the user's, or 1e-7 of the scene's coordinate scale
    (EMBREE_EPSILON of it where Embree traces the meshes, in float32: see compile/embree.py)."""
    if scene.render.epsilon > 0:
        return scene.render.epsilon
    scale = max(1.0, float(np.max(np.abs(scene.camera.position))))
    if np.all(np.isfinite(compiled.bounds_min)):
        scale = max(scale, float(np.max(np.abs(compiled.bounds_min))),
                    float(np.max(np.abs(compiled.bounds_max))))
    for i in compiled.geometry.unbounded:
        scale = max(scale, float(np.max(np.abs(compiled.geometry.prim_params[i, :3]))))
    if compiled.mesh_tracer == "embree":
        return EMBREE_EPSILON * scale
    return 1e-7 * scale


def render_params(scene: Scene, compiled: CompiledScene, settings: RenderSettings) -> RenderParams:
    cam = scene.camera
    right, up, forward = cam.basis()
    hw, hh = cam.half_extents(settings.width, settings.height)
    bg = scene.background
    top = bg.gradient.top if bg.gradient else bg.color
    bottom = bg.gradient.bottom if bg.gradient else bg.color

    def t3(v) -> tuple[float, float, float]:
        return (float(v[0]), float(v[1]), float(v[2]))

    return RenderParams(
        width=int(settings.width),
        height=int(settings.height),
        samples=int(settings.samples),
        max_depth=int(settings.max_depth),
        min_weight=float(settings.min_weight),
        epsilon=float(auto_epsilon(scene, compiled)),
        seed=int(settings.seed),
        ambient=t3(compiled.ambient),
        background_top=t3(top),
        background_bottom=t3(bottom),
        camera_origin=t3(cam.position),
        camera_right=t3(np.asarray(right) * hw),
        camera_up=t3(np.asarray(up) * hh),
        camera_forward=t3(forward),
        orthographic=int(cam.projection == "orthographic"),
        lens_u=t3(np.asarray(right) * (cam.aperture / 2)),
        lens_v=t3(np.asarray(up) * (cam.aperture / 2)),
        focal_distance=float(cam.focus()) if cam.aperture > 0 else 0.0,
    )
