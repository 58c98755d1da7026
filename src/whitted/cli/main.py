"""The ``whitted`` command: a thin client of the render API."""

from __future__ import annotations

import signal
import sys
import threading
import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from pydantic import ValidationError
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeRemainingColumn

try:  # typer vendors click from 0.2x on; older releases depend on click itself
    from typer._click.exceptions import UsageError
except ImportError:  # pragma: no cover - depends on the installed typer
    from click.exceptions import UsageError

from .. import __version__
from ..errors import WhittedError
from ..scene import Scene, load_scene
from ..scene.default import default_scene

app = typer.Typer(
    add_completion=False,
    no_args_is_help=False,
    help="whitted: a fast Whitted ray tracer. Render scene files (TOML/JSON) to images.",
    pretty_exceptions_enable=False,
)
err = Console(stderr=True, highlight=False, soft_wrap=True)
out = Console(highlight=False, soft_wrap=True)

AOV_NAMES = ("depth", "normal", "id")
EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130


def fail(message: str) -> typer.Exit:
    """One line on stderr, exit status 2: the way every user mistake ends."""
    err.print(f"[bold red]error:[/] {escape(message)}", soft_wrap=True)
    return typer.Exit(EXIT_USER_ERROR)


def _version(value: bool) -> None:
    if value:
        out.print(f"whitted {__version__}")
        raise typer.Exit()


@app.callback()
def main_options(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Show the version.")
    ] = False,
) -> None:
    """whitted: a fast Whitted ray tracer."""


def _load(scene_path: Path | None) -> tuple[Scene, str]:
    if scene_path is None:
        return default_scene(), "<default scene>"
    return load_scene(scene_path), str(scene_path)


def _parse_aovs(text: str | None) -> list[str]:
    if not text:
        return []
    names = [n.strip() for n in text.split(",") if n.strip()]
    for n in names:
        if n not in AOV_NAMES:
            raise fail(f"--aov: unknown AOV {n!r} (choose from {', '.join(AOV_NAMES)})")
    return names


