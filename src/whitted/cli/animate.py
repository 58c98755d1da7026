"""``whitted animate``: render the frames of an animated scene and encode the film."""

from __future__ import annotations

import signal
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import SceneError, WhittedError
from .farm import ClusterOption, SchedulerOption, animate_on_farm
from .main import (
    EXIT_INTERRUPTED,
    SceneArgument,
    _load,
    _override_error,
    app,
    apply_set_options,
    err,
    fail,
    out,
)

if TYPE_CHECKING:
    from rich.progress import Progress

FRAME_DIGITS = 4


def parse_frame_range(text: str | None, count: int) -> range:
    """``A:B`` (both included), ``A:``, ``:B`` or ``K`` -> the frames; SceneError if outside
    0 .. count-1 or empty."""
    last = count - 1
    if text is None or not text.strip():
        return range(count)
    text = text.strip()
    try:
        if ":" in text:
            a, b = text.split(":", 1)
            first = int(a) if a.strip() else 0
            final = int(b) if b.strip() else last
        else:
            first = final = int(text)
    except ValueError:
        raise SceneError(f"expected A:B (frame numbers), got {text!r}",
                         where="--frames") from None
    for k in (first, final):
        if not 0 <= k <= last:
            raise SceneError(f"frame {k} is outside 0..{last} (the scene has {count} "
                             f"frame{'s' if count != 1 else ''})", where="--frames")
    if final < first:
        raise SceneError(f"{text!r} is empty (the first frame comes after the last)",
                         where="--frames")
    return range(first, final + 1)


def frame_name(frame: int, count: int) -> str:
    return f"{frame:0{max(FRAME_DIGITS, len(str(count - 1)))}d}.png"


def film_paths(output: Path) -> tuple[Path | None, Path]:
    """(the film or None for frames only, the folder of its frames) for ``-o output``."""
    from ..output.video import video_format

    if output.suffix == "" or output.is_dir():
        return None, output
    try:
        video_format(output)
    except ValueError as exc:
        raise SceneError(str(exc), where=str(output)) from None
    return output, output.with_name(f"{output.stem}_frames")


