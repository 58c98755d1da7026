"""The ``whitted`` command: a thin client of the render API."""

from __future__ import annotations

import contextlib
import gc
import os
import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

try:  # typer vendors click from 0.2x on; older releases depend on click itself
    from typer._click.exceptions import UsageError
except ImportError:  # pragma: no cover - depends on the installed typer
    from click.exceptions import UsageError

from ..errors import WhittedError, shorten
from .console import Text, err, out
from .farm import ClusterOption, SchedulerOption, render_still_on_farm

if TYPE_CHECKING:
    import numpy as np
    from pydantic import ValidationError

    from ..scene import Scene

# NumPy, pydantic, rich, the scene models and the renderer are imported inside the commands
# that use them: `whitted --help` and the import of this module stay far under 0.2 s
# (tests/test_startup.py).

app = typer.Typer(
    add_completion=False,
    no_args_is_help=False,
    help="whitted: a fast Whitted ray tracer. Render scene files (TOML/JSON) to images.",
    pretty_exceptions_enable=False,
)

#: The optional scene-file argument of render, export, animate and sweep.
SceneArgument = Annotated[
    Path | None, typer.Argument(metavar="[SCENE]", help="Scene file; default: built-in scene")
]

AOV_NAMES = ("depth", "normal", "id")
EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143  # 128 + SIGTERM
#: After an interrupt during the first compile the render thread is abandoned; the process
#: then ends at once (os._exit) instead of waiting for the compiler to let the interpreter
#: shut down (seconds). A local ``render`` also ends at once once its files are written and
#: its output flushed: tearing down the interpreter (freeing Numba's, LLVM's and NumPy's
#: modules one by one) took 0.1-0.15 s of CPU after the picture was done, and there is
#: nothing left to clean up. Tests that run the command in-process turn this off.
EXIT_AT_ONCE_WHEN_ABANDONED = True
_abandoned: list[bool] = []
_ends_at_once: list[bool] = []  # set by a local render: the process may skip the teardown
#: The longest error line printed (a file may hold a huge key or value: it is cut, not echoed).
MESSAGE_LIMIT = 400


def one_line(message: str) -> str:
    """``message`` as one line of at most :data:`MESSAGE_LIMIT` characters."""
    return shorten(" ".join(str(message).split()), MESSAGE_LIMIT)


def fail(message: str) -> typer.Exit:
    """One line on stderr, exit status 2: the way every user mistake ends. The message is
    printed literally (no rich markup, no emoji codes)."""
    err.print(Text.assemble(("error:", "bold red"), " ", one_line(message)), soft_wrap=True)
    return typer.Exit(EXIT_USER_ERROR)


def _note(message: str) -> None:
    err.print(Text(one_line(message)), soft_wrap=True)


def _version(value: bool) -> None:
    if value:
        from .. import __version__

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
    from ..scene import load_scene
    from ..scene.default import default_scene

    if scene_path is None:
        return default_scene(), "<default scene>"
    return load_scene(scene_path), str(scene_path)


def apply_set_options(scene: Scene, set_values: list[str] | None) -> Scene:
    """The scene with every ``--set PATH=VALUE`` applied (SceneError on a bad one)."""
    if not set_values:
        return scene
    from ..animation.overrides import apply_overrides, parse_assignment

    return apply_overrides(scene, [parse_assignment(text) for text in set_values])