@app.command()
def render(
    scene_path: Annotated[
        Path | None, typer.Argument(metavar="[SCENE]", help="Scene file; default: built-in scene")
    ] = None,
    output: Annotated[Path, typer.Option("-o", "--output", help="Image to write")] = Path(
        "render.png"
    ),
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
    samples: Annotated[int | None, typer.Option("--samples", "-s", help="Samples/pixel")] = None,
    max_depth: Annotated[int | None, typer.Option("--max-depth", "-d", help="Recursion")] = None,
    threads: Annotated[int | None, typer.Option("--threads", "-t", help="0 = all cores")] = None,
    seed: Annotated[int | None, typer.Option("--seed", help="Random seed")] = None,
    aov: Annotated[str | None, typer.Option("--aov", help="Also write depth,normal,id")] = None,
    bit_depth: Annotated[int, typer.Option("--bit-depth", help="PNG bits: 8 or 16")] = 8,
    transfer: Annotated[
        str | None, typer.Option("--transfer", help="srgb or linear (default: the scene's)")
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar")] = False,
) -> None:
    """Render SCENE (or the built-in default scene) to an image (PNG, EXR, PFM, NPY, JPEG)."""
    from ..output.encode import check_bit_depth, image_format
    from ..render.api import RenderJob, render_aovs

    process_start = time.perf_counter()
    aovs = _parse_aovs(aov)
    try:
        image_format(output)
        check_bit_depth(bit_depth, output)
    except ValueError as exc:
        raise fail(f"{output}: {exc}") from None
    if transfer not in (None, "srgb", "linear"):
        raise fail(f"--transfer: unknown transfer {transfer!r} (use srgb or linear)")
    try:
        scene, name = _load(scene_path)
        scene = scene.with_settings(width=width, height=height, samples=samples,
                                    max_depth=max_depth, threads=threads, seed=seed,
                                    transfer=transfer)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:  # a command-line override out of range
        raise fail(_override_error(exc)) from None
    if not output.parent.exists():
        raise fail(f"{output}: the folder {output.parent} does not exist")

    job = RenderJob(scene)
    interrupted = threading.Event()
    previous = signal.getsignal(signal.SIGINT)

    def on_interrupt(signum, frame) -> None:  # Ctrl-C: stop after the tiles in flight
        interrupted.set()
        job.cancel()

    signal.signal(signal.SIGINT, on_interrupt)
    try:
        _run_with_progress(job, quiet)
    except WhittedError as exc:  # a model or texture file the scene names is unusable
        raise fail(str(exc)) from None
    finally:
        signal.signal(signal.SIGINT, previous)
    image = job.image
    assert image is not None
    stats = job.stats
    for warning in stats.warnings:
        err.print(f"warning: {warning}", markup=False, highlight=False)
    image.save(output, bit_depth=bit_depth)
    written = [str(output)]
    if aovs and not interrupted.is_set():
        planes = render_aovs(scene)
        for aov_name in aovs:
            path = output.with_name(f"{output.stem}.{aov_name}.npy")
            _save_npy(path, planes[aov_name])
            written.append(str(path))
    stats.wall_seconds = time.perf_counter() - process_start
    if not quiet or interrupted.is_set():
        out.print(f"{stats.summary()} -> {', '.join(written)}")
    if interrupted.is_set():
        err.print(f"interrupted: kept {stats.tiles_done}/{stats.tiles_total} tiles in {output}")
        raise typer.Exit(EXIT_INTERRUPTED)


def _save_npy(path: Path, array: np.ndarray) -> None:
    from ..output.encode import atomic_write

    atomic_write(path, lambda tmp: np.save(tmp, array))


def _override_error(exc: ValidationError) -> str:
    """One line for a command-line value the render settings reject."""
    from ..scene.io import _clean_message

    e = exc.errors()[0]
    if e["loc"]:
        option = "--" + str(e["loc"][0]).replace("_", "-")
    else:  # the only whole-settings check is the image size
        option = "--width/--height"
    return f"{option}: {_clean_message(e)}"


def _run_with_progress(job, quiet: bool) -> None:
    if quiet or not err.is_terminal:
        job.start()
        while job.wait(0.1) is None and job.running:
            pass
        job.wait()
        return
    columns = (
        TextColumn("[bold]rendering"),
        BarColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[rays]} rays"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=err, transient=True) as bar:
        task = bar.add_task("render", total=1.0, rays="0")

        def update(p) -> None:
            bar.update(task, completed=p.fraction, rays=f"{p.rays:,}")

        job.progress = update
        job.start()
        while job.wait(0.1) is None and job.running:
            pass
        job.wait()


def _model_info(path: Path) -> None:
    """``whitted info MODEL``: what the loader reads from a model file."""
    from ..assets import load_mesh

    try:
        mesh = load_mesh(path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    out.print(f"[bold]{path}[/]", highlight=False)
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
                  highlight=False)
    out.print(f"textures: {len(mesh.texture_files)}")
    for file in mesh.texture_files:
        out.print(f"  {file}", highlight=False)
    out.print(f"warnings: {len(mesh.warnings)}")
    for warning in mesh.warnings:
        out.print(f"  {warning}", markup=False, highlight=False)


@app.command()
def info(
    scene_path: Annotated[
        Path | None, typer.Argument(metavar="[SCENE|MODEL]", help="A scene or a model file")
    ] = None,
) -> None:
    """Print a scene's objects, lights, bounds and an estimate of the work; or what a model
    file (OBJ, PLY, STL, OFF, glTF) holds: vertices, triangles, bounds, materials, textures."""
    from ..assets.mesh import SUPPORTED_SUFFIXES
    from ..compile.flatten import compile_scene

    if scene_path is not None and scene_path.suffix.lower() in SUPPORTED_SUFFIXES:
        _model_info(scene_path)
        return
    try:
        scene, name = _load(scene_path)
        compiled = compile_scene(scene)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    r = scene.render
    out.print(f"[bold]{name}[/]")
    out.print(f"image: {r.width}x{r.height}, {r.samples} sample(s)/pixel, max depth "
              f"{r.max_depth}, min weight {r.min_weight}")
    out.print(f"objects: {len(scene.objects)}")
    for i, obj in enumerate(scene.objects):
        mat = obj.material if isinstance(obj.material, str) else (
            "inline" if obj.material is not None
            else "from the file" if obj.type == "mesh" and getattr(obj, "file", None)
            else "default")
        label = f" '{obj.name}'" if obj.name else ""
        out.print(f"  [{i}] {obj.type}{label} material={mat}")
    out.print(f"lights: {len(scene.lights)}")
    for i, light in enumerate(scene.lights):
        out.print(f"  [{i}] {light.type} intensity={light.intensity}")
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
            parts.append(f"{len(geo.mesh_info)} stored for instancing ({stored:,} triangles, "
                         f"{compiled.instanced_triangles - flat:,} with instances, "
                         f"{len(geo.mesh_nodes):,} mesh BVH nodes)")
        out.print("meshes: " + "; ".join(parts))
    for warning in compiled.warnings:
        out.print(f"warning: {warning}", markup=False, highlight=False)
    shadow = sum(
        (light.samples or r.shadow_samples) if light.type == "disk" else 1
        for light in scene.lights if light.type != "ambient"
    )
    primary = r.width * r.height * r.samples
    out.print(f"work: {primary:,} primary rays, up to {shadow} shadow ray(s) per hit, "
              f"secondary rays up to depth {r.max_depth}")


@app.command()
def gui(
    scene_path: Annotated[
        Path | None, typer.Argument(metavar="[SCENE]", help="Scene file; a new one if missing")
    ] = None,
) -> None:
    """Open the scene editor (a desktop window) on SCENE, or on the built-in default scene."""
    scene = None
    if scene_path is not None and scene_path.exists():
        try:
            scene = load_scene(scene_path)
        except WhittedError as exc:
            raise fail(str(exc)) from None
    elif scene_path is not None and scene_path.suffix.lower() not in (".toml", ".json"):
        raise fail(f"{scene_path}: unknown scene format {scene_path.suffix!r} (use .toml or .json)")
    try:  # Qt is imported here only, so the other commands start without it
        from ..gui.app import run_editor
    except ImportError as exc:
        raise fail(f"the editor needs PySide6 (pip install PySide6-Essentials): {exc}") from None
    raise typer.Exit(run_editor(scene, scene_path))


@app.command()
def export(
    scene_path: Annotated[
        Path | None, typer.Argument(metavar="[SCENE]", help="Scene file; default: built-in scene")
    ] = None,
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="File to write; default: SCENE.pov")
    ] = None,
    export_format: Annotated[str, typer.Option("--format", "-f", help="Only 'pov'")] = "pov",
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
) -> None:
    """Write SCENE for another renderer: POV-Ray 3.7 scene language (--format pov)."""
    from ..export.pov import export_pov

    if export_format != "pov":
        raise fail(f"--format: unknown format {export_format!r} (known: pov)")
    try:
        scene, name = _load(scene_path)
        scene = scene.with_settings(width=width, height=height)
        if output is None:
            output = Path(scene_path.stem if scene_path else "default").with_suffix(".pov")
        if not output.parent.exists():
            raise fail(f"{output}: the folder {output.parent} does not exist")
        export_pov(scene, output, source=name)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:
        raise fail(_override_error(exc)) from None
    r = scene.render
    out.print(f"{name} -> {output} (POV-Ray 3.7; render with: povray +I{output} "
              f"+W{r.width} +H{r.height} -A)")


