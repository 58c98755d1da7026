"""``whitted info``: a scene's objects, lights, bounds and work estimate, or what a model
file holds."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import app, fail, load_scene_argument, with_scene_key
from .console import Text, out


def _model_info(path: Path) -> None:
    """``whitted info MODEL``: what the loader reads from a model file."""
    import numpy as np

    from ..assets import load_mesh

    try:
        mesh = load_mesh(path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    out.print(Text(str(path), style="bold"))
    out.print(f"vertices: {mesh.vertex_records}")
    out.print(f"triangles: {mesh.triangle_records}")
    if len(mesh.vertices) != mesh.vertex_records:
        out.print(f"vertices after splitting by normal/uv: {len(mesh.vertices)}")
    if len(mesh.faces) and len(mesh.vertices):
        used = mesh.vertices[np.unique(mesh.faces)]
        lo = ", ".join(f"{v:.4g}" for v in used.min(axis=0))
        hi = ", ".join(f"{v:.4g}" for v in used.max(axis=0))
        out.print(f"bounds: ({lo}) .. ({hi})")
    else:
        out.print("bounds: no triangles")
    out.print(f"normals: {'yes' if mesh.normals is not None else 'no'}, "
              f"texture coordinates: {'yes' if mesh.uvs is not None else 'no'}")
    counts = np.bincount(mesh.face_material, minlength=len(mesh.materials))
    out.print(f"materials: {len(mesh.materials)}")
    for k, mat in enumerate(mesh.materials):
        colour = ", ".join(f"{c:.3g}" for c in mat.color)
        tex = f" texture={mat.texture.file}" if getattr(mat.texture, "file", None) else ""
        out.print(f"  [{k}] color=({colour}) kt={mat.kt:.3g} triangles={counts[k]}{tex}",
                  highlight=False, markup=False)
    out.print(f"textures: {len(mesh.texture_files)}")
    for file in mesh.texture_files:
        out.print(f"  {file}", highlight=False, markup=False)
    out.print(f"warnings: {len(mesh.warnings)}")
    for warning in mesh.warnings:
        out.print(Text(f"  {warning}"))


@app.command()
def info(
    scene_path: Annotated[
        Path | None, typer.Argument(metavar="[SCENE|MODEL]", help="A scene or a model file")
    ] = None,
) -> None:
    """Print a scene's objects, lights, bounds and an estimate of the work; or what a model
    file (OBJ, PLY, STL, OFF, glTF) holds: vertices, triangles, bounds, materials, textures."""
    import numpy as np

    from ..assets.mesh import SUPPORTED_SUFFIXES
    from ..compile.scene import compile_scene

    if scene_path is not None and scene_path.suffix.lower() in SUPPORTED_SUFFIXES:
        _model_info(scene_path)
        return
    try:
        scene, name = load_scene_argument(scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    try:
        compiled = compile_scene(scene.at_frame(0) if scene.is_animated else scene)
    except WhittedError as exc:  # a model or texture file the scene names is unusable
        raise fail(with_scene_key(exc, scene, name)) from None
    r = scene.render
    out.print(Text(name, style="bold"))
    if scene.animation is not None:
        a = scene.animation
        out.print(f"animation: {a.frames} frames at {a.fps:g} fps ({a.frames / a.fps:.2f} s), "
                  f"{len(a.tracks)} track(s): "
                  + ", ".join(f"{t.path} ({t.interpolation})" for t in a.tracks),
                  markup=False, highlight=False)
    out.print(f"image: {r.width}x{r.height}, {r.samples} sample(s)/pixel, max depth "
              f"{r.max_depth}, min weight {r.min_weight}")
    for line in effect_lines(scene):
        out.print(line, markup=False, highlight=False)
    out.print(f"objects: {len(scene.objects)}")
    for i, obj in enumerate(scene.objects):
        mat = obj.material if isinstance(obj.material, str) else (
            "inline" if obj.material is not None
            else "from the file" if obj.type == "mesh" and getattr(obj, "file", None)
            else "default")
        label = f" '{obj.name}'" if obj.name else ""
        operation = f" {obj.operation}" if obj.type == "csg" else ""
        out.print(f"  [{i}] {obj.type}{operation}{label} material={mat}", markup=False)
        if obj.type == "csg":  # the tree of a CSG object
            for line in obj.tree_lines():
                out.print(line, markup=False, highlight=False)
    out.print(f"lights: {len(scene.lights)}")
    for i, light in enumerate(scene.lights):
        out.print(f"  [{i}] {light.type} intensity={light.intensity}", markup=False)
    out.print(f"materials: {len(compiled.materials)} distinct")
    if np.all(np.isfinite(compiled.bounds_min)):
        lo = ", ".join(f"{v:.3g}" for v in compiled.bounds_min)
        hi = ", ".join(f"{v:.3g}" for v in compiled.bounds_max)
        out.print(f"bounds: ({lo}) .. ({hi}) (infinite planes: {len(compiled.geometry.unbounded)})")
    else:
        out.print("bounds: no bounded objects")
    out.print(f"bvh: {len(compiled.geometry.node_link)} nodes over "
              f"{len(compiled.geometry.node_prims)} primitives")
    if compiled.triangles:
        geo = compiled.geometry
        stored = len(geo.mesh_faces)
        flat = compiled.triangles - stored
        parts = []
        if flat:
            parts.append(f"{flat:,} triangles in the scene BVH")
        if stored:
            traced = ("traced by Embree" if compiled.mesh_tracer == "embree"
                      else f"{len(geo.mesh_nodes):,} mesh BVH nodes")
            parts.append(f"{len(geo.mesh_info)} stored for instancing ({stored:,} triangles, "
                         f"{compiled.instanced_triangles - flat:,} with instances, {traced})")
        out.print("meshes: " + "; ".join(parts))
    for warning in compiled.warnings:
        out.print(Text(f"warning: {warning}"))
    shadow = sum(
        (light.samples or r.shadow_samples) if light.type == "disk" else 1
        for light in scene.lights if light.type != "ambient"
    )
    primary = r.width * r.height * r.samples
    if r.antialias is not None:  # from the pixels' corners to every pixel fully split
        levels = r.antialias.levels
        most = ((r.width << levels) + 1) * ((r.height << levels) + 1)
        rays = f"{(r.width + 1) * (r.height + 1):,} to {most:,} primary rays"
    else:
        rays = f"{primary:,} primary rays"
    photons = r.caustics.photons * r.caustics.passes
    out.print(f"work: {rays}, up to {shadow} shadow ray(s) per hit, "
              f"secondary rays up to depth {r.max_depth}"
              + (f", {photons:,} photons" if photons else ""))


def effect_lines(scene) -> list[str]:
    """What ``whitted info`` says of anti-aliasing, focal blur and caustics: on or off,
    and with what settings."""
    r, cam = scene.render, scene.camera
    aa = r.antialias
    if aa is None:
        lines = [f"anti-aliasing: off ({r.samples} sample(s)/pixel; "
                 "[render.antialias] for adaptive)"]
    else:
        lines = [f"anti-aliasing: adaptive (POV-Ray's method 2), threshold {aa.threshold:g}, "
                 f"up to {aa.max_samples} samples/pixel ({aa.levels} level(s) of splits)"]
    if cam.aperture > 0.0:
        source = ("focal_distance" if cam.focal_distance is not None
                  else "focal_point" if cam.focal_point is not None
                  else "the look_at point" if cam.look_at is not None else "the default")
        lines.append(f"focal blur: aperture {cam.aperture:g}, in focus at {cam.focus():.4g} "
                     f"({source}); each of a pixel's samples through its own point of the lens")
    else:
        lines.append("focal blur: off (camera.aperture = 0)")
    c = r.caustics
    if c.photons == 0:
        lines.append("caustics: off ([render.caustics] photons = 0)")
    else:
        radius = f"radius {c.radius:g}" if c.radius > 0.0 else "radius fitted to the photons"
        lines.append(f"caustics: {c.photons:,} photons x {c.passes:,} pass(es), {radius}, "
                     f"alpha {c.alpha:g}")
    return lines