def _is_dir(path: Path) -> bool:
    try:
        return path.is_dir()
    except (OSError, ValueError):  # a name too long, a NUL byte: reported by the checks later
        return False


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
    scene_path: SceneArgument = None,
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
    frame: Annotated[
        int | None, typer.Option("--frame", "-f", help="Frame of an animated scene (from 0)")
    ] = None,
    set_values: Annotated[
        list[str] | None, typer.Option("--set", help="PATH=VALUE: change a scene value")
    ] = None,
    cluster: ClusterOption = None,
    scheduler: SchedulerOption = None,
) -> None:
    """Render SCENE (or the built-in default scene) to an image (PNG, EXR, PFM, NPY, JPEG).
    An animated scene renders frame 0, or the frame --frame names."""
    from pydantic import ValidationError

    from ..output.formats import check_bit_depth, image_format
    from ..render.api import RenderJob

    process_start = time.perf_counter()
    aovs = _parse_aovs(aov)
    if _is_dir(output):
        raise fail(f"{output}: is a directory (give a file name such as {output / 'render.png'})")
    try:
        check_bit_depth(bit_depth, image_format(output))
    except ValueError as exc:
        raise fail(f"{output}: {exc}") from None
    if transfer not in (None, "srgb", "linear"):
        raise fail(f"--transfer: unknown transfer {shorten(transfer)!r} (use srgb or linear)")
    try:
        scene, name = _load(scene_path)
        scene = apply_set_options(scene, set_values)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    try:
        scene = scene.with_settings(width=width, height=height, samples=samples,
                                    max_depth=max_depth, threads=threads, seed=seed,
                                    transfer=transfer)
        if frame is not None or scene.is_animated:
            scene = scene.at_frame(frame or 0)
    except ValidationError as exc:  # a command-line override out of range
        raise fail(_override_error(exc)) from None
    except WhittedError as exc:
        raise fail(str(exc)) from None
    outputs = [output] + [output.with_name(f"{output.stem}.{a}.npy") for a in aovs]
    try:
        from ..output.safety import check_memory, check_outputs

        check_outputs(outputs, scene, scene_path)
        check_memory(scene.render.width, scene.render.height, image_format(output), bit_depth)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    _resume_collector()  # set-up done: the job (or the farm's client) runs with it
    if cluster is not None or scheduler is not None:  # bands on a Dask cluster (cli/farm.py)
        render_still_on_farm(scene, output, cluster=cluster, scheduler=scheduler,
                             threads=threads, quiet=quiet, bit_depth=bit_depth, aovs=aovs)

    try:
        job = RenderJob(scene)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    _ends_at_once.append(True)
    interrupted = threading.Event()
    signals: list[int] = []
    handled = [signal.SIGINT, signal.SIGTERM]
    previous = {sig: signal.getsignal(sig) for sig in handled}

    def on_interrupt(signum, frame) -> None:  # Ctrl-C, SIGTERM: stop after the tiles in flight
        if interrupted.is_set():  # the second one: stop now (a write in progress is undone)
            raise KeyboardInterrupt
        signals.append(signum)
        interrupted.set()
        job.cancel()

    # the handlers stay until the image is written: a signal during the write lets it finish
    for sig in handled:
        signal.signal(sig, on_interrupt)
    try:
        _render_and_write(job, scene, name, output, outputs, aovs, bit_depth, quiet,
                          interrupted, signals, process_start, frame)
    finally:
        for sig in handled:
            signal.signal(sig, previous[sig])


