"""What ``whitted bench`` does once its options are parsed (the CLI is a thin wrapper)."""

from __future__ import annotations

import platform
from pathlib import Path

from rich.console import Console

from ..errors import WhittedError
from ..render.api import available_threads
from .runner import BenchError, BenchOptions, rich_table, run_bench, write_json
from .studies import plot_study, run_study, study_markdown


class BenchUsageError(WhittedError):
    """A bad ``whitted bench`` option (one line, exit status 2)."""


def parse_threads(text: str | None) -> list[int] | None:
    """``"1,2"`` -> [1, 2]; ``"all"`` or 0 -> every core."""
    if not text:
        return None
    counts = []
    for part in text.split(","):
        part = part.strip().lower()
        if part in ("all", "0"):
            counts.append(available_threads())
            continue
        if not part.isdigit() or int(part) < 1:
            raise BenchUsageError(f"--threads: expected counts like 1,2 (got {part!r})")
        counts.append(int(part))
    return list(dict.fromkeys(counts))


def parse_size(text: str | None) -> tuple[int, int] | None:
    if not text:
        return None
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise BenchUsageError(
            f"--size: expected WIDTHxHEIGHT such as 320x240 (got {text!r})") from None
    if w < 1 or h < 1:
        raise BenchUsageError(f"--size: width and height must be positive (got {text!r})")
    from pydantic import ValidationError

    from ..scene.messages import describe_validation_error
    from ..scene.scene import RenderSettings

    try:  # the limits of any render (100,000 a side, 100 megapixels), in the option's name
        RenderSettings(width=w, height=h)
    except ValidationError as exc:
        where, message = describe_validation_error(exc)
        where = where.rsplit(".", 1)[-1]  # the field, not the settings' class
        raise BenchUsageError(f"--size: {where + ': ' if where else ''}{message}") from None
    return w, h


def _check_runs_and_povray(runs: int, compare: str | None) -> None:
    """--runs is at least 1, and POV-Ray is installed when it is to be compared with."""
    if runs < 1:
        raise BenchUsageError("--runs: must be at least 1")
    if compare == "povray":
        from .povray import povray_executable

        if povray_executable() is None:
            raise BenchUsageError("--compare povray: povray is not installed "
                                  "(Debian: apt-get install povray)")


def bench_main(
    *, scenes: list[str] | None, runs: int, threads: str | None, quick: bool,
    compare: str | None, study: str | None, json_path: Path | None, plot_path: Path | None,
    markdown_path: Path | None, size: str | None, in_process: bool,
    out: Console, err: Console, rays: bool = False,
) -> None:
    if compare not in (None, "povray", "embree"):
        raise BenchUsageError(f"--compare: unknown renderer {compare!r} (known: povray, embree)")
    if compare == "embree":
        from .embree import embree_available

        if not embree_available():
            raise BenchUsageError("--compare embree needs embreex: pip install 'whitted[bench]'")
    if study not in (None, "threads", "size"):
        raise BenchUsageError(f"--study: unknown study {study!r} (threads or size)")
    _check_runs_and_povray(runs, compare)
    if study:
        import importlib.util

        if importlib.util.find_spec("matplotlib") is None:  # checked before the long study
            raise BenchUsageError(f"--study {study}: the plot needs matplotlib: "
                                  "pip install 'whitted[plots]'")
    options = BenchOptions(scenes=scenes or None, runs=runs, threads=parse_threads(threads),
                           quick=quick, compare=compare, in_process=in_process,
                           size=parse_size(size), rays=rays)
    if rays and study:
        raise BenchUsageError("--rays: not with --study (it times the scenes themselves)")

    def log(line: str) -> None:
        err.print(f"[dim]{line}[/]", highlight=False)

    err.print(f"[dim]whitted bench on {platform.processor() or platform.machine()}, "
              f"{available_threads()} usable core(s); "
              f"{'quick' if quick else f'median of {options.effective().runs} run(s)'}"
              " after a warm-up[/]")
    _say_compile_time(options, err)
    compile_builders_first(err)
    try:
        if study:
            result = run_study(study, options, log)
        else:
            result = run_bench(options, log)
    except BenchError as exc:
        raise BenchUsageError(str(exc)) from None
    for name, why in result.skipped:
        err.print(f"skipped {name}: {why}")
    if not result.rows:
        raise BenchUsageError("no scene could be rendered")
    title = f"whitted bench{' --study ' + study if study else ''}"
    _print_wide(out, rich_table(result.rows, title=title))
    if rays:
        from .breakdown import breakdown_table

        _print_wide(out, breakdown_table(result.rows))
    if json_path is not None:
        write_json(result.rows, json_path)
        out.print(f"wrote {json_path}")
    if study:
        plot = plot_path or Path(f"bench-study-{study}.png")
        plot_study(study, result.rows, plot, with_seed=not quick)
        out.print(f"wrote {plot}")
        if markdown_path is not None:
            markdown_path.write_text(study_markdown(study, result.rows) + "\n", encoding="utf-8")
            out.print(f"wrote {markdown_path}")
    elif markdown_path is not None:
        from .runner import markdown_table

        markdown_path.write_text(markdown_table(result.rows) + "\n", encoding="utf-8")
        out.print(f"wrote {markdown_path}")


