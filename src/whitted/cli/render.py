"""``whitted render``: one still, with a progress bar on a terminal, Ctrl-C and SIGTERM keeping
the tiles finished (cli/interrupt.py), AOVs beside it, or bands on a farm (cli/farm.py)."""

from __future__ import annotations

import contextlib
import math
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError, shorten
from .app import (
    SceneArgument,
    abandoned,
    app,
    apply_set_options,
    check_default_output,
    check_side_files,
    ends_at_once,
    fail,
    is_dir,
    load_scene_argument,
    note,
    override_error,
    resume_collector,
    save_npy,
    with_options,
    with_scene_key,
)
from .console import err, out
from .farm import ClusterOption, SchedulerOption, render_still_on_farm
from .interrupt import InterruptGuard
from .region import parse_region

AOV_NAMES = ("depth", "normal", "id")


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
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="Image to write [default: render.png]")] = None,
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
    region: Annotated[str | None, typer.Option(
        "--region", help="Render only X0:X1,Y0:Y1 (pixels, or fractions such as "
        "0.25:0.75) into the full-size image")] = None,
    alpha: Annotated[bool, typer.Option(
        "--alpha", help="Alpha channel, 0 where nothing is hit (.png .tif .webp .exr .npy)"
    )] = False,
    exposure: Annotated[float, typer.Option(
        "--exposure", help="Exposure in stops: the image times 2^EV")] = 0.0,
    quality: Annotated[int | None, typer.Option(
        "--quality", help="JPEG or WebP quality, 1-100 (default: JPEG 95, WebP lossless)"
    )] = None,
    resume: Annotated[bool, typer.Option(
        "--continue", help="Finish an interrupted render from the tiles it kept")] = False,
    turntable: Annotated[int | None, typer.Option(
        "--turntable", help="A film instead: N frames of the camera going once around "
        "(whitted animate --turntable; -o NAME.mp4 or .gif, default SCENE_turntable.mp4)",
        min=1, max=1_000_000)] = None,
    cluster: ClusterOption = None,
    scheduler: SchedulerOption = None,
) -> None:
    """Render SCENE (or the built-in default scene) to an image: PNG, JPEG, TIFF, WebP,
    EXR, PFM or NPY, chosen by the name given to -o. An animated scene renders frame 0, or
    the frame --frame names; an interrupted render (Ctrl-C) keeps its finished tiles, and
    --continue finishes it. A model file is shown on a lit ground by a camera that frames
    it."""
    from .. import marks

    marks.mark("command")  # the imports and the command line's parsing are done
    from pydantic import ValidationError

    if turntable is not None:
        stills_only = [name for name, given in (
            ("--aov", aov), ("--frame", frame is not None), ("--bit-depth", bit_depth != 8),
            ("--transfer", transfer), ("--region", region), ("--alpha", alpha),
            ("--exposure", exposure != 0.0), ("--quality", quality is not None),
            ("--continue", resume)) if given]
        if stills_only:
            raise fail(f"--turntable makes a film: {', '.join(stills_only)} only apply to a "
                       "still")
        _turntable_film(scene_path, output, turntable, width, height, samples, max_depth,
                        threads, seed, set_values, quiet, cluster, scheduler)
        return
    named = output is not None
    output = output or Path("render.png")

    from ..output.formats import check_bit_depth, check_image_options, image_format
    from ..render.api import DEFAULT_TILE, RenderJob
    from ..render.warm_up import cold_compile_ahead

    process_start = time.perf_counter()
    aovs = _parse_aovs(aov)
    if is_dir(output):
        raise fail(f"{output}: is a directory (give a file name such as {output / 'render.png'})")
    if not named:
        check_default_output(output)
    if bit_depth not in (8, 16):
        raise fail(f"--bit-depth: must be 8 or 16 (got {bit_depth})")
    try:
        kind = image_format(output)
    except ValueError as exc:
        raise fail(f"{output}: {exc}") from None
    try:
        check_bit_depth(bit_depth, kind)
    except ValueError:
        raise fail(f"{output}: --bit-depth 16 is only for .png output (got {kind}: .jpg, "
                   ".tif and .webp have 8 bits, .exr, .pfm and .npy store float32)") from None
    try:
        check_image_options(kind, alpha=alpha)
    except ValueError as exc:
        raise fail(f"{output}: {exc}") from None
    try:
        check_image_options(image_format(output), quality=quality)
    except ValueError as exc:
        raise fail(f"--quality: {exc}") from None
    if not math.isfinite(exposure) or abs(exposure) > MAX_EXPOSURE:
        raise fail(f"--exposure: {exposure:g} stops is not a finite number from "
                   f"-{MAX_EXPOSURE} to {MAX_EXPOSURE}")
    if transfer not in (None, "srgb", "linear"):
        raise fail(f"--transfer: unknown transfer {shorten(transfer)!r} (use srgb or linear)")
    try:
        scene, name = load_scene_argument(scene_path, width=width, height=height)
        scene = apply_set_options(scene, set_values)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    scene = with_options(scene, width=width, height=height, samples=samples,
                         max_depth=max_depth, threads=threads, seed=seed, transfer=transfer)
    try:
        if frame is not None or scene.is_animated:
            scene = scene.at_frame(frame or 0)
    except ValidationError as exc:
        raise fail(override_error(exc)) from None
    except WhittedError as exc:
        raise fail(str(exc)) from None
    pixels_region = None
    if region is not None:
        try:
            pixels_region = parse_region(region, scene.render.width, scene.render.height)
        except ValueError as exc:
            raise fail(f"--region: {exc}") from None
    outputs = [output] + [output.with_name(f"{output.stem}.{a}.npy") for a in aovs]
    farm = cluster is not None or scheduler is not None
    # a cold kernel cache: the compile helper starts now and compiles its share of the
    # render kernel while the output checks read the scene's models (compiling the OBJ
    # reader in this process); stopped if the command ends before its render adopts it
    with contextlib.nullcontext() if farm else cold_compile_ahead(scene):
        try:
            from ..output.safety import check_memory, check_outputs

            check_outputs(outputs, scene, scene_path)
            check_memory(scene.render.width, scene.render.height, image_format(output),
                         bit_depth)
        except WhittedError as exc:
            raise fail(str(exc)) from None
        check_side_files(outputs[1:])  # the AOVs: names the user did not give
        resume_collector()  # set-up done: the job (or the farm's client) runs with it
        if farm and (region is not None or alpha or resume or exposure or quality is not None):
            raise fail("--region, --alpha, --exposure, --quality and --continue render here, not "
                       "on a cluster (leave out --cluster/--scheduler)")
        if farm:  # bands on a Dask cluster (cli/farm.py)
            render_still_on_farm(scene, output, cluster=cluster, scheduler=scheduler,
                                 threads=threads, quiet=quiet, bit_depth=bit_depth, aovs=aovs,
                                 frame=frame)

        from .tile_state import job_digest, state_path

        kept = state_path(output)
        digest = job_digest(scene, frame or 0, pixels_region, DEFAULT_TILE)
        earlier = _kept_tiles(kept, digest, scene) if resume else None
        try:
            job = RenderJob(scene, region=pixels_region, resume=earlier)
        except WhittedError as exc:
            raise fail(str(exc)) from None
        ends_at_once.append(True)
        finish = StillFinish(pixels_region, alpha, exposure, quality, kept, digest)
        # Ctrl-C, SIGTERM: stop after the tiles in flight (cli/interrupt.py); the handlers stay
        # until the image is written: a signal during the write lets it finish
        with InterruptGuard() as guard:
            guard.on_interrupt(job.cancel)
            _render_and_write(job, scene, name, output, outputs, aovs, bit_depth, quiet, guard,
                              process_start, frame, finish)