@app.command()
def bench(
    scene: Annotated[
        list[str] | None, typer.Option("--scene", help="Scene(s): seed000, softshadow, ice, "
                                       "mesh1m, lecture (default: all)")
    ] = None,
    runs: Annotated[int, typer.Option("--runs", "-n", help="Timed runs; the median")] = 5,
    threads: Annotated[
        str | None, typer.Option("--threads", "-t", help="Thread counts, e.g. 1,2 (all cores)")
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Tiny images, one run (CI)")] = False,
    compare: Annotated[str | None, typer.Option("--compare", help="Also time: povray")] = None,
    study: Annotated[str | None, typer.Option("--study", help="threads or size")] = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write results")] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Study plot (PNG)")] = None,
    markdown: Annotated[Path | None, typer.Option("--markdown", help="Table as Markdown")] = None,
    size: Annotated[str | None, typer.Option("--size", help="WxH for every scene")] = None,
    in_process: Annotated[
        bool, typer.Option("--in-process", help="Render in this process, not a fresh one")
    ] = False,
) -> None:
    """Render the benchmark scenes (benchmarks/) and print times, rays and memory."""
    from ..bench.command import bench_main

    try:
        bench_main(scenes=scene, runs=runs, threads=threads, quick=quick, compare=compare,
                   study=study, json_path=json_path, plot_path=plot, markdown_path=markdown,
                   size=size, in_process=in_process, out=out, err=err)
    except WhittedError as exc:
        raise fail(str(exc)) from None


from .stefan import register as _register_stefan  # noqa: E402 - after the commands above

_register_stefan(app)


def main() -> None:
    """Console entry point: usage mistakes end as one ``error:`` line and status 2."""
    try:
        code = app(standalone_mode=False)
    except UsageError as exc:
        command = "whitted" if exc.ctx is None or exc.ctx.parent is None else (
            f"whitted {exc.ctx.info_name}"
        )
        hint = f" (see '{command} --help')"
        err.print(f"[bold red]error:[/] {escape(exc.format_message())}{hint}", soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except typer.Abort:
        sys.exit(EXIT_INTERRUPTED)
    except KeyboardInterrupt:
        sys.exit(EXIT_INTERRUPTED)
    sys.exit(code if isinstance(code, int) else 0)