def _print_wide(out: Console, table) -> None:
    """A table wide enough for every column, also when the output is a file or a pipe."""
    needed = Console(width=1000).measure(table).maximum
    if needed > out.width and not out.is_terminal:
        Console(file=out.file, width=needed, highlight=False).print(table)
    else:
        out.print(table)


def _say_compile_time(options: BenchOptions, err: Console) -> None:
    """Before a bench whose first runs compile kernels: how long that takes here (the last
    compile measured on this machine, jit/progress.py), said up front."""
    from ..jit.progress import expected_seconds
    from ..render.warm_up import kernels_cached
    from .scenes import pick_scenes

    if kernels_cached():
        return
    seconds = expected_seconds("the kernels")
    names = [s.name for s in pick_scenes(options.scenes, options.quick)]
    if "caustics" in names:
        seconds += expected_seconds("the caustics kernels")
    err.print(f"the kernels are not in the cache yet: the first runs compile them first, "
              f"about {seconds:.0f} s (`whitted warm` compiles every variant ahead of use)",
              highlight=False)


def compile_builders_first(err: Console) -> None:
    """A bench times a warmed cache (``whitted warm``'s): the scene builders compiled too.
    Before they are, a small scene's builders run as Python (jit/python_twins.py), a few
    hundredths of a second more per process; compiled here once if they are not yet."""
    from ..jit.python_twins import builders_cached
    from ..render.warm_up import compile_builders

    if builders_cached():
        return
    err.print("[dim]compiling the scene builders once (as `whitted warm` does), so that "
              "every run times the compiled ones[/]", highlight=False)
    compile_builders()


def startup_main(*, scenes: list[str] | None, runs: int, threads: str | None,
                 compare: str | None, json_path: Path | None, out: Console,
                 err: Console) -> None:
    """``whitted bench --startup``: the budget of a whole ``whitted render`` process for each
    scene (a benchmark's name or a scene file), beside POV-Ray with ``--compare povray``."""
    from ..machine import cpu_name
    from .startup import budget_table, scene_file_of, startup_budget

    if compare not in (None, "povray"):
        raise BenchUsageError(f"--compare: --startup compares with povray only (got {compare!r})")
    _check_runs_and_povray(runs, compare)
    counts = parse_threads(threads)
    if counts is not None and len(counts) > 1:
        raise BenchUsageError("--threads: --startup takes one thread count")
    count = counts[0] if counts else None

    names = scenes or ["seed000"]
    for name in names:  # checked before the header line: a mistake is one line
        scene_file_of(name)

    def log(line: str) -> None:
        err.print(f"[dim]{line}[/]", highlight=False)

    compile_builders_first(err)
    err.print(f"[dim]whitted bench --startup on {cpu_name()}, "
              f"{available_threads()} usable core(s); median of {runs} run(s) after a "
              "warm-up[/]")
    results = []
    for name in names:
        budget = startup_budget(name, runs=runs, threads=count, povray=compare == "povray",
                                log=log)
        out.print(budget_table(budget))
        results.append(budget.as_dict())
    if json_path is not None:
        write_json(results, json_path)
        out.print(f"wrote {json_path}")
