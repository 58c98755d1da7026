"""Command-line glue for the render farm: ``whitted render ... --cluster local:N`` or
``--scheduler tcp://HOST:PORT`` (and the same options of ``whitted animate``).

Exit status: 0 done; 2 a bad option or scene, a frame that failed (named); 3 the cluster
cannot do the job (scheduler unreachable or lost, no worker able to render: every one lost,
stalled, or running another whitted); 130 interrupted (143 terminated). Whatever arrived
before the end (frames, bands) is kept."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import WhittedError
from .interrupt import InterruptGuard

if TYPE_CHECKING:
    from rich.progress import Progress

    from ..animation.film import FilmPlan
    from ..scene.scene import Scene

EXIT_CLUSTER = 3  # the cluster cannot do the job (docs/farm.md)

ClusterOption = Annotated[
    str | None, typer.Option("--cluster", help="Render on a new local Dask cluster: local:N "
                             "worker processes (needs whitted\\[farm])")]
SchedulerOption = Annotated[
    str | None, typer.Option("--scheduler", help="Render on the Dask cluster at "
                             "tls://HOST:PORT (tcp:// on a trusted network only; workers need "
                             "whitted installed)")]


def farm_module():
    """``whitted.farm``, or the one-line error saying what to install."""
    from .app import fail

    try:
        from .. import farm
    except ImportError as exc:
        raise fail(str(exc)) from None
    return farm


def cluster_fail(message: str) -> typer.Exit:
    """One line, exit status :data:`EXIT_CLUSTER`."""
    from .app import fail

    fail(message)
    return typer.Exit(EXIT_CLUSTER)


@contextmanager
def quiet_dask_logs() -> Iterator[None]:
    """Dask's own log lines (reconnect attempts, restarted workers, its tracebacks) off while
    the command runs: the farm tells a wrangler what happened in its own lines."""
    import logging

    names = ["distributed", "tornado", "asyncio"] + [
        name for name in logging.root.manager.loggerDict if name.startswith("distributed.")]
    loggers = [logging.getLogger(name) for name in names]
    levels = [log.level for log in loggers]
    for log in loggers:
        log.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for log, level in zip(loggers, levels, strict=True):
            log.setLevel(level)


def status(quiet: bool) -> Callable[[str], None] | None:
    """Where the farm's status lines go (the cluster's size): stdout, as a local command's
    progress lines; stderr keeps warnings and the one line of an error or interrupt."""
    from .app import out

    return None if quiet else (lambda line: out.print(line, markup=False, highlight=False))


def bar(label: str, quiet: bool) -> Progress | None:
    from .app import err

    if quiet or not err.is_terminal:
        return None
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    return Progress(TextColumn(f"[bold]{label}"), BarColumn(), MofNCompleteColumn(),
                    TimeRemainingColumn(), console=err.console, transient=True)


def render_still_on_farm(scene: Scene, output: Path, *, cluster: str | None,
                         scheduler: str | None, threads: int | None, quiet: bool,
                         bit_depth: int, aovs: list[str], frame: int | None = None) -> None:
    """``whitted render`` on a cluster: bands across the workers, one image written here
    (with ``frame``, an 8-bit PNG is the film's frame file, record included, as locally).
    Stopped part way, the bands that arrived are written, as a local render keeps its
    tiles."""
    from .app import err, fail, out, save_npy

    farm = farm_module()
    start = time.perf_counter()
    tell = None if quiet else (lambda line: err.print(line, markup=False, highlight=False))
    # Ctrl-C, SIGTERM (cli/interrupt.py): while the cluster starts, at once (nothing to keep);
    # while bands render, after writing the bands that arrived, as a local render keeps tiles
    starting, rendering = InterruptGuard(at_once=True), InterruptGuard()
    try:
        with quiet_dask_logs(), starting, \
                farm.farm_client(cluster, scheduler, threads=threads, note=tell,
                                 status=status(quiet)) as client, \
                rendering:
            progress = bar("rendering bands", quiet)
            with progress if progress is not None else nullcontext():
                task = progress.add_task("bands", total=None) if progress else None
                image = farm.render_still(
                    client, scene, cancel=rendering.event, note=tell,
                    progress=None if progress is None else (
                        lambda done, total: progress.update(task, completed=done,
                                                            total=total)))
    except KeyboardInterrupt:  # while the cluster started, or a second signal
        guard = rendering if rendering.interrupted else starting
        raise guard.exit(f"nothing written ({output} is unchanged)") from None
    except farm.ClusterLost as exc:
        raise cluster_fail(str(exc)) from None
    except WhittedError as exc:  # a bad option, a bad model file
        raise fail(str(exc)) from None
    stats = image.meta["stats"]
    if stats.cancelled and stats.tiles_done == 0:
        raise rendering.exit(f"before any band was finished: nothing written ({output} is "
                             "unchanged)")
    for warning in stats.warnings:
        err.print(f"warning: {warning}", markup=False, highlight=False)
    from ..output.formats import image_format

    try:
        if frame is not None and not stats.cancelled and bit_depth == 8 \
                and image_format(output) == "png":  # the very file the film's frame K is
            from ..animation.frames import frame_digest, write_frame_png

            write_frame_png(output, image, frame_digest(scene, frame), frame)
        else:
            image.save(output, bit_depth=bit_depth)
    except OSError as exc:
        raise fail(f"{getattr(exc, 'filename', None) or output}: cannot write: "
                   f"{exc.strerror or exc}") from None
    written = [str(output)]
    if aovs and not stats.cancelled:  # one cheap pass through the pixel centres: done here
        from ..render.api import render_aovs

        planes = render_aovs(scene)
        for name in aovs:
            path = output.with_name(f"{output.stem}.{name}.npy")
            save_npy(path, planes[name])
            written.append(str(path))
    stats.wall_seconds = time.perf_counter() - start
    if not quiet or stats.cancelled:
        out.print(f"{stats.summary()} on {image.meta['workers']} workers "
                  f"({image.meta['bands']} bands) -> {', '.join(written)}", highlight=False)
    if stats.cancelled:
        raise rendering.exit(f"kept {stats.tiles_done}/{stats.tiles_total} bands in {output}")
    raise typer.Exit(0)


def animate_on_farm(scene: Scene, plan: FilmPlan, *, force: bool, quiet: bool,
                    cluster: str | None, scheduler: str | None, threads: int | None) -> None:
    """``whitted animate`` on a cluster: the film pipeline (:mod:`whitted.animation.film`)
    with the farm's executor: frames as tasks, each written here as it arrives (resumable, as
    the local command), then the film encoded from the whole sequence."""
    from ..animation.film import missing_frames, render_film
    from ..render.api import CancelToken
    from .app import err, fail, out

    farm = farm_module()
    start = time.perf_counter()
    folder, film, total = plan.paths.frames, plan.paths.film, len(plan.frames)
    note = None if quiet else (lambda line: err.print(line, markup=False, highlight=False))
    finished: list[int | None] = []
    cancel = CancelToken()
    # Ctrl-C, SIGTERM (cli/interrupt.py): while the cluster starts, at once; while frames
    # render, after writing every frame that arrived (a second signal: at once)
    starting, rendering = InterruptGuard(at_once=True), InterruptGuard()
    rendering.on_interrupt(cancel.cancel)

    def stopped() -> typer.Exit:
        guard = rendering if rendering.interrupted else starting
        return guard.exit(f"{len(finished)} of {total} frames finished in {folder}; "
                          "run the same command again to continue")

    try:
        farm.check_farm_options(cluster, scheduler)
        todo, _ = missing_frames(scene, plan, force)
        # a cluster only when frames are missing: a finished film is only encoded
        connect = (farm.farm_client(cluster, scheduler, threads=threads, note=note,
                                    status=status(quiet)) if todo else nullcontext())
        with quiet_dask_logs(), starting, connect as client, rendering:
            progress = bar("frames", quiet)

            def frame_done(p) -> None:
                if p.event != "done":
                    return
                finished.append(p.frame)
                for warning in p.warnings:
                    err.print(f"warning: {warning}", markup=False, highlight=False)
                if progress is not None:
                    progress.update(task, completed=p.done, total=p.total)
                elif not quiet and p.result.rendered:
                    out.echo(f"frame {p.frame} ({p.done}/{p.total})")

            with progress if progress is not None else nullcontext():
                task = progress.add_task("frames", total=total) if progress else None
                executor = (farm.DaskFrames(client, note=note) if client is not None
                            else None)
                result = render_film(scene, plan, force=force, progress=frame_done,
                                     cancel=cancel, executor=executor)
    except KeyboardInterrupt:  # while the cluster started, or a second signal
        raise stopped() from None
    except farm.ClusterLost as exc:
        kept = f" ({len(finished)} of {total} frames are in {folder})" if finished else ""
        raise cluster_fail(f"{exc}{kept}") from None
    except WhittedError as exc:  # a bad option, a failed frame, the encoder
        raise fail(str(exc)) from None
    if result.cancelled:
        raise stopped()
    if not quiet:
        done = f"{len(result.rendered)} rendered" + (
            f", {len(result.kept)} already done" if result.kept else "")
        per_frame = (f", {result.render_seconds / len(result.rendered):.2f} s a frame on a "
                     "worker" if result.rendered else "")
        tasks = f", {result.report.tasks} tasks" if result.report is not None else ""
        target = f"; {film}" if film is not None else ""
        out.print(f"{total} frames ({done}{per_frame}{tasks}) -> {folder}{target}; total "
                  f"{time.perf_counter() - start:.1f} s", highlight=False)
    raise typer.Exit(0)