@app.command()
def animate(
    scene_path: SceneArgument = None,
    output: Annotated[
        Path, typer.Option("-o", "--output", help="film.mp4, film.gif, or a folder (frames only)")
    ] = Path("film.mp4"),
    frames: Annotated[
        str | None, typer.Option("--frames", help="A:B, both included (default: all)")
    ] = None,
    fps: Annotated[float | None, typer.Option("--fps", help="Frames per second")] = None,
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
    cluster: ClusterOption = None,
    scheduler: SchedulerOption = None,
) -> None:
    """Render every frame of SCENE to numbered PNGs (FILM_frames/0000.png ...), then encode
    the film (H.264 MP4 or GIF). Frames already rendered from the same scene and settings are
    kept, so an interrupted run continues where it stopped (Ctrl-C keeps finished frames)."""
    from pydantic import ValidationError

    from ..animation.frames import FrameRenderer
    from ..output.video import encode_film, even_size
    from ..render.api import CancelToken

    started = time.perf_counter()
    try:
        film, folder = film_paths(output)
        scene, name = _load(scene_path)
        if scene_path is not None and film is not None and film.resolve() == scene_path.resolve():
            raise SceneError("would write over the scene file", where=str(output))
        scene = apply_set_options(scene, set_values)
        scene = scene.with_settings(width=width, height=height, samples=samples,
                                    max_depth=max_depth, threads=threads, seed=seed)
        chosen = parse_frame_range(frames, scene.frame_count)
        rate = fps if fps is not None else (scene.animation.fps if scene.animation else 24.0)
        if not rate > 0:
            raise SceneError(f"must be > 0, got {rate:g}", where="--fps")
        if not 0 <= crf <= 51:
            raise SceneError(f"must be 0..51, got {crf}", where="--crf")
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:
        raise fail(_override_error(exc)) from None
    if not folder.parent.exists():
        raise fail(f"{output}: the folder {folder.parent} does not exist")
    folder.mkdir(exist_ok=True)
    if cluster is not None or scheduler is not None:  # frames on a Dask cluster (cli/farm.py)
        animate_on_farm(scene, chosen, folder, film, fps=rate, crf=crf, force=force, quiet=quiet,
                        cluster=cluster, scheduler=scheduler, threads=threads)

    renderer = FrameRenderer(threads)
    cancel = CancelToken()
    interrupted = threading.Event()
    previous = signal.getsignal(signal.SIGINT)

    def on_interrupt(signum, frame) -> None:  # Ctrl-C: finish nothing more, keep what is done
        interrupted.set()
        cancel.cancel()

    signal.signal(signal.SIGINT, on_interrupt)
    paths: list[Path] = []
    rendered = kept = 0
    render_seconds = 0.0
    warned: set[str] = set()
    try:
        with _FilmProgress(len(chosen), quiet) as bar:
            for frame in chosen:
                if interrupted.is_set():
                    break
                path = folder / frame_name(frame, scene.frame_count)
                still = scene.at_frame(frame)
                bar.start_frame(frame)
                result = renderer.render(still, frame, path, force=force,
                                         progress=bar.tiles, cancel=cancel)
                if result.cancelled:
                    break
                paths.append(path)
                if result.rendered:
                    rendered += 1
                    render_seconds += result.seconds
                    for warning in result.stats.warnings if result.stats else []:
                        if warning not in warned:
                            warned.add(warning)
                            err.print(f"warning: {warning}", markup=False, highlight=False)
                else:
                    kept += 1
                bar.frame_done(frame, result)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    finally:
        signal.signal(signal.SIGINT, previous)

    done = f"{rendered} rendered" + (f", {kept} already done" if kept else "")
    if interrupted.is_set() or len(paths) < len(chosen):
        err.print(f"interrupted: {len(paths)} of {len(chosen)} frames finished ({done}) in "
                  f"{folder}; run the same command again to continue")
        raise typer.Exit(EXIT_INTERRUPTED)
    per_frame = f", {render_seconds / rendered:.2f} s a frame" if rendered else ""
    summary = f"{len(paths)} frames ({done}{per_frame}) -> {folder}"
    encode_seconds = 0.0
    if film is not None:
        encode_start = time.perf_counter()
        try:
            encode_film(paths, film, rate, crf=crf)
        except (ValueError, OSError) as exc:
            raise fail(f"{film}: cannot encode: {exc}") from None
        encode_seconds = time.perf_counter() - encode_start
        r = scene.render
        w, h = even_size(r.width, r.height) if film.suffix.lower() == ".mp4" else (r.width,
                                                                                   r.height)
        summary += (f"; {film} ({w}x{h}, {rate:g} fps, {len(paths) / rate:.2f} s) encoded in "
                    f"{encode_seconds:.2f} s")
    if not quiet:
        out.print(f"{summary}; total {time.perf_counter() - started:.1f} s", highlight=False)
        if rendered:
            out.print(renderer.cache.stats.summary(), highlight=False)


class _FilmProgress:
    """Two bars on a terminal (frames with ETA; the current frame's tiles), else one line
    per frame; nothing when quiet."""

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
                TaskProgressColumn(), TimeRemainingColumn(), console=err, transient=True)
            self._progress.__enter__()
            self._frames = self._progress.add_task("frames", total=self.total)
            self._tiles = self._progress.add_task("frame tiles", total=None)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._progress.__exit__(*exc)

    def start_frame(self, frame: int) -> None:
        if self._progress is not None:
            self._progress.reset(self._tiles, total=None, description=f"frame {frame} tiles")

    def tiles(self, p) -> None:
        if self._progress is not None:
            self._progress.update(self._tiles, completed=p.tiles_done, total=p.tiles_total)

    def frame_done(self, frame: int, result) -> None:
        self.done += 1
        if self._progress is not None:
            self._progress.update(self._frames, advance=1)
        elif not self.quiet:
            state = f"{result.seconds:.2f} s" if result.rendered else "already done"
            err.print(f"frame {frame} ({self.done}/{self.total}): {state}", highlight=False)