def _render_and_write(job, scene, name, output, outputs, aovs, bit_depth, quiet, interrupted,
                      signals, process_start, frame: int | None) -> None:
    from ..output.formats import image_format
    from ..render.api import render_aovs

    try:
        _run_with_progress(job, quiet, interrupted)
    except WhittedError as exc:  # a model or texture file the scene names is unusable
        raise fail(_with_scene_key(exc, scene, name)) from None
    exit_code = EXIT_TERMINATED if signal.SIGTERM in signals else EXIT_INTERRUPTED
    stats = job.stats
    if interrupted.is_set() and (job.running or stats.tiles_done == 0):
        # stopped while compiling, or before any tile was finished: there is nothing to keep,
        # and an existing file at the output path is left as it was
        what = "terminated" if signal.SIGTERM in signals else "interrupted"
        _note(f"{what} before any tile was finished: nothing written ({output} is unchanged)")
        if job.running:
            _abandoned.append(True)
        raise typer.Exit(exit_code)
    image = job.image
    assert image is not None
    for warning in stats.warnings:
        err.line(f"warning: {warning}")
    written = [str(output)]
    try:
        if frame is not None and not interrupted.is_set() and bit_depth == 8 \
                and image_format(output) == "png":  # the very file the film's frame K is
            from ..animation.frames import frame_digest, write_frame_png

            write_frame_png(output, image, frame_digest(scene, frame), frame)
        else:
            image.save(output, bit_depth=bit_depth)
        if aovs and not interrupted.is_set():
            planes = render_aovs(scene)
            for path, aov_name in zip(outputs[1:], aovs, strict=True):
                _save_npy(path, planes[aov_name])
                written.append(str(path))
    except OSError as exc:
        raise fail(f"{getattr(exc, 'filename', None) or output}: cannot write: "
                   f"{exc.strerror or exc}") from None
    except WhittedError as exc:
        raise fail(str(exc)) from None
    stats.wall_seconds = time.perf_counter() - process_start
    if not quiet or interrupted.is_set():
        out.line(f"{stats.summary()} -> {', '.join(written)}")
    if interrupted.is_set():  # (a signal may have come during the write)
        what = "terminated" if signal.SIGTERM in signals else "interrupted"
        _note(f"{what}: kept {stats.tiles_done}/{stats.tiles_total} tiles in {output}")
        raise typer.Exit(EXIT_TERMINATED if signal.SIGTERM in signals else EXIT_INTERRUPTED)


def _with_scene_key(exc: WhittedError, scene: Scene, name: str) -> str:
    """A model or texture error from the render, with the scene file and key that name it."""
    from ..scene.writing import named_files

    file = getattr(exc, "file", None)
    if not file or file == name:
        return str(exc)
    for keys, named in named_files(scene):
        try:
            target = scene.resolve_path(named)
        except (OSError, RuntimeError, ValueError):
            continue
        from ..files import same_file

        if same_file(target, file) or str(target) == file:
            where = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in keys).lstrip(".")
            return f"{name}: {where}: {exc}"
    return f"{name}: {exc}"


def _save_npy(path: Path, array: np.ndarray) -> None:
    import numpy as np

    from ..files import atomic_write

    atomic_write(path, lambda tmp: np.save(tmp, array))


def _override_error(exc: ValidationError) -> str:
    """One line for a command-line value the render settings reject."""
    from ..scene.messages import clean_message as _clean_message

    e = exc.errors()[0]
    if e["loc"]:
        option = "--" + str(e["loc"][0]).replace("_", "-")
    else:  # the only whole-settings check is the image size
        option = "--width/--height"
    return f"{option}: {_clean_message(e)}"


def _wait(job, interrupted: threading.Event, tick=None, until: float | None = None) -> bool:
    """Wait for the job; after an interrupt, stop waiting at once if no tile is being rendered
    yet (the first compile of the kernels takes many seconds and cannot be cut short).
    ``tick()`` is called every tenth of a second meanwhile. With ``until`` (a
    ``time.monotonic()`` deadline), False when the job is still running then."""
    while job.running:
        left = 0.1 if until is None else min(0.1, until - time.monotonic())
        if left <= 0:
            return False
        job.join(left)
        if tick is not None:
            tick()
        if interrupted.is_set() and not job.rendering:
            return True
    job.wait()
    return True


#: seconds a render runs before its progress bar appears: a shorter one would only flash it
#: (and a render of the timing scene would spend 40 ms importing rich's progress display);
#: ``WHITTED_PROGRESS_DELAY`` (seconds) overrides it, 0 shows the bar at once
PROGRESS_DELAY = 0.4


def _progress_delay() -> float:
    try:
        value = float(os.environ["WHITTED_PROGRESS_DELAY"])
    except (KeyError, ValueError):
        return PROGRESS_DELAY
    return value if value >= 0 else PROGRESS_DELAY


def _show_compile(bar, task) -> None:
    """While the first run compiles the kernels, the bar says so and how far along it is."""
    from ..render.warm_up import compile_progress

    fraction = compile_progress()
    if fraction is not None:
        bar.update(task, description="compiling the kernels (first run only)",
                   completed=fraction)