#: the widest --exposure, in stops (2^64 times brighter or darker is far beyond any use)
MAX_EXPOSURE = 64


@dataclass
class StillFinish:
    """What ``whitted render`` does to the picture after the tiles: the region, alpha,
    exposure and quality options, and the tile state file of an interrupted render."""

    region: tuple[int, int, int, int] | None
    alpha: bool
    exposure: float
    quality: int | None
    state: Path
    digest: str


def _kept_tiles(path: Path, digest: str, scene):
    """The tiles an interrupted render of this very job kept, for --continue (None: none,
    and the whole picture is rendered; a damaged or foreign state file is one line)."""
    from .tile_state import StateError, load_state

    r = scene.render
    try:
        state = load_state(path, max_bytes=64 + 2 * 12 * r.width * r.height + (1 << 24))
    except StateError as exc:
        raise fail(f"--continue: {path}: {exc} (render without --continue to start over)") \
            from None
    if state is None:
        note(f"--continue: no kept tiles at {path}: rendering the whole picture")
        return None
    if state.digest != digest:
        raise fail(f"--continue: {path} holds tiles of another scene, settings or region "
                   "(render without --continue to start over)")
    return state.finished, state.framebuffer


def _turntable_film(scene_path, output, frames, width, height, samples, max_depth, threads,
                    seed, set_values, quiet, cluster, scheduler) -> None:
    """``render --turntable N``: the film ``whitted animate --turntable N`` makes."""
    from .animate import animate

    if output is None:  # a name the user did not give: it replaces only whitted's film
        stem = scene_path.stem if scene_path is not None else "render"
        output = Path(f"{stem}_turntable.mp4")
        check_default_output(output)
    elif output.suffix.lower() in (".png", ".exr", ".pfm", ".npy", ".jpg", ".jpeg", ".tif",
                                   ".tiff", ".webp"):
        raise fail(f"{output}: --turntable makes a film: name an .mp4 or .gif file, or a "
                   "folder for the frames alone")
    animate(scene_path=scene_path, output=output, frames=None, fps=None, width=width,
            height=height, samples=samples, max_depth=max_depth, threads=threads, seed=seed,
            set_values=set_values, crf=18, force=False, quiet=quiet, turntable=frames,
            cluster=cluster, scheduler=scheduler)


