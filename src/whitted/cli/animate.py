"""``whitted animate``: render the frames of an animated scene and encode the film (a thin
client of :mod:`whitted.animation.film`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import WhittedError
from .app import (
    SceneArgument,
    app,
    apply_set_options,
    check_default_output,
    err,
    fail,
    load_scene_argument,
    out,
    override_error,
    with_options,
)
from .farm import ClusterOption, SchedulerOption, animate_on_farm
from .interrupt import InterruptGuard

if TYPE_CHECKING:
    from rich.progress import Progress


@app.command()
def animate(
    scene_path: SceneArgument = None,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="film.mp4, film.gif, or a folder (frames only) "
        "[default: film.mp4]")] = None,
    frames: Annotated[
        str | None, typer.Option("--frames", help="A:B, both included (default: all)")
    ] = None,
    fps: Annotated[float | None, typer.Option(
        "--fps", help="Frames per second: 0.01..1000 (MP4), 0.01..50 (GIF)")] = None,
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
    samples: Annotated[int | None, typer.Option("--samples", "-s", help="Samples/pixel")] = None,
    max_depth: Annotated[int | None, typer.Option("--max-depth", "-d", help="Recursion")] = None,
    threads: Annotated[int | None, typer.Option("--threads", "-t", help="0 = all cores")] = None,
    seed: Annotated[int | None, typer.Option("--seed", help="Random seed of the film")] = None,
    set_values: Annotated[
        list[str] | None, typer.Option("--set", help="PATH=VALUE: change a scene value")
    ] = None,
    crf: Annotated[int, typer.Option("--crf", help="MP4 quality: 0 best .. 51 worst")] = 18,
    force: Annotated[bool, typer.Option("--force", help="Render frames already on disk")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress output")] = False,
    turntable: Annotated[int | None, typer.Option(
        "--turntable", help="N frames of the camera going once around (a model's quick look)",
        min=1, max=1_000_000)] = None,
    cluster: ClusterOption = None,
    scheduler: SchedulerOption = None,
) -> None:
    """Render every frame of SCENE to numbered PNGs (FILM_frames/0000.png ...), then encode
    the film (H.264 MP4 or GIF). Frames already rendered from the same scene and settings are
    kept, so an interrupted run continues where it stopped (Ctrl-C or SIGTERM keeps finished
    frames). Files in the way that whitted did not write are never written over: without
    -o, a film.mp4 already there is replaced only when whitted encoded it."""
    from pydantic import ValidationError

    from ..animation.film import parse_frame_range, prepare_film, render_film
    from ..render.api import CancelToken

    started = time.perf_counter()
    if output is None:  # a name the user did not give: it replaces only whitted's film
        output = Path("film.mp4")
        check_default_output(output)
    try:
        scene, name = load_scene_argument(scene_path, width=width, height=height,
                                          turntable=turntable)
        scene = apply_set_options(scene, set_values)
        scene = with_options(scene, width=width, height=height, samples=samples,
                             max_depth=max_depth, threads=threads, seed=seed)
        chosen = parse_frame_range(frames, scene.frame_count)
        plan = prepare_film(scene, output, frames=chosen, fps=fps, crf=crf,
                            scene_path=scene_path,
                            fps_where="--fps" if fps is not None else f"{name}: animation.fps")
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:
        raise fail(override_error(exc)) from None
    if cluster is not None or scheduler is not None:  # frames on a Dask cluster (cli/farm.py)
        animate_on_farm(scene, plan, force=force, quiet=quiet, cluster=cluster,
                        scheduler=scheduler, threads=threads)

    cancel = CancelToken()
    with InterruptGuard() as guard, _FilmProgress(len(chosen), quiet) as bar:
        guard.on_interrupt(cancel.cancel)
        try:
            result = render_film(scene, plan, force=force, threads=threads, progress=bar,
                                 cancel=cancel)
        except WhittedError as exc:
            raise fail(str(exc)) from None
    folder = plan.paths.frames
    done = f"{len(result.rendered)} rendered" + (
        f", {len(result.kept)} already done" if result.kept else "")
    if result.cancelled or not result.complete:
        what = (f"{len(result.files)} of {len(chosen)} frames finished ({done}) in {folder}"
                if len(result.files) < len(chosen) else
                f"every frame is in {folder}, the film was not encoded")
        raise guard.exit(f"{what}; run the same command again to continue")
    per_frame = (f", {result.render_seconds / len(result.rendered):.2f} s a frame"
                 if result.rendered else "")
    summary = f"{len(result.files)} frames ({done}{per_frame}) -> {folder}"
    if result.film is not None:
        w, h = result.size
        summary += (f"; {result.film} ({w}x{h}, {plan.fps:g} fps, "
                    f"{len(result.files) / plan.fps:.2f} s) encoded in "
                    f"{result.encode_seconds:.2f} s")
    if not quiet:
        out.print(f"{summary}; total {time.perf_counter() - started:.1f} s", highlight=False)
        if result.compiles:
            out.print(result.compiles, highlight=False)


class _FilmProgress:
    """Two bars on a terminal (frames with ETA; the current frame's tiles), else one line
    per frame on stdout (stderr is for warnings and the one line of an error or interrupt);
    nothing when quiet."""

    def __init__(self, total: int, quiet: bool) -> None:
        self.quiet = quiet
        self.total = total
        self.live = not quiet and err.is_terminal
        self.done = 0
        self._progress: Progress | None = None

    def __enter__(self) -> _FilmProgress:
        if self.live:
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TaskProgressColumn,
                TextColumn,
                TimeRemainingColumn,
            )

            self._progress = Progress(
                TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                TaskProgressColumn(), TimeRemainingColumn(), console=err.console, transient=True)
            self._progress.__enter__()
            self._frames = self._progress.add_task("frames", total=self.total)
            self._tiles = self._progress.add_task("frame tiles", total=None)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._progress.__exit__(*exc)

    def __call__(self, p) -> None:
        """:func:`~whitted.animation.film.render_film`'s progress callback."""
        for warning in p.warnings:
            err.print(f"warning: {warning}", markup=False, highlight=False)
        if p.event == "frame":
            if self._progress is not None:
                self._progress.reset(self._tiles, total=None,
                                     description=f"frame {p.frame} tiles")
        elif p.event == "tiles":
            if self._progress is not None:
                self._progress.update(self._tiles, completed=p.tiles.tiles_done,
                                      total=p.tiles.tiles_total)
        elif p.event == "done":
            self.done += 1
            if self._progress is not None:
                self._progress.update(self._frames, advance=1)
            elif not self.quiet:
                result = p.result
                state = f"{result.seconds:.2f} s" if result.rendered else "already done"
                out.echo(f"frame {p.frame} ({self.done}/{self.total}): {state}")
