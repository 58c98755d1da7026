"""An alpha channel for a render: the part of each pixel whose primary rays hit something.

It is measured beside the renderer, not inside it: the same scene with every surface a white
matte lit only by an ambient light of 1, on a black background and with no secondary rays,
renders each pixel as exactly the fraction of its samples that hit an object (the same
samples, seed and anti-aliasing as the picture; under adaptive anti-aliasing the matte's own
edges decide the splits). A second pass of the background alone says what the missed samples
saw, so the colour of what was hit can be taken apart from it: a pixel of the picture is
``C = a·F + (1 − a)·B``, and ``F`` (straight) or ``a·F`` (premultiplied) is what an image
with alpha stores. Secondary rays still see the background (a mirror reflects the sky).
"""

from __future__ import annotations

import numpy as np

from ..scene.lights import AmbientLight
from ..scene.materials import Material
from ..scene.scene import CausticsSettings, Scene
from ..scene.types import Background

__all__ = ["coverage_scenes", "render_coverage", "straight_colour"]

_MATTE = Material(color=(1.0, 1.0, 1.0), ka=1.0, kd=0.0, ks=0.0, kr=0.0, kt=0.0)


def _matte_objects(objects: list) -> list:
    out = []
    for obj in objects:
        update: dict = {"material": _MATTE}
        if obj.type == "csg":
            update["objects"] = _matte_objects(obj.objects)
        out.append(obj.model_copy(update=update))
    return out


def coverage_scenes(scene: Scene) -> tuple[Scene, Scene]:
    """(the matte scene whose pixels are the coverage, the background alone), both with the
    render settings of ``scene`` but for the tone map and transfer (clamp, linear) and no
    secondary rays or photons."""
    render = scene.render.model_copy(update={
        "max_depth": 0, "transfer": "linear", "tonemap": "clamp",
        "caustics": CausticsSettings()})
    matte = scene.model_copy(update={
        "render": render, "objects": _matte_objects(scene.objects),
        "materials": {name: _MATTE for name in scene.materials},
        "lights": [AmbientLight(intensity=1.0)], "background": Background(),
        "animation": None})
    sky = scene.model_copy(update={"render": render, "objects": [], "lights": [],
                                   "animation": None})
    return matte, sky


def render_coverage(scene: Scene, *, region: tuple[int, int, int, int] | None = None,
                    threads: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(alpha: float32 (H, W) in 0..1, the background's linear RGB (H, W, 3)) of a render of
    ``scene`` (a still), in ``region`` when given (0 elsewhere)."""
    from .api import RenderJob

    planes = []
    for part in coverage_scenes(scene):
        job = RenderJob(part, threads=threads, region=region)
        planes.append(job.run().pixels)
    alpha = np.clip(planes[0][..., 0], 0.0, 1.0).astype(np.float32)
    return alpha, planes[1]


def straight_colour(pixels: np.ndarray, alpha: np.ndarray,
                    background: np.ndarray) -> np.ndarray:
    """The colour of what the primary rays hit, apart from the background (straight, not
    premultiplied; 0 where nothing was hit): ``(C − (1 − a)·B) / a``."""
    a = alpha[..., None]
    premultiplied = np.maximum(pixels - (1.0 - a) * background, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(a > 0.0, premultiplied / np.where(a > 0.0, a, 1.0), 0.0)
    return out.astype(np.float32)