def _render_and_write(job, scene, name, output, outputs, aovs, bit_depth, quiet,
                      guard: InterruptGuard, process_start, frame: int | None,
                      finish: StillFinish) -> None:
    from .. import marks
    from ..output.formats import image_format
    from ..render.api import render_aovs

    interrupted = guard.event
    marks.mark("job")
    try:
        _run_with_progress(job, quiet, interrupted)
    except WhittedError as exc:  # a model or texture file the scene names is unusable
        raise fail(with_scene_key(exc, scene, name)) from None
    stats = job.stats
    if interrupted.is_set() and (job.running or stats.tiles_done == 0):
        # stopped while compiling, or before any tile was finished: there is nothing to keep,
        # and an existing file at the output path is left as it was
        if job.running:
            abandoned.append(True)
        raise guard.exit(f"before any tile was finished: nothing written ({output} is "
                         "unchanged)")
    image = job.image
    assert image is not None
    marks.mark("rendered")
    for warning in stats.warnings:
        err.echo(f"warning: {warning}")
    written = [str(output)]
    plain = not (finish.alpha or finish.exposure or finish.quality is not None
                 or finish.region is not None)
    try:
        whole = not interrupted.is_set() and stats.tiles_done == stats.tiles_total
        if not whole:  # what finishing it needs, beside the picture (cli/tile_state.py)
            from .tile_state import TileState, foreign, save_state

            if foreign(finish.state):  # a file of someone else's by that name: kept
                err.echo(f"warning: {finish.state} is not whitted's: the tiles are kept in "
                         f"{output} only (--continue cannot finish it)")
            else:
                save_state(finish.state, TileState(finish.digest, job.tiles_finished.copy(),
                                                   job.framebuffer))
        if frame is not None and whole and plain and bit_depth == 8 \
                and image_format(output) == "png":  # the very file the film's frame K is
            from ..animation.frames import frame_digest, write_frame_png

            write_frame_png(output, image, frame_digest(scene, frame), frame)
        else:
            _save_still(image, output, bit_depth, scene, finish, whole and finish.alpha,
                        job.threads)
        if whole:
            from .tile_state import remove_state

            remove_state(finish.state)
        if aovs and not interrupted.is_set():
            planes = render_aovs(scene)
            for path, aov_name in zip(outputs[1:], aovs, strict=True):
                save_npy(path, planes[aov_name])
                written.append(str(path))
    except OSError as exc:
        raise fail(f"{getattr(exc, 'filename', None) or output}: cannot write: "
                   f"{exc.strerror or exc}") from None
    except WhittedError as exc:
        raise fail(str(exc)) from None
    stats.wall_seconds = time.perf_counter() - process_start
    if not quiet or interrupted.is_set():
        out.echo(f"{stats.summary()} -> {', '.join(written)}")
    if marks.enabled():  # whitted bench --startup: the moments, and the job's own figures
        marks.note("build", stats.build_seconds)
        marks.note("kernels", stats.compile_seconds)
        marks.note("render", stats.render_seconds)
        if stats.photons is not None:
            marks.note("photons", stats.photons.seconds)
        for kind, traced in stats.rays.items():
            marks.count(f"rays:{kind}", traced)
        marks.mark("written")
        marks.write()
    if interrupted.is_set():  # (a signal may have come during the write)
        raise guard.exit(f"kept {stats.tiles_done}/{stats.tiles_total} tiles in {output} "
                         f"and {finish.state.name}; the same command with --continue "
                         "finishes it")


def _save_still(image, output: Path, bit_depth: int, scene, finish: StillFinish,
                with_alpha: bool, threads: int) -> None:
    """The picture written with the options that change it: exposure (2^EV), quality, and
    an alpha channel (render/coverage.py) once every tile is done (an interrupted one is
    written without, until --continue finishes it)."""
    import numpy as np

    from ..output.image import Image

    pixels = image.pixels
    alpha = None
    if with_alpha:
        from ..render.coverage import render_coverage, straight_colour

        alpha, background = render_coverage(scene, region=finish.region, threads=threads)
        pixels = straight_colour(pixels, alpha, background)
    if finish.exposure:
        pixels = pixels * np.float32(2.0 ** finish.exposure)
    if pixels is not image.pixels:
        image = Image(pixels, transfer=image.transfer, tonemap=image.tonemap)
    image.save(output, bit_depth=bit_depth, alpha=alpha, quality=finish.quality)


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
    from ..render.warm_up import compile_label, compile_progress

    fraction = compile_progress()
    if fraction is not None:
        bar.update(task, description=f"compiling {compile_label()} (first run only)",
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


