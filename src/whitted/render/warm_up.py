"""Getting the kernels ready before a render: loaded from the on-disk cache (every run after
the first), or compiled (the first run, or after the kernels changed).

Numba compiles one function at a time in a process, so on a cold cache the first compile is
shared with a second process (``python -m whitted.render.warm_up``) when there are two cores
or more. While this process compiles ``render_tiles`` (and its callees on the way, depth
first), the helper compiles the render kernel's large callees (``kernels/callees.py``), then
the scene builders and the OBJ loader, into the cache; ``render_tiles`` loads those callees
instead of compiling them. Then this process waits for the helper (which by then is on the
builders and loader, work this process would do next) and loads what it made. Whatever the
helper did not finish is compiled here, so the result never depends on the helper: it only
saves time.

A marker file in the cache folder (``whitted-ready-plain`` / ``whitted-ready-instances``)
records that a variant is complete there, so a warm start starts no helper.

Measured on the 2-core VM (fresh cache, the default scene's ``whitted render``): see
docs/performance.md.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

from .._cache import configure_kernel_cache
from ..assets.mesh import load_obj_bytes
from ..compile.params import render_params
from ..compile.scene import CompiledScene, compile_scene
from ..kernels.layout import N_RAY_KINDS
from ..scene.lights import PointLight
from ..scene.scene import Scene
from ..scene.shapes import Mesh, Sphere

_lock = threading.Lock()
_ready: set[bool] = set()  # render kernel variants loaded here: with / without mesh instances
_builders_ready = False
HELPER_WAIT_SECONDS = 120.0  # a helper still busy after this is stopped (never expected)
TINY_OBJ = b"""v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vt 1 0
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
"""


def kernel_variant(compiled: CompiledScene) -> bool:
    """True for the variant of the kernels compiled for scenes with mesh instances."""
    return compiled.geometry.inst_box.dtype == np.float64


def stand_in_scene(instances: bool) -> CompiledScene:
    """Arrays with no geometry but the types of a compiled scene of the given variant: enough
    to compile the render kernels without running any builder."""
    compiled = compile_scene(Scene())
    if instances:
        geometry = compiled.geometry._replace(
            inst_box=compiled.geometry.inst_box.astype(np.float64))
        compiled = dataclasses.replace(compiled, geometry=geometry)
    return compiled


def _builders_scene() -> Scene:
    # a bounded shape, a point light and a smooth mesh: the BVH, light-buffer and normal
    # builders run
    mesh = Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                faces=[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]], smooth=True)
    return Scene(objects=[Sphere(radius=1.0), mesh],
                 lights=[PointLight(position=(0, 5, 0))])


def _compile_builders() -> None:
    """The kernels that load models and build a scene's arrays."""
    global _builders_ready
    if not _builders_ready:
        load_obj_bytes(TINY_OBJ, "warm-up.obj", Path("."))
        scene = _builders_scene()
        compile_scene(scene)  # the mesh flattened into the scene BVH
        compile_scene(scene, flatten_limit=0)  # the mesh instanced
        _builders_ready = True


def _compile_render_kernels(compiled: CompiledScene) -> None:
    from ..kernels.tiles import lane_workspace, render_aovs, render_tiles

    scene = _builders_scene()
    params = render_params(scene, compiled, scene.render.model_copy(update={"width": 1,
                                                                            "height": 1}))
    fb = np.zeros((1, 1, 3), np.float32)
    counters = np.zeros((1, N_RAY_KINDS), np.int64)
    no_tiles = np.zeros((0, 4), np.int32)  # compiles (or loads) without rendering
    render_tiles(no_tiles, fb, compiled.geometry, compiled.materials, compiled.lights,
                 params, counters, lane_workspace(params.max_depth), 0, 1)
    render_aovs(compiled.geometry, params._replace(height=0), np.zeros((1, 1), np.float32),
                np.zeros((1, 1, 3), np.float32), np.zeros((1, 1), np.int32),
                lane_workspace(0), 0, 1)


def _marker(instances: bool) -> Path:
    return Path(configure_kernel_cache()) / (
        "whitted-ready-instances" if instances else "whitted-ready-plain")


def _start_helper(instances: bool) -> subprocess.Popen | None:
    from numba import config

    if (config.DISABLE_JIT or os.environ.get("WHITTED_COMPILE_HELPER", "1") == "0"
            or len(os.sched_getaffinity(0)) < 2):
        return None
    configure_kernel_cache()  # the helper inherits NUMBA_CACHE_DIR
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "whitted.render.warm_up",
             "instances" if instances else "plain"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:  # no interpreter to start (frozen app, exotic platform): compile alone
        return None


def _finish_helper(helper: subprocess.Popen | None) -> None:
    """Wait for the helper (stopping it if it hangs): its last work, the builders and the
    loader, is what this process needs next."""
    if helper is None:
        return
    try:
        helper.wait(HELPER_WAIT_SECONDS)
    except subprocess.TimeoutExpired:
        helper.kill()
        helper.wait()


def warm_up_kernels(compiled: CompiledScene | None = None) -> float:
    """Compile (first run) or load from the on-disk cache (later runs) the render kernels for
    scenes like ``compiled`` (kernels are specialised for scenes with and without mesh
    instances; without when None) and the builders. Returns the seconds it took; 0 when all
    of it was already loaded in this process."""
    with _lock:
        instances = kernel_variant(compiled) if compiled is not None else False
        if instances in _ready and _builders_ready:
            return 0.0
        start = time.perf_counter()
        marker = _marker(instances)
        helper = None if marker.exists() else _start_helper(instances)
        try:
            _compile_render_kernels(compiled if compiled is not None
                                    else stand_in_scene(instances))
        finally:
            _finish_helper(helper)
        _compile_builders()
        marker.touch()
        _ready.add(instances)
        return time.perf_counter() - start


def precompile_for_render(instances: bool) -> None:
    """The helper's work: the render kernel's large callees, then the builders, into the
    on-disk cache."""
    from ..kernels.callees import render_callees

    stand_in = stand_in_scene(instances)
    for dispatcher, argument_types in render_callees(stand_in.geometry, stand_in.materials):
        dispatcher.compile(argument_types)
    _compile_builders()


if __name__ == "__main__":
    precompile_for_render(len(sys.argv) > 1 and sys.argv[1] == "instances")
