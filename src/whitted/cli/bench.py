"""``whitted bench``: the benchmark scenes timed, beside POV-Ray or Embree on request."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError, shorten
from .app import app, fail
from .console import err, out

# written out (the command's help must not import the bench); tests/test_bench_command.py
# checks it names every scene of bench/scenes.py
SCENE_HELP = ("Scene(s): seed000, softshadow, ice, mesh1m, lecture, sphere1m, bunny1m, vase1m, "
              "instances100, csg, dice100, caustics (default: all)")


@app.command()
def bench(
    scene: Annotated[
        list[str] | None, typer.Option("--scene", help=SCENE_HELP)
    ] = None,
    runs: Annotated[int, typer.Option("--runs", "-n", help="Timed runs; the median")] = 5,
    threads: Annotated[
        str | None, typer.Option("--threads", "-t", help="Thread counts, e.g. 1,2 (all cores)")
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Tiny images, one run (CI)")] = False,
    compare: Annotated[str | None, typer.Option(
        "--compare", help="Also time povray (its runs alternate with whitted's) or embree "
                          "(the mesh scenes' rays)")] = None,
    study: Annotated[str | None, typer.Option("--study", help="threads or size")] = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write results")] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Study plot (PNG)")] = None,
    markdown: Annotated[Path | None, typer.Option("--markdown", help="Table as Markdown")] = None,
    size: Annotated[str | None, typer.Option("--size", help="WxH for every scene")] = None,
    in_process: Annotated[
        bool, typer.Option("--in-process", help="Render in this process, not a fresh one")
    ] = False,
    rays: Annotated[bool, typer.Option(
        "--rays", help="Also the render time by kind of ray (primary, shadow, reflection, "
                       "refraction, photon), from variants of each scene timed alternately")
    ] = False,
    startup: Annotated[bool, typer.Option(
        "--startup", help="Where a whole `whitted render` process spends its time, for "
                          "--scene (a benchmark or a scene file; default seed000)")] = False,
) -> None:
    """Render the benchmark scenes (benchmarks/) and print times, rays and memory."""
    from ..bench.command import bench_main
    from ..bench.scenes import SCENES

    if startup:
        from ..bench.command import startup_main
        from ..output.safety import check_output_place

        try:
            if json_path is not None:
                check_output_place(json_path)
            startup_main(scenes=scene, runs=runs, threads=threads, compare=compare,
                         json_path=json_path, out=out, err=err)
        except WhittedError as exc:
            raise fail(str(exc)) from None
        return
    for name in scene or []:  # checked before the header line: a mistake is one line
        if name not in SCENES and not name.startswith("generated/"):
            raise fail(f"--scene: unknown benchmark scene {shorten(name)!r} "
                       f"(known: {', '.join(SCENES)})")
    from ..output.safety import check_output_place

    if study in ("threads", "size") and plot is None:  # a name not given: only whitted's
        from .app import check_default_output

        plot = Path(f"bench-study-{study}.png")
        check_default_output(plot)
    named = [(o, p) for o, p in (("--json", json_path), ("--plot", plot),
                                 ("--markdown", markdown)) if p is not None]
    for k, (option, path) in enumerate(named):  # two results never go to one file
        for other, earlier in named[:k]:
            if os.path.realpath(path) == os.path.realpath(earlier):  # loops too
                raise fail(f"{option}: {path} is the file {other} names too")
    for option, path in (("--json", json_path), ("--plot", plot), ("--markdown", markdown)):
        try:
            if path is not None:
                check_output_place(path)
        except WhittedError as exc:
            raise fail(f"{option}: {exc}") from None
    try:
        bench_main(scenes=scene, runs=runs, threads=threads, quick=quick, compare=compare,
                   study=study, json_path=json_path, plot_path=plot, markdown_path=markdown,
                   size=size, in_process=in_process, out=out, err=err, rays=rays)
    except WhittedError as exc:
        raise fail(str(exc)) from None