def _run_with_progress(job, quiet: bool, interrupted: threading.Event) -> None:
    job.start()
    if quiet or not err.is_terminal:
        _wait(job, interrupted)
        return
    if _wait(job, interrupted, until=time.monotonic() + _progress_delay()):
        return
    from rich.progress import (
        BarColumn,
        Progress,
        TaskProgressColumn,
        TextColumn,
        TimeRemainingColumn,
    )

    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[rays]} rays"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=err.console, transient=True) as bar:
        task = bar.add_task("rendering", total=1.0, rays="0")

        def update(p) -> None:
            bar.update(task, description="rendering", completed=p.fraction, rays=f"{p.rays:,}")

        job.progress = update  # read by the job at each report: taken up from now on
        _wait(job, interrupted, lambda: _show_compile(bar, task))


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
        scene, name = _load(scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    try:
        compiled = compile_scene(scene.at_frame(0) if scene.is_animated else scene)
    except WhittedError as exc:  # a model or texture file the scene names is unusable
        raise fail(_with_scene_key(exc, scene, name)) from None
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
    out.print(f"work: {primary:,} primary rays, up to {shadow} shadow ray(s) per hit, "
              f"secondary rays up to depth {r.max_depth}")


@app.command()
def export(
    scene_path: SceneArgument = None,
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="File to write; default: SCENE.pov")
    ] = None,
    export_format: Annotated[str, typer.Option("--format", "-f", help="Only 'pov'")] = "pov",
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
) -> None:
    """Write SCENE for another renderer: POV-Ray 3.7 scene language (--format pov)."""
    from pydantic import ValidationError

    from ..export.pov import export_pov

    if export_format != "pov":
        raise fail(f"--format: unknown format {export_format!r} (known: pov)")
    try:
        scene, name = _load(scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    try:
        scene = scene.with_settings(width=width, height=height)
        if scene.is_animated:  # POV-Ray gets the first frame, mesh sequences named
            scene = scene.at_frame(0)
    except ValidationError as exc:
        raise fail(_override_error(exc)) from None
    if output is None:  # the whole stem: scene.v1.toml -> scene.v1.pov
        output = Path((scene_path.stem if scene_path else "default") + ".pov")
    try:
        export_pov(scene, output, source=str(scene_path) if scene_path else name)
    except WhittedError as exc:
        raise fail(_with_scene_key(exc, scene, name)) from None
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None
    r = scene.render
    out.print(Text(f"{name} -> {output} (POV-Ray 3.7; render with: povray +I{output} "
                   f"+W{r.width} +H{r.height} -A)"))


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
    from ..bench.scenes import SCENES

    for name in scene or []:  # checked before the header line: a mistake is one line
        if name not in SCENES and not name.startswith("generated/"):
            raise fail(f"--scene: unknown benchmark scene {shorten(name)!r} "
                       f"(known: {', '.join(SCENES)})")
    from ..output.safety import check_output_place

    for option, path in (("--json", json_path), ("--plot", plot), ("--markdown", markdown)):
        try:
            if path is not None:
                check_output_place(path)
        except WhittedError as exc:
            raise fail(f"{option}: {exc}") from None
    try:
        bench_main(scenes=scene, runs=runs, threads=threads, quick=quick, compare=compare,
                   study=study, json_path=json_path, plot_path=plot, markdown_path=markdown,
                   size=size, in_process=in_process, out=out, err=err)
    except WhittedError as exc:
        raise fail(str(exc)) from None


#: whether main() paused the cyclic garbage collector for a render's set-up (a list: set once)
_collector_paused: list[bool] = []


def _resume_collector() -> None:
    """The cyclic garbage collector, paused by main() while ``whitted render`` imports its
    modules and reads its scene (some 90 collections, 10-15 ms of a 0.57 s render, finding
    next to nothing: modules, classes and the scene all live to the end), back on for the job,
    with everything made so far frozen (``gc.freeze``), so later collections never scan it."""
    if _collector_paused:
        _collector_paused.clear()
        gc.freeze()
        gc.enable()


def main() -> None:
    """Console entry point: usage mistakes end as one ``error:`` line and status 2; nothing
    ends in a traceback (set WHITTED_DEBUG=1 to see one for an internal error)."""
    if len(sys.argv) > 1 and sys.argv[1] == "render" and gc.isenabled():
        gc.disable()  # until the render's set-up is done: _resume_collector
        _collector_paused.append(True)

    # No BLAS thread pool: the commands' NumPy work is small matrices and element-wise
    # arithmetic (the renderer's threads are Numba's), and starting OpenBLAS's pool made
    # importing NumPy 0.05 s slower on a 2-core machine. A user's own setting is kept.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    _abandoned.clear()
    _ends_at_once.clear()
    try:
        with only_the_command_named(sys.argv):
            code = app(standalone_mode=False)
        if (_abandoned or _ends_at_once) and EXIT_AT_ONCE_WHEN_ABANDONED:
            _exit_now(code if isinstance(code, int) else 0)
    except UsageError as exc:
        command = "whitted" if exc.ctx is None or exc.ctx.parent is None else (
            f"whitted {exc.ctx.info_name}"
        )
        hint = f" (see '{command} --help')"
        err.print(Text.assemble(("error:", "bold red"), " ",
                                one_line(exc.format_message()) + hint), soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except typer.Abort:
        sys.exit(EXIT_INTERRUPTED)
    except KeyboardInterrupt:
        sys.exit(EXIT_INTERRUPTED)
    except typer.Exit as exc:  # raised with standalone_mode=False only by an eager callback
        sys.exit(exc.exit_code)
    except WhittedError as exc:  # a user mistake a command did not catch itself
        err.print(Text.assemble(("error:", "bold red"), " ", one_line(str(exc))), soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except MemoryError:
        err.print(Text.assemble(("error:", "bold red"), " ", "out of memory"), soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except Exception as exc:  # noqa: BLE001 - a bug: one line, the traceback on request
        if os.environ.get("WHITTED_DEBUG"):
            raise
        err.print(Text.assemble(("internal error:", "bold red"), " ", one_line(
            f"{type(exc).__name__}: {exc} (please report it; WHITTED_DEBUG=1 shows the "
            "traceback)")), soft_wrap=True)
        sys.exit(1)
    finally:
        _resume_collector()  # a render that ended before its job (a usage error), a caller
    sys.exit(code if isinstance(code, int) else 0)


def _command_name(info: typer.models.CommandInfo) -> str:
    return info.name or typer.main.get_command_name(info.callback.__name__)


@contextlib.contextmanager
def only_the_command_named(argv: list[str]):
    """While ``app`` runs: only the command ``argv`` names, when its first argument names
    one. Before it dispatches, typer makes a click command of every registered command,
    evaluating each parameter's annotation: 18 ms of every run for whitted's eight, against
    about 3 ms for one. Anything else (no argument, an option first, the ``stefan`` group, a
    misspelt command) keeps them all, so ``whitted --help`` and typer's suggestions are whole;
    a command's own help and errors are the same either way (tests/test_cli.py)."""
    chosen = [info for info in app.registered_commands
              if len(argv) > 1 and _command_name(info) == argv[1]]
    if len(chosen) != 1:
        yield
        return
    saved = app.registered_commands, app.registered_groups
    app.registered_commands, app.registered_groups = chosen, []
    try:
        yield
    finally:
        app.registered_commands, app.registered_groups = saved


def _exit_now(code: int) -> None:
    """End the process now (output flushed), not waiting for an abandoned render thread."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
    os._exit(code)


# Commands in their own modules register themselves on `app` when imported.
from . import animate as _animate  # noqa: E402, F401
from . import stefan as _stefan  # noqa: E402, F401
from . import sweep as _sweep  # noqa: E402, F401
