"""``whitted bench --compare embree``: the same camera and shadow rays of a mesh scene traced by
whitted's walk and by Embree (through embreex, an optional dependency: ``pip install
'whitted[bench]'``), one thread each, so the table shows how far whitted's mesh walk is from
the state of the art on this machine.

The rays: one camera ray through every pixel centre (whitted's camera, in the render's tile
order), then, from each hit,
one shadow ray toward the scene's first point light, its origin moved 1e-4 toward the light
and its length shortened by as much, so both tracers start clear of the surface. Both get
exactly these rays (Embree in float32, whitted in float64) and the same world: every mesh
with its transform baked in (instances flattened for Embree, which embreex cannot
instance), the ground plane as two large triangles for Embree. Times are thread CPU time,
the best of ``repeats``; the hit and occlusion counts of both are reported so a reader can
see the two traced the same thing.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..scene.scene import Scene

SHADOW_OFFSET = 1e-4
PLANE_HALF_SIZE = 1e6


class EmbreeMissing(ImportError):
    """embreex is not installed."""


def embree_available() -> bool:
    try:
        import embreex.rtcore_scene  # noqa: F401
    except ImportError:
        return False
    return True


def world_triangles(scene: Scene) -> np.ndarray:
    """Every triangle of the scene's meshes and planes in world space, (N, 3, 3) float32."""
    from ..assets.mesh import load_mesh
    from ..scene.shapes import Mesh, Plane

    parts = []
    for obj in scene.objects:
        if isinstance(obj, Mesh):
            if obj.file is not None:
                data = load_mesh(scene.resolve_path(obj.file))
                vertices, faces = data.vertices, data.faces
            else:
                vertices, faces = np.asarray(obj.vertices), np.asarray(obj.faces)
            world = np.asarray(vertices, np.float64)
            if obj.transform is not None:
                matrix = obj.transform.matrix()
                world = world @ matrix[:3, :3].T + matrix[:3, 3]
            parts.append(world[faces].astype(np.float32))
        elif isinstance(obj, Plane):
            n = np.asarray(obj.normal, np.float64)
            n /= np.linalg.norm(n)
            a = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            a /= np.linalg.norm(a)
            b = np.cross(n, a)
            p = np.asarray(obj.point, np.float64)
            c = [p + PLANE_HALF_SIZE * (sa * a + sb * b)
                 for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            parts.append(np.array([[c[0], c[1], c[2]], [c[0], c[2], c[3]]], np.float32))
    return np.concatenate(parts) if parts else np.zeros((0, 3, 3), np.float32)


def _best(fn, repeats: int) -> tuple[float, Any]:
    best, value = float("inf"), None
    for _ in range(repeats):
        start = time.thread_time()
        value = fn()
        best = min(best, time.thread_time() - start)
    return best, value


def compare_embree(scene: Scene, repeats: int = 3) -> dict[str, Any]:
    """Trace the scene's camera and shadow rays with whitted and with Embree; the JSON keys
    ``embree_*``, ``whitted_trace_*`` and ``ratio_embree`` (whitted's rays per second as a
    fraction of Embree's)."""
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError as exc:
        raise EmbreeMissing("--compare embree needs embreex: pip install 'whitted[bench]'") \
            from exc
    from ..compile.embree import embree_library
    from ..scene.lights import PointLight

    lights = [light for light in scene.lights if isinstance(light, PointLight)]
    if not lights:
        raise ValueError("the scene has no point light to cast shadow rays toward")
    light = np.asarray(lights[0].position, np.float64)
    walk = _whitted_trace(scene, light, "whitted", repeats)
    origins, directions = walk.pop("origins"), walk.pop("directions")
    s_origins, s_dirs, s_tmax = walk.pop("s_origins"), walk.pop("s_dirs"), walk.pop("s_tmax")
    n = len(origins)
    result: dict[str, Any] = {f"walk_{k}": v for k, v in walk.items()}
    if embree_library() is not None:  # the render's own Embree path (compile/embree.py)
        traced = _whitted_trace(scene, light, "embree", repeats)
        for key in ("origins", "directions", "s_origins", "s_dirs", "s_tmax"):
            traced.pop(key)
        result.update({f"whitted_embree_{k}": v for k, v in traced.items()})

    start = time.perf_counter()
    triangles = world_triangles(scene)
    embree_scene = rtcore_scene.EmbreeScene()
    TriangleMesh(embree_scene, triangles)
    o32, d32 = origins.astype(np.float32), directions.astype(np.float32)
    embree_scene.run(o32[:1], d32[:1])  # Embree builds its BVH on the first query
    embree_build_s = time.perf_counter() - start
    embree_primary_s, embree_t = _best(
        lambda: embree_scene.run(o32, d32, query="DISTANCE"), repeats)
    so32, sd32 = s_origins.astype(np.float32), s_dirs.astype(np.float32)
    st32 = s_tmax.astype(np.float32)
    embree_shadow_s, embree_blocked = _best(
        lambda: embree_scene.run(so32, sd32, query="OCCLUDED", dists=st32), repeats)

    rays = n + len(s_origins)
    embree_s = embree_primary_s + embree_shadow_s
    embree_rate = rays / embree_s / 1e6 if embree_s > 0 else 0.0
    result.update({
        "embree_rays": rays,
        "embree_triangles": len(triangles),
        "embree_build_s": embree_build_s,
        "embree_primary_s": embree_primary_s,
        "embree_shadow_s": embree_shadow_s,
        "embree_mrays_per_s": embree_rate,
        "embree_hits": int(np.count_nonzero(embree_t < 1e30)),
        "embree_occluded": int(np.count_nonzero(np.asarray(embree_blocked) >= 0)),
    })
    # the headline: what a render uses (Embree inside whitted when it loads, else the walk)
    used = "whitted_embree" if "whitted_embree_trace_s" in result else "walk"
    for key in ("primary_s", "shadow_s", "mrays_per_s", "hits", "occluded"):
        result[f"whitted_trace_{key}"] = result[f"{used}_{key}"]
    result["whitted_mesh_tracer"] = "embree" if used == "whitted_embree" else "whitted"
    for prefix in ("walk", "whitted_embree", "whitted_trace"):
        if f"{prefix}_mrays_per_s" in result:
            result[f"ratio_embree_{prefix}" if prefix != "whitted_trace" else "ratio_embree"] = (
                result[f"{prefix}_mrays_per_s"] / embree_rate if embree_rate > 0
                else float("inf"))
    return result


def _whitted_trace(scene: Scene, light: np.ndarray, tracer: str,
                   repeats: int) -> dict[str, Any]:
    """Camera rays then shadow rays toward ``light`` traced by whitted with its meshes traced
    by ``tracer``: thread CPU seconds (best of ``repeats``), rates, counts, and the rays."""
    from ..compile.params import render_params
    from ..compile.scene import compile_scene
    from ..kernels.tiles import BVH_STACK
    from ..render.warm_up import warm_up_kernels
    from .rays import camera_rays, nearest_hits, occluded

    compiled = compile_scene(scene, mesh_tracer=tracer)
    warm_up_kernels(compiled)
    params = render_params(scene, compiled, scene.render)
    n = scene.render.width * scene.render.height
    origins = np.empty((n, 3))
    directions = np.empty((n, 3))
    camera_rays(params, origins, directions)
    stack = np.empty(BVH_STACK, np.int32)
    geo = compiled.geometry

    t_hit = np.empty(n)
    nearest_hits(geo, origins[:1], directions[:1], t_hit[:1], stack)  # compile or load
    primary_s, _ = _best(lambda: nearest_hits(geo, origins, directions, t_hit, stack),
                         repeats)
    hit = np.isfinite(t_hit)
    points = origins[hit] + t_hit[hit, None] * directions[hit]
    to_light = light - points
    distance = np.linalg.norm(to_light, axis=1)
    s_dirs = to_light / distance[:, None]
    s_origins = points + SHADOW_OFFSET * s_dirs
    s_tmax = distance - SHADOW_OFFSET
    blocked = np.empty(len(s_origins), np.int32)
    occluded(geo, compiled.materials, s_origins[:1], s_dirs[:1], s_tmax[:1], blocked[:1], stack)
    shadow_s, _ = _best(lambda: occluded(geo, compiled.materials, s_origins, s_dirs,
                                         s_tmax, blocked, stack), repeats)
    rays = n + len(s_origins)
    total = primary_s + shadow_s
    return {
        "build_s": compiled.build_seconds,
        "primary_s": primary_s,
        "shadow_s": shadow_s,
        "trace_s": total,
        "mrays_per_s": rays / total / 1e6 if total > 0 else 0.0,
        "hits": int(np.count_nonzero(hit)),
        "occluded": int(np.count_nonzero(blocked)),
        "origins": origins, "directions": directions,
        "s_origins": s_origins, "s_dirs": s_dirs, "s_tmax": s_tmax,
    }
