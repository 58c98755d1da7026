"""Lights -> the light table (ambient lights summed apart)."""

from __future__ import annotations

import numpy as np

from ..kernels.layout import (
    FALLOFF_CODES,
    LIGHT_DIRECTION,
    LIGHT_DIRECTIONAL,
    LIGHT_DISK,
    LIGHT_DISK_U,
    LIGHT_DISK_V,
    LIGHT_DIST_SCALE,
    LIGHT_FALLOFF,
    LIGHT_POINT,
    LIGHT_POSITION,
    LIGHT_RADIANCE,
    LIGHT_RADIUS,
    LIGHT_SAMPLES,
    LIGHT_TYPE,
    N_LIGHT_PARAMS,
)
from ..scene.lights import AmbientLight, DirectionalLight, DiskLight, PointLight
from ..scene.scene import Scene
from .geometry import unit


def light_rows(scene: Scene) -> tuple[np.ndarray, tuple[float, float, float]]:
    rows = []
    ambient = np.zeros(3)
    for light in scene.lights:
        radiance = np.array(light.color) * light.intensity
        if isinstance(light, AmbientLight):
            ambient += radiance
            continue
        row = np.zeros(N_LIGHT_PARAMS)
        row[LIGHT_RADIANCE : LIGHT_RADIANCE + 3] = radiance
        if isinstance(light, PointLight):
            row[LIGHT_TYPE] = LIGHT_POINT
            row[LIGHT_POSITION : LIGHT_POSITION + 3] = light.position
        elif isinstance(light, DirectionalLight):
            row[LIGHT_TYPE] = LIGHT_DIRECTIONAL
            row[LIGHT_DIRECTION : LIGHT_DIRECTION + 3] = unit(light.direction)
        elif isinstance(light, DiskLight):
            row[LIGHT_TYPE] = LIGHT_DISK
            n = unit(light.normal)
            helper = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
            u = unit(np.cross(n, helper))
            row[LIGHT_POSITION : LIGHT_POSITION + 3] = light.center
            row[LIGHT_DIRECTION : LIGHT_DIRECTION + 3] = n
            row[LIGHT_RADIUS] = light.radius
            row[LIGHT_SAMPLES] = light.samples or scene.render.shadow_samples
            row[LIGHT_DISK_U : LIGHT_DISK_U + 3] = u
            row[LIGHT_DISK_V : LIGHT_DISK_V + 3] = np.cross(n, u)
        if isinstance(light, PointLight | DiskLight):
            row[LIGHT_FALLOFF] = FALLOFF_CODES[light.falloff]
            row[LIGHT_DIST_SCALE] = light.dist_scale
        rows.append(row)
    table = np.array(rows, dtype=np.float64).reshape(len(rows), N_LIGHT_PARAMS)
    return table, (float(ambient[0]), float(ambient[1]), float(ambient[2]))
