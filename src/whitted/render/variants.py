"""Every variant of the render kernels a scene can reach, each compiled (or loaded) by
rendering a tiny scene that needs it: what ``whitted warm`` compiles ahead of use.

The render kernels are specialised on a scene's arrays (kernels/features.py): *plain* (no mesh
instances, no tori or CSG objects) or *general* (either or both); the AOV kernel (depth,
normal, id) is one more. Caustics need the photon tracer (compile/photon_map.py, its IEEE
twins of the kernels, kernels/strict.py), one for each kind of geometry: the ``caustics``
variants compile only it. Their gather is a run-time choice of the render kernel
(kernels/caustics.py), as are adaptive anti-aliasing (kernels/adaptive.py), focal blur, area
lights, textures and media, compiled with it: a render with caustics needs the ``render``
variant of its geometry and the ``caustics`` one, a render with adaptive anti-aliasing the
``render`` one alone.
"""

from __future__ import annotations

import time
from collections.abc import Callable

#: the tiny scene of each kind of geometry: (with a mesh instance, with a torus); compile/
#: scene.py gives either or both the general kernels
GEOMETRY = {"plain": (False, False), "general": (True, True)}
KINDS = ("render", "caustics", "aovs")


def variant_names() -> list[str]:
    return [f"{geometry}/{kind}" for geometry in GEOMETRY for kind in KINDS]


def tiny_scene(extras: bool, kind: str):
    """A scene of a few pixels that reaches the variant: a glass sphere over a plane, a point
    light (caustics: the sphere focuses its photons), a torus for the extras, a small mesh
    (instanced when the variant asks for instances)."""
    from ..scene import Mesh, Plane, PointLight, RenderSettings, Scene, Sphere, Torus
    from ..scene.scene import CausticsSettings

    objects = [Sphere(center=(0, 1, 0), radius=1.0, material={"preset": "glass"}),
               Plane(), Mesh(vertices=[[2, 0, 0], [3, 0, 0], [2, 1, 0]], faces=[[0, 1, 2]])]
    if extras:
        objects.append(Torus(major_radius=1.0, minor_radius=0.25))
    render = RenderSettings(width=4, height=3, threads=1, max_depth=3)
    if kind == "caustics":
        render = render.model_copy(update={"caustics": CausticsSettings(photons=2000)})
    return Scene(objects=objects, lights=[PointLight(position=(0, 5, 0))], render=render)


def warm_variant(name: str) -> float:
    """Compile (or load) the kernels of variant ``name`` (``plain/render``, ...); returns the
    seconds it took."""
    from ..compile.scene import compile_scene
    from .api import RenderJob, render_aovs

    geometry, kind = name.split("/")
    instances, extras = GEOMETRY[geometry]
    scene = tiny_scene(extras, kind)
    start = time.perf_counter()
    if kind == "aovs" and not instances:
        render_aovs(scene)
    elif kind == "caustics":
        # the photon tracer only: a render with caustics runs the render kernel of its
        # geometry (the gather is a run-time choice of it), which is that geometry's
        # ``render`` variant; compiling it here too made two processes of ``whitted warm``
        # compile the general render kernel at once
        from ..compile.params import render_params
        from ..compile.photon_map import photon_lights

        compiled = compile_scene(scene, flatten_limit=0 if instances else 65_536)
        photon_lights(compiled, render_params(scene, compiled, scene.render),
                      scene.render.caustics)
    else:
        compiled = compile_scene(scene, flatten_limit=0 if instances else 65_536)
        RenderJob(scene, compiled=compiled, threads=1).run()
        if kind == "aovs":  # the AOV kernel of instanced scenes (after their render kernel)
            _aovs_of(scene, compiled)
    return time.perf_counter() - start


def _aovs_of(scene, compiled) -> None:
    """The AOV kernel for ``compiled`` (render_aovs compiles the scene itself, flattened)."""
    import numpy as np

    from ..compile.params import render_params
    from ..kernels.tiles import lane_workspace, render_aovs

    params = render_params(scene, compiled, scene.render)
    render_aovs(compiled.geometry, params._replace(height=0), np.zeros((1, 1), np.float32),
                np.zeros((1, 1, 3), np.float32), np.zeros((1, 1), np.int32),
                lane_workspace(0), 0, 1)


def warm_variants(names: list[str], log: Callable[[str, float], None] = lambda n, s: None
                  ) -> dict[str, float]:
    """Warm each of ``names`` in turn; ``log(name, seconds)`` after each."""
    times = {}
    for name in names:
        times[name] = warm_variant(name)
        log(name, times[name])
    return times
