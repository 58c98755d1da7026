"""A compiled scene rendered by the render kernel itself on one lane (no job, no threads):
what the light-buffer tests compare, framebuffer against framebuffer."""

from __future__ import annotations

import numpy as np

from whitted.compile.params import render_params
from whitted.kernels.layout import N_RAY_KINDS
from whitted.kernels.tiles import adaptive_workspace, lane_workspace, render_tiles
from whitted.render.api import tile_grid


def render_one_lane(compiled, scene) -> np.ndarray:
    """The float32 framebuffer of ``compiled`` with ``scene``'s render settings."""
    params = render_params(scene, compiled, scene.render)
    tiles = tile_grid(params.width, params.height)
    fb = np.zeros((params.height, params.width, 3), np.float32)
    counters = np.zeros((len(tiles), N_RAY_KINDS), np.int64)
    render_tiles(tiles, fb, compiled.geometry, compiled.materials, compiled.lights, params,
                 counters, lane_workspace(params.max_depth), adaptive_workspace(), 0.0, -1, 0, 1)
    return fb
