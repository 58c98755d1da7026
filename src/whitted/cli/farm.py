"""Command-line glue for the render farm: ``whitted render ... --cluster local:N`` or
``--scheduler tcp://HOST:PORT`` (and the same options of ``whitted animate``)."""

from __future__ import annotations

import time
from contextlib import nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import WhittedError
from .interrupt import InterruptGuard

if TYPE_CHECKING:
    from rich.progress import Progress

    from ..scene.scene import Scene

ClusterOption = Annotated[
    str | None, typer.Option("--cluster", help="Render on a new local Dask cluster: local:N "
                             "worker processes (needs whitted[farm])")]
SchedulerOption = Annotated[
    str | None, typer.Option("--scheduler", help="Render on the Dask cluster at "
                             "tcp://HOST:PORT (workers need whitted installed)")]


def farm_module():
    """``whitted.farm``, or the one-line error saying what to install."""
    from .app import fail

    try:
        from .. import farm
    except ImportError as exc:
        raise fail(str(exc)) from None
    return farm


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
                    TimeRemainingColumn(), console=err, transient=True)


def render_still_on_farm(scene: Scene, output: Path, *, cluster: str | None,
                         scheduler: str | None, threads: int | None, quiet: bool,
                         bit_depth: int, aovs: list[str]) -> None:
    """``whitted render`` on a cluster: bands across the workers, one image written here."""
    from .app import err, fail, out, save_npy

    farm = farm_module()
    start = time.perf_counter()
    note = None if quiet else (lambda line: err.print(line, markup=False, highlight=False))
    guard = InterruptGuard(at_once=True)  # SIGINT, SIGTERM: the cluster closed, nothing kept
    try:
        with guard, farm.farm_client(cluster, scheduler, threads=threads,
                                     note=note) as client:
            progress = bar("rendering bands", quiet)
            if progress is None:
                image = farm.render_still(client, scene)
            else:
                with progress:
                    task = progress.add_task("bands", total=None)
                    image = farm.render_still(
                        client, scene,
                        progress=lambda done, total: progress.update(task, completed=done,
                                                                     total=total))
    except KeyboardInterrupt:
        raise guard.exit(f"nothing written ({output} is unchanged)") from None
    except WhittedError as exc:  # a bad option, an unreachable scheduler, a bad model file
        raise fail(str(exc)) from None
    stats = image.meta["stats"]
    for warning in stats.warnings:
        err.print(f"warning: {warning}", markup=False, highlight=False)
    image.save(output, bit_depth=bit_depth)
    written = [str(output)]
    if aovs:  # one cheap pass through the pixel centres: done here
        from ..render.api import render_aovs

        planes = render_aovs(scene)
        for name in aovs:
            path = output.with_name(f"{output.stem}.{name}.npy")
            save_npy(path, planes[name])
            written.append(str(path))
    stats.wall_seconds = time.perf_counter() - start
    if not quiet:
        out.print(f"{stats.summary()} on {image.meta['workers']} workers "
                  f"({image.meta['bands']} bands) -> {', '.join(written)}")
    raise typer.Exit(0)


def animate_on_farm(scene: Scene, frames: range, folder: Path, film: Path | None, *,
                    fps: float, crf: int, force: bool, quiet: bool, cluster: str | None,
                    scheduler: str | None, threads: int | None) -> None:
    """``whitted animate`` on a cluster: frames as tasks, each written here as it arrives
    (resumable, as the local command), then the film encoded from the whole sequence."""
    from .app import err, fail, out

    farm = farm_module()
    start = time.perf_counter()
    note = None if quiet else (lambda line: err.print(line, markup=False, highlight=False))
    finished: list[int | None] = []
    guard = InterruptGuard(at_once=True)  # SIGINT, SIGTERM: the frames written are kept
    with guard:
        try:
            farm.check_farm_options(cluster, scheduler)
            plan = farm.plan_film(scene, folder, frames=frames, force=force)
            # a cluster only when frames are missing: a finished film is only encoded
            connect = (farm.farm_client(cluster, scheduler, threads=threads, note=note)
                       if plan.todo else nullcontext())
            with connect as client:
                progress = bar("frames", quiet)

                def frame_done(done: int, total: int, frame: int | None) -> None:
                    finished.append(frame)
                    if progress is not None:
                        progress.update(task, completed=done, total=total)
                    elif not quiet and frame is not None:
                        err.print(f"frame {frame} ({done}/{total})", highlight=False)

                with progress if progress is not None else nullcontext():
                    task = progress.add_task("frames", total=len(frames)) if progress else None
                    result = farm.render_film(client, scene, folder, film=film, fps=fps, crf=crf,
                                              progress=frame_done, plan=plan)
        except KeyboardInterrupt:
            raise guard.exit(f"{len(finished)} of {len(frames)} frames finished in {folder}; "
                             "run the same command again to continue") from None
        except WhittedError as exc:  # a bad option, an unreachable scheduler, a failed frame
            raise fail(str(exc)) from None
        except (ValueError, OSError) as exc:  # the encoder
            raise fail(f"{film}: cannot encode: {exc}") from None
    for warning in result.warnings:
        err.print(f"warning: {warning}", markup=False, highlight=False)
    if not quiet:
        done = f"{len(result.rendered)} rendered" + (
            f", {len(result.kept)} already done" if result.kept else "")
        per_frame = (f", {result.render_seconds / len(result.rendered):.2f} s a frame on a "
                     "worker" if result.rendered else "")
        target = f"; {film}" if film is not None else ""
        out.print(f"{len(result.paths)} frames ({done}{per_frame}, {result.tasks} tasks) -> "
                  f"{folder}{target}; total {time.perf_counter() - start:.1f} s",
                  highlight=False)
    raise typer.Exit(0)
