"""``whitted stefan``: solve, validate and film the melting of a hollow piece of ice.

A thin client: the physics is :mod:`whitted.stefan`, the rendering the render API.
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import app as main_app
from .app import err, fail
from .console import LazyConsole
from .interrupt import InterruptGuard

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="The Stefan problem: a hollow piece of ice with water inside, melting.")
main_app.add_typer(app, name="stefan")
# tables keep their columns when the output is a file or a pipe
out = LazyConsole(highlight=False, soft_wrap=True, emoji=False,
                  width=None if sys.stdout.isatty() else 120)


def _fail(message: str) -> typer.Exit:
    return fail(message)


@app.callback()
def _needs_the_solver() -> None:
    """The Stefan problem: a hollow piece of ice with water inside, melting."""
    import importlib.util

    missing = [name for module, name in (("scipy", "SciPy"), ("skimage", "scikit-image"),
                                         ("matplotlib", "Matplotlib"))
               if importlib.util.find_spec(module) is None]
    if missing:
        names = ", ".join(missing[:-1]) + " and " * (len(missing) > 1) + missing[-1]
        raise _fail(f"whitted stefan needs {names}, which are not installed: "
                    "install whitted[stefan] (pip install 'whitted[stefan]')")


def load_scene_argument(case_path: Path):
    from ..stefan.case import load_case

    try:
        case = load_case(case_path)
    except WhittedError as exc:
        raise _fail(str(exc)) from None
    return case, case_path.read_text(encoding="utf-8")


#: the files a run writes at the top of its folder (stefan/run.py)
RUN_FILES = ("case.toml", "series.csv", "summary.json", "series.png")


def _check_run_outputs(case_path: Path, output: Path) -> None:
    """The output-safety check of ``render`` for a run's folder: its files can be written
    there and none of them is the case file the run reads (one line)."""
    from ..output.safety import check_outputs

    if not output.is_dir():  # the run makes it
        return
    try:
        check_outputs([output / name for name in RUN_FILES], inputs=[case_path])
    except WhittedError as exc:
        raise _fail(str(exc)) from None


def _solve(case_path: Path, output: Path, fresh: bool, quiet: bool, guard: InterruptGuard,
           size=(480, 360), allow_large: bool = False):
    from ..stefan.case import CaseError
    from ..stefan.run import run_case

    case, text = load_scene_argument(case_path)
    if output.exists() and not output.is_dir():
        raise _fail(f"{output}: exists and is not a folder")
    _check_run_outputs(case_path, output)
    import time

    from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn

    from ..stefan.eta import TimeLeft

    # the bar runs to time.end; the time left says when the breach will stop the run first
    left = TimeLeft(case.time.end, case.breach.action == "stop", opens_at=case.dx * 1e3 / 4)
    columns = (TextColumn("[bold]{task.description}"), BarColumn(), TaskProgressColumn(),
               TextColumn("t = {task.fields[t]}"), TextColumn("{task.fields[left]}"))
    with Progress(*columns, console=err.console, transient=True,
                  disable=quiet or not err.is_terminal) as bar:
        task = bar.add_task("melting", total=1.0, t="0 s", left="")

        def progress(fraction: float, t: float, what: str) -> None:
            left.tick(time.monotonic(), t)
            bar.update(task, completed=fraction, t=f"{t:.0f} s", left=left.text(t))

        try:
            result = run_case(case, text, output, resume=not fresh, progress=progress,
                              should_stop=guard.is_set, scene_size=size,
                              allow_large=allow_large, case_path=case_path,
                              on_estimate=None if quiet else
                              lambda line: bar.console.print(line, highlight=False),
                              on_row=lambda r: left.row(r["time_s"], r["min_shell_mm"]))
        except CaseError as exc:
            raise _fail(str(exc)) from None
    return case, result


@app.command()
def run(
    case_path: Annotated[Path, typer.Argument(metavar="CASE", help="Case file (TOML)")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output folder")] = Path(
        "stefan-out"),
    fresh: Annotated[bool, typer.Option("--fresh", help="Start over, do not resume (removes "
                                        "only the files whitted wrote there)")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar")] = False,
    allow_large: Annotated[bool, typer.Option(
        "--allow-large", help="Go beyond the soft limits on steps, cell updates, saved times "
        "and disk (never beyond the machine's memory or free disk)")] = False,
) -> None:
    """Compute the melt of CASE: fields (.npz), surfaces (.ply) per saved time, a time series
    (CSV and plots) and a scene per saved time. Ctrl-C keeps what was saved; run again to
    resume from the last saved time. The folder must be new, empty of the run's names, or
    one whitted made (its .whitted-stefan-run marker): nothing else is written over."""
    with InterruptGuard() as guard:
        case, result = _solve(case_path, output, fresh, quiet, guard, allow_large=allow_large)
        _report(result)
        if result.interrupted:
            raise guard.exit(f"at t = {result.end_time:.1f} s: kept the saved times up to "
                             f"t = {result.last_saved:.0f} s in {output}; run the same "
                             "command again to resume from there")


def _report(result) -> None:
    cells = "x".join(str(n) for n in result.cells)
    head = (f"resumed at t = {result.resumed_from:.0f} s, " if result.resumed_from is not None
            else "")
    out.print(f"{head}t = {result.end_time:.0f} s after {result.steps} steps on {cells} cells "
              f"({result.solve_seconds:.1f} s solving); saved {len(result.saved)} time(s) -> "
              f"{result.out_dir}")
    if result.breach_time is not None:
        out.print(f"breach: the shell opened at t = {result.breach_time:.0f} s "
                  f"({result.breach_time / 60:.1f} min)")


@app.command()
def validate(
    full: Annotated[bool, typer.Option("--full", help="The docs' table: 1 h, finer cells "
                                       "(minutes)")] = False,
    plot: Annotated[Path | None, typer.Option("--plot", help="Front against time (PNG)")] = None,
) -> None:
    """Check the solver against exact answers and print the tables: Neumann's lambda, front
    error against cell size, the axes, the cavity's convection, the flow solver on de Vahl
    Davis's square cavity (32², with --full 32² to 128²) and on the heated cube (24³, with
    --full 32³ to 64³), gallium melting beside Gau & Viskanta's measured front and at Blais
    & Ilinca's Ra 1e5 beside their computation, the convective
    slab, the sphere,
    the energy balance."""
    from rich.table import Table

    from ..stefan import validate as v

    t0 = time.perf_counter()
    table = Table(title="Similarity constants (root-found) against quoted values")
    for col in ("case", "computed", "quoted", "difference"):
        table.add_column(col)
    for r in v.lambda_rows():
        table.add_row(r["case"], f"{r['lambda']:.6f}", f"{r['quoted']:g}",
                      f"{r['difference']:+.2e}")
    out.print(table)

    t_end = 3600.0 if full else 600.0
    cells = (1.0, 0.5, 0.25, 0.125)
    table = Table(title=f"Two-phase front (+10 °C wall, -10 °C ice) after {t_end:.0f} s, 1-D")
    for col in ("dx (mm)", "cells", "steps", "front (mm)", "exact (mm)", "error", "order",
                "far end moved (°C)", "energy (rel.)"):
        table.add_column(col, justify="right")
    for r in v.convergence_rows(t_end=t_end, cells_mm=cells):
        table.add_row(f"{r['dx_mm']:g}", str(r["cells"]), str(r["steps"]),
                      f"{r['front_mm']:.4f}", f"{r['exact_mm']:.4f}", f"{r['error_pct']:+.2f} %",
                      "" if r["order"] is None else f"{r['order']:.2f}",
                      f"{r['far_change']:.1e}", f"{r['energy_rel']:.1e}")
    out.print(table)

    table = Table(title=f"Three more 1-D cases after {t_end:.0f} s")
    for col in ("case", "dx (mm)", "steps", "front (mm)", "exact (mm)", "error", "order",
                "energy (rel.)"):
        table.add_column(col, justify="right")
    for r in v.more_case_rows(t_end=t_end, cells_mm=(0.5, 0.25, 0.125) if full else (0.5, 0.25)):
        table.add_row(r["case"], f"{r['dx_mm']:g}", str(r["steps"]), f"{r['front_mm']:.4f}",
                      f"{r['exact_mm']:.4f}", f"{r['error_pct']:+.2f} %",
                      "" if r["order"] is None else f"{r['order']:.2f}",
                      f"{r['energy_rel']:.1e}")
    out.print(table)

    table = Table(title="The 1-D case along each axis and in 3-D (0.5 mm, 600 s, same dt)")
    for col in ("run", "front (mm)", "error", "vs first (m)"):
        table.add_column(col, justify="right")
    for r in v.axis_rows():
        table.add_row(r["run"], f"{r['front_mm']:.6f}", f"{r['error_pct']:+.2f} %",
                      f"{r['vs_first']:.1e}")
    out.print(table)

    table = Table(title="The cavity's convection: Catton's enclosure law against de Vahl Davis's "
                  "square cavity (Pr 0.71)")
    for col in ("Ra", "benchmark Nu", "model Nu", "error", "Catton's range"):
        table.add_column(col, justify="right")
    for r in v.enclosure_rows():
        table.add_row(f"{r['ra']:.0e}", f"{r['benchmark']:.3f}", f"{r['model']:.3f}",
                      f"{r['error_pct']:+.1f} %", "yes" if r["in_range"] else "below (Nu = 1)")
    out.print(table)

    grids = (32, 64, 128) if full else (32,)
    table = Table(title="The flow solver on de Vahl Davis's square cavity (Pr 0.71; reference, "
                  "whitted, error)")
    for col in ("Ra", "grid", "Nu ref", "Nu", "error", "u_max ref", "u_max", "error",
                "v_max ref", "v_max", "error"):
        table.add_column(col, justify="right")
    cavity = v.flow_cavity_rows(grids)
    for r in cavity:
        table.add_row(f"{r['ra']:.0e}", r["grid"], f"{r['nu_ref']:.3f}", f"{r['nu']:.4f}",
                      f"{r['nu_error_pct']:+.2f} %", f"{r['u_ref']:.3f}", f"{r['u_max']:.3f}",
                      f"{r['u_error_pct']:+.2f} %", f"{r['v_ref']:.3f}", f"{r['v_max']:.3f}",
                      f"{r['v_error_pct']:+.2f} %")
    out.print(table)
    table = Table(title="Where the square cavity's velocity maxima are (units of the side; "
                  "reference, whitted, difference)")
    for col in ("Ra", "grid", "y(u_max) ref", "y(u_max)", "difference", "x(v_max) ref",
                "x(v_max)", "difference"):
        table.add_column(col, justify="right")
    for r in cavity:
        table.add_row(f"{r['ra']:.0e}", r["grid"], f"{r['y_ref']:.3f}", f"{r['y_umax']:.4f}",
                      f"{r['y_error']:+.4f}", f"{r['x_ref']:.4f}", f"{r['x_vmax']:.4f}",
                      f"{r['x_error']:+.4f}")
    out.print(table)

    cubes = (32, 48, 64) if full else (24,)
    table = Table(title="The flow solver on the differentially heated cube (3-D, Pr 0.71; "
                  "reference, whitted, error)")
    for col in ("Ra", "grid", "Nu ref", "Nu (hot wall)", "error", "u_max", "v_max", "steps",
                "M cell updates/s"):
        table.add_column(col, justify="right")
    for r in v.cube_rows(cubes):
        table.add_row(f"{r['ra']:.0e}", r["grid"], f"{r['nu_ref']:.3f}", f"{r['nu']:.4f}",
                      f"{r['nu_error_pct']:+.2f} %", f"{r['u_max']:.3f}", f"{r['v_max']:.3f}",
                      "" if r["steps"] is None else str(r["steps"]),
                      "" if r["cell_updates_per_s"] is None
                      else f"{r['cell_updates_per_s'] / 1e6:.1f}")
    out.print(table)
    out.print("cube reference: Tric et al. (2000) and Wakashima & Saitoh (2004) as a secondary "
              "source quotes them (docs/stefan.md); velocity maxima at z = 1/2 in units of "
              "alpha/L, no reference read")

    table = Table(title="Gallium melting from a heated wall (Gau & Viskanta 1986), 2-D: the "
                  "melted length over the width (measured, whitted)")
    for col in ("cells", "t (min)", "top ref", "top", "middle ref", "middle", "bottom ref",
                "bottom", "melted ref", "melted", "error", "energy (rel.)"):
        table.add_column(col, justify="right")
    for mm, last in (((4.0, None), (2.0, None)) if full else ((4.0, 3),)):
        for r in v.gallium_rows(mm, last=last):
            table.add_row(r["cells"], f"{r['minutes']:.1f}", f"{r['top_ref']:.3f}",
                          f"{r['top']:.3f}", f"{r['middle_ref']:.3f}", f"{r['middle']:.3f}",
                          f"{r['bottom_ref']:.3f}", f"{r['bottom']:.3f}",
                          "-" if math.isnan(r["melted_ref"]) else f"{r['melted_ref']:.3f}",
                          f"{r['melted']:.3f}",
                          "-" if math.isnan(r["melted_ref"]) else
                          f"{100 * (r['melted'] / r['melted_ref'] - 1):+.1f} %",
                          f"{r['energy_rel']:.1e}")
    out.print(table)
    table = Table(title="Gallium at Blais & Ilinca's Ra 1e5 (their 2-D computation's case): "
                  "the melted fraction (measured at Ra 6.1e5, Blais & Ilinca, whitted)")
    for col in ("cells", "t (min)", "tau", "measured", "Blais & Ilinca", "whitted", "error",
                "top", "middle", "bottom"):
        table.add_column(col, justify="right")
    for mm in ((4.0, 2.0) if full else (4.0,)):
        for r in v.gallium_ra_1e5_rows(mm):
            table.add_row(r["cells"], f"{r['minutes']:.1f}", f"{r['tau']:.4f}",
                          "-" if math.isnan(r["melted_ref"]) else f"{r['melted_ref']:.3f}",
                          f"{r['melted_blais']:.3f}", f"{r['melted']:.3f}",
                          f"{100 * (r['melted'] / r['melted_blais'] - 1):+.1f} %",
                          f"{r['top']:.3f}",
                          f"{r['middle']:.3f}", f"{r['bottom']:.3f}")
    out.print(table)

    slab = v.convective_slab()
    out.print(f"convective slab (h = 20 W/m²K, air 20 °C, 3000 s): receded "
              f"{slab['receded_mm']:.4f} mm, h dT t / (rho_i L) = {slab['expected_mm']:.4f} mm, "
              f"error {slab['error_pct']:+.3f} %")
    sphere = v.sphere_roundness()
    out.print(f"sphere of ice (radius 9 cells, 2400 s): radius spread "
              f"{sphere['spread_start_cells']:.2f} -> {sphere['spread_end_cells']:.2f} cells; "
              f"receded {sphere['receded_mm']:.3f} mm by volume, exact "
              f"{sphere['receded_exact_mm']:.3f} mm")
    energy = v.energy_balance()
    out.print(f"energy (default case, 16 cells, 600 s): enthalpy change "
              f"{energy['enthalpy_change_J']:.6f} J = heat in {energy['heat_in_J']:.6f} J - "
              f"drained {energy['drained_J']:.6f} J; imbalance {energy['imbalance_J']:.1e} J "
              f"({energy['relative']:.1e} relative)")
    if plot is not None:
        v.plot_front(plot)
        out.print(f"plot -> {plot}")
    out.print(f"({time.perf_counter() - t0:.1f} s)")


def _thread_counts(text: str) -> tuple[int, ...]:
    try:
        counts = tuple(int(t) for t in text.split(",") if t.strip())
    except ValueError:
        counts = ()
    if not counts or any(c < 1 or c > 1024 for c in counts):
        raise _fail(f"--threads: {text!r} is not a list of thread counts (e.g. 1,2)")
    return counts


@app.command()
def bench(
    cells: Annotated[int, typer.Option("--cells", help="The enthalpy step's grid: the default "
                                       "case at this many cells a side")] = 64,
    flow_cells: Annotated[int, typer.Option("--flow-cells", help="The flow solver's cube: "
                                            "this many cells a side")] = 48,
    threads: Annotated[str, typer.Option("--threads", "-t",
                                         help="Thread counts, alternating run by run")] = "1,2",
    runs: Annotated[int, typer.Option("--runs", "-n", help="Timed runs per thread count")] = 5,
    steps: Annotated[int, typer.Option("--steps", help="Enthalpy steps a run")] = 200,
    json_path: Annotated[Path | None, typer.Option("--json", "-o",
                                                   help="Write the runs (JSON)")] = None,
) -> None:
    """The solvers' throughput in cell updates a second (median and best run, per thread,
    speed-up over one thread): the enthalpy step on the default case without the cavity's
    convection, and the flow solver on the heated cube. Run it on a quiet machine; the
    processor and the load average are printed beside the figures."""
    from rich.table import Table

    from .. import machine
    from ..stefan import bench as b

    counts = _thread_counts(threads)
    for option, value, low, high in (("--cells", cells, 8, 400), ("--flow-cells", flow_cells, 8,
                                                                   256),
                                     ("--runs", runs, 1, 1000), ("--steps", steps, 1, 100000)):
        if not low <= value <= high:
            raise _fail(f"{option}: {value} is outside {low}..{high}")
    if json_path is not None:
        from ..output.safety import check_output_place

        try:
            check_output_place(json_path)
        except WhittedError as exc:
            raise _fail(f"--json: {exc}") from None
    load = machine.load_average()
    usable = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
              else os.cpu_count())
    out.print(f"CPU: {machine.cpu_name()}; {usable} cores usable; load average "
              f"{'unknown' if load is None else f'{load:.2f}'}")
    guard = InterruptGuard(at_once=True)
    try:
        with guard:
            rows = b.measure(cells=cells, flow_cells=flow_cells, threads=counts, runs=runs,
                             steps=steps)
    except KeyboardInterrupt:
        raise guard.exit("the benchmark stopped before its table; nothing written") from None
    table = Table(title="Cell updates a second (M), the thread counts alternating run by run")
    for col in ("solver", "cells", "threads", "median", "best", "per thread", "speed-up"):
        table.add_column(col, justify="right")
    one = {r.solver: r.median for r in rows if r.threads == 1}
    for r in rows:
        base = one.get(r.solver)
        table.add_row(r.solver, f"{r.cells:,}", str(r.threads), f"{r.median / 1e6:.1f}",
                      f"{r.best / 1e6:.1f}", f"{r.per_thread / 1e6:.1f}",
                      "" if base is None else f"{r.median / base:.2f}x")
    out.print(table)
    load = machine.load_average()
    out.print(f"load average after: {'unknown' if load is None else f'{load:.2f}'}")
    if json_path is not None:
        import json

        from ..files.atomic import atomic_write

        data = {"cpu": machine.cpu_name(), "rows": [
            {"solver": r.solver, "cells": r.cells, "threads": r.threads, "steps": r.steps,
             "cell_updates_per_s": r.runs} for r in rows]}
        atomic_write(json_path, lambda tmp: Path(tmp).write_text(json.dumps(data, indent=1)))
        out.print(f"wrote {json_path}")


def _check_film_options(case_path: Path, output: Path, gif: Path | None, width: int,
                        height: int, fps: float) -> None:
    """What the film's options must be, checked before the solve (one line naming the
    option): the image size, the frame rate each film's format takes, and films that can be
    written where they go without writing over the case file or each other."""
    from pydantic import ValidationError

    from ..output.safety import check_outputs
    from ..output.video import check_fps, video_format
    from ..scene.scene import RenderSettings

    try:
        RenderSettings(width=width, height=height)
    except ValidationError as exc:
        from .app import override_error

        raise _fail(override_error(exc, {"width": width, "height": height})) from None
    films = [output, *([gif] if gif is not None else [])]
    formats = []
    for option, path in zip(("-o", "--gif"), films, strict=False):
        try:
            formats.append(video_format(path))
        except ValueError as exc:
            raise _fail(f"{option}: {path}: {exc}") from None
    for fmt in formats:
        try:
            check_fps(fps, fmt)
        except ValueError as exc:
            raise _fail(f"--fps: {exc}") from None
    if gif is not None and output.resolve() == gif.resolve():
        raise _fail(f"--gif: {gif} is the film -o names too")
    try:
        check_outputs(films, inputs=[case_path])
    except WhittedError as exc:
        raise _fail(str(exc)) from None


@app.command()
def film(
    case_path: Annotated[Path, typer.Argument(metavar="CASE", help="Case file (TOML)")],
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="Film: .mp4 or .gif [default: melt.mp4]")] = None,
    width: Annotated[int, typer.Option("--width", "-W", help="Frame width")] = 480,
    height: Annotated[int, typer.Option("--height", "-H", help="Frame height")] = 360,
    fps: Annotated[float, typer.Option("--fps", help="Frames per second")] = 8.0,
    gif: Annotated[Path | None, typer.Option("--gif", help="Also write a GIF")] = None,
    fresh: Annotated[bool, typer.Option("--fresh", help="Solve again from t = 0")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar")] = False,
) -> None:
    """Solve CASE (or resume it) into OUTPUT's folder NAME_stefan/, render one frame per saved
    time (the piece on a table, backlit; ice 1.31, water 1.333, measured absorption, 4 samples
    per pixel) and encode the film with the simulated time in each frame. Ctrl-C or SIGTERM
    keeps the solved times and the finished frames; run again to continue."""
    from ..render.api import CancelToken
    from ..stefan.film import render_melt_film

    started = time.perf_counter()
    if output is None:  # a name the user did not give: it replaces only whitted's film
        from .app import check_default_output

        output = Path("melt.mp4")
        check_default_output(output)
    _check_film_options(case_path, output, gif, width, height, fps)
    work = output.with_name(output.stem + "_stefan")
    with InterruptGuard() as guard:
        case, result = _solve(case_path, work, fresh, quiet, guard, size=(width, height))
        _report(result)
        if result.interrupted:
            raise guard.exit(f"while solving: kept every saved time in {work}; run the same "
                             "command again to continue")
        cancel = CancelToken()
        guard.on_interrupt(cancel.cancel)
        try:
            made = render_melt_film(work, case, [output, *([gif] if gif is not None else [])],
                                    width=width, height=height, fps=fps, cancel=cancel,
                                    progress=None if quiet else _frame_line)
        except WhittedError as exc:
            raise _fail(str(exc)) from None
        if made.cancelled:
            if len(made.frames) == made.count:
                raise guard.exit(f"every frame is in {work / 'frames'}; the film was not "
                                 "written")
            raise guard.exit(f"{len(made.frames)} of {made.count} frames finished in "
                             f"{work / 'frames'}; run the same command again to continue")
    out.print(f"{made.count} frames ({made.render_seconds / made.count:.2f} s a frame, wall) "
              f"-> {output}" + (f", {gif}" if gif is not None else "")
              + f"; total {time.perf_counter() - started:.1f} s")


def _frame_line(p) -> None:
    """One line per frame finished (render_film's progress), on stdout."""
    if p.event == "done":
        state = f"{p.result.seconds:.2f} s" if p.result.rendered else "already done"
        out.echo(f"frame {p.frame} ({p.done}/{p.total}): {state}")
