"""``whitted bench``: render the standard scenes, time every stage, optionally beside POV-Ray.

Each (scene, thread count) is rendered once as a warm-up (fills the kernel cache and the
operating system's file cache; not counted), then ``runs`` times; every number reported is the
median over those runs. By default every run is a fresh ``whitted render`` process, started as
a user starts it, so the wall time is a user's wall time; ``--quick``
and ``in_process`` render inside this process instead (start-up is then just the scene load).
Beside POV-Ray (``--compare povray``) the two renderers' runs alternate, and each ratio is the
median of the ratios of the pairs (a run of whitted and the POV-Ray run after it).

The columns (also the JSON keys, see docs/performance.md):

- ``startup_s``: the rest of the process's wall time: starting Python, imports, reading the
  scene and its models, writing the PNG (``wall_s − compile_s − build_s − render_s``);
- ``compile_s``: loading the compiled kernels from the on-disk cache (compiling them when the
  cache is cold: the warm-up run does that, so the median is a cache load);
- ``build_s``: flattening the scene and building the BVH;
- ``render_s``: tracing the image (all threads, wall clock);
- ``wall_s``: the whole process from launch to exit;
- ``mrays_per_s``: all rays (primary, shadow, reflection, refraction) / render_s / 10⁶;
- ``peak_mib``: the process's peak resident memory.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..marks import ENV as MARKS_ENV
from ..render.api import RAY_KIND_NAMES, RenderJob, available_threads
from ..scene.scene import Scene
from .models import MissingSourceModel
from .scenes import BenchScene, has_meshes, load_bench_scene, pick_scenes
from .startup import read_marks
from .timing import timed_process

RAY_KINDS = tuple(RAY_KIND_NAMES.values())  # primary, shadow, reflection, refraction
QUICK_WIDTH = 48
TIMES = ("startup_s", "compile_s", "build_s", "render_s", "wall_s")


class BenchError(RuntimeError):
    """A benchmark that cannot run (a scene that fails to render, POV-Ray failing)."""


@dataclass
class BenchOptions:
    scenes: list[str] | None = None  # None: every scene (the quick ones with quick)
    runs: int = 5
    threads: list[int] | None = None  # None: every core
    quick: bool = False  # tiny images, one run, in this process, no 1M-triangle mesh
    compare: str | None = None  # "povray" or "embree" (the mesh scenes' rays, one thread)
    in_process: bool = False
    size: tuple[int, int] | None = None  # override every scene's image size
    warmup: bool = True
    rays: bool = False  # also the render time by kind of ray (bench/breakdown.py)

    def effective(self) -> BenchOptions:
        if not self.quick:
            return self
        return BenchOptions(scenes=self.scenes, runs=1, threads=self.threads or [1],
                            quick=True, compare=self.compare, in_process=True,
                            size=self.size, warmup=self.warmup, rays=self.rays)


@dataclass
class BenchResult:
    rows: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (scene, why)


def image_size(scene: Scene, options: BenchOptions) -> tuple[int, int]:
    if options.size is not None:
        return options.size
    r = scene.render
    if options.quick:
        return QUICK_WIDTH, max(1, round(QUICK_WIDTH * r.height / r.width))
    return r.width, r.height


def run_bench(options: BenchOptions, log: Callable[[str], None] = print) -> BenchResult:
    """Render every chosen scene at every thread count; one row per (scene, threads)."""
    options = options.effective()
    if options.runs < 1:
        raise BenchError("--runs must be at least 1")
    threads_list = options.threads or [available_threads()]
    result = BenchResult()
    for spec in pick_scenes(options.scenes, options.quick):
        try:
            scene = load_bench_scene(spec.name, quick=options.quick)
        except MissingSourceModel as exc:
            result.skipped.append((spec.name, str(exc)))
            log(f"  skipped {spec.name}: {exc}")
            continue
        width, height = image_size(scene, options)
        scene = scene.with_settings(width=width, height=height)
        with tempfile.TemporaryDirectory(prefix=f"whitted-bench-{spec.name}-") as tmp:
            folder = Path(tmp)
            for threads in threads_list:
                log(f"{spec.name} {width}x{height}, {threads} thread(s)")
                try:
                    if options.compare == "povray":
                        row = _bench_side_by_side(spec, scene, threads, options, folder)
                    else:
                        row = _bench_whitted(spec, scene, threads, options, folder)
                except BenchError as exc:
                    if not has_meshes(scene):
                        raise
                    # meshes may not render yet on a tree where they are being integrated
                    result.skipped.append((spec.name, f"its meshes do not render: {exc}"))
                    log(f"  skipped {spec.name}: {exc}")
                    break
                if options.rays:
                    from .breakdown import time_by_kind

                    measure = _in_process_run if options.in_process else _process_run
                    log(f"{spec.name}: time by kind of ray, {threads} thread(s)")
                    row["time_by_kind"] = time_by_kind(scene, threads, options.runs, folder,
                                                       measure)
                result.rows.append(row)
        if options.compare == "embree" and spec.meshes and result.rows \
                and result.rows[-1]["scene"] == spec.name:
            log(f"{spec.name}: the same camera and shadow rays, whitted and Embree, 1 thread")
            embree = _bench_embree(scene)
            for row in result.rows:
                if row["scene"] == spec.name:
                    row.update(embree)
    return result


def _bench_embree(scene: Scene) -> dict[str, Any]:
    from .embree import compare_embree

    try:
        return compare_embree(scene)
    except (ImportError, ValueError) as exc:
        raise BenchError(str(exc)) from None


def _median(values: list[float]) -> float:
    return float(statistics.median(values))


def _bench_whitted(spec: BenchScene, scene: Scene, threads: int, options: BenchOptions,
                   folder: Path) -> dict[str, Any]:
    measure = _in_process_run if options.in_process else _process_run
    warmup = measure(scene, threads, folder) if options.warmup else None
    runs = [measure(scene, threads, folder) for _ in range(options.runs)]
    return _whitted_row(spec, scene, threads, options, runs, warmup)


def _whitted_row(spec: BenchScene, scene: Scene, threads: int, options: BenchOptions,
                 runs: list[dict[str, Any]], warmup: dict[str, Any] | None) -> dict[str, Any]:
    row: dict[str, Any] = {
        "scene": spec.name, "width": scene.render.width, "height": scene.render.height,
        "threads": threads, "runs": len(runs),
        "mode": "in-process" if options.in_process else "process",
        "rays": {k: int(runs[0]["rays"].get(k, 0)) for k in RAY_KINDS},
    }
    row["rays_total"] = sum(row["rays"].values())
    for key in (*TIMES, "peak_mib"):
        row[key] = _median([r[key] for r in runs])
    if options.in_process and warmup is not None:
        # in one process the kernels load once, in the warm-up: that is the cost to report
        row["compile_s"] = max(row["compile_s"], warmup["compile_s"])
    row["mrays_per_s"] = (row["rays_total"] / row["render_s"] / 1e6
                          if row["render_s"] > 0 else 0.0)
    return row


def _bench_side_by_side(spec: BenchScene, scene: Scene, threads: int, options: BenchOptions,
                        folder: Path) -> dict[str, Any]:
    """whitted and POV-Ray on the same scene, their runs alternating (whitted, POV-Ray,
    whitted, ...) after a warm-up of each, so a machine that speeds up or slows down while
    the bench runs (another process, the clock) weighs on both alike. The ratios are the
    medians of each pair's ratio."""
    measure = _in_process_run if options.in_process else _process_run
    povray_once = _povray_runner(spec, scene, threads, folder)
    warmup = None
    if options.warmup:
        warmup = measure(scene, threads, folder)
        povray_once()
    runs, pov_runs = [], []
    for _ in range(options.runs):
        runs.append(measure(scene, threads, folder))
        pov_runs.append(povray_once())
    row = _whitted_row(spec, scene, threads, options, runs, warmup)
    row.update(_povray_columns(runs, pov_runs))
    return row


def _in_process_run(scene: Scene, threads: int, folder: Path) -> dict[str, Any]:
    start = time.perf_counter()
    job = RenderJob(scene, threads=threads)
    try:
        job.run()
    except Exception as exc:  # noqa: BLE001 - reported as the scene's failure
        raise BenchError(f"{type(exc).__name__}: {exc}") from exc
    wall = time.perf_counter() - start
    s = job.stats
    return {
        "rays": dict(s.rays), "compile_s": s.compile_seconds, "build_s": s.build_seconds,
        "render_s": s.render_seconds, "wall_s": wall,
        "photon_s": s.photons.seconds if s.photons is not None else 0.0,
        "startup_s": max(0.0, wall - s.compile_seconds - s.build_seconds - s.render_seconds),
        "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def _process_run(scene: Scene, threads: int, folder: Path) -> dict[str, Any]:
    """One ``whitted render`` process, as a user starts it (its own early exit and collector
    settings included), timed from outside; the job's figures from its marks
    (whitted/marks.py)."""
    scene_file = folder / "scene.json"
    if not scene_file.exists():
        scene.save(scene_file)
    marks_file = folder / "marks.jsonl"
    marks_file.unlink(missing_ok=True)
    command = [sys.executable, "-m", "whitted", "render", str(scene_file), "-q",
               "-o", str(folder / "whitted.png"), "--threads", str(threads)]
    run = timed_process(command, env=dict(os.environ, **{MARKS_ENV: str(marks_file)}))
    if run.returncode != 0:
        tail = " | ".join(run.stderr.strip().splitlines()[-3:])
        raise BenchError(f"the render process failed (exit {run.returncode}): {tail}")
    marks = read_marks(marks_file)
    missing = [f"{name}:seconds" for name in ("kernels", "build", "render")
               if f"{name}:seconds" not in marks]
    if missing:
        raise BenchError(f"the render process noted no {', '.join(missing)}")
    compile_s, build_s, render_s = (marks["kernels:seconds"], marks["build:seconds"],
                                    marks["render:seconds"])
    rays = {name[len("rays:"):-len(":count")]: int(value) for name, value in marks.items()
            if name.startswith("rays:") and name.endswith(":count")}
    return {
        "rays": rays, "compile_s": compile_s, "build_s": build_s, "render_s": render_s,
        "wall_s": run.wall_s, "photon_s": marks.get("photons:seconds", 0.0),
        "startup_s": max(0.0, run.wall_s - compile_s - build_s - render_s),
        "peak_mib": run.peak_mib,
    }


def _povray_runner(spec: BenchScene, scene: Scene, threads: int,
                   folder: Path) -> Callable[[], Any]:
    """One POV-Ray render of the scene (exported once, into ``folder``) per call."""
    from ..export.pov import export_pov
    from .povray import PovrayError, run_povray

    pov_file = folder / f"{spec.name}.pov"
    if not pov_file.exists():
        export_pov(scene, pov_file, source=f"benchmarks/{spec.file}")
    linear = scene.render.transfer == "linear"

    def once():
        try:
            return run_povray(pov_file, folder / "povray.png", scene.render.width,
                              scene.render.height, threads, linear)
        except PovrayError as exc:
            raise BenchError(str(exc)) from None

    return once


def _ratio(a: float, b: float) -> float:
    return a / b if b > 0 else float("inf")


def _povray_columns(runs: list[dict[str, Any]], pov_runs: list[Any]) -> dict[str, Any]:
    """POV-Ray's columns, from its runs made alternately with whitted's ``runs``."""
    trace = _median([r.trace_s for r in pov_runs])
    return {
        "povray_trace_s": trace,
        "povray_parse_s": _median([r.parse_s for r in pov_runs]),
        "povray_bounding_s": _median([r.bounding_s for r in pov_runs]),
        "povray_wall_s": _median([r.wall_s for r in pov_runs]),
        "povray_peak_mib": _median([r.peak_mib for r in pov_runs]),
        "povray_rays": pov_runs[0].rays,
        "povray_mrays_per_s": (sum(pov_runs[0].rays.values()) / trace / 1e6 if trace > 0
                               else 0.0),
        "ratio_render": _median([_ratio(w["render_s"], p.trace_s)
                                 for w, p in zip(runs, pov_runs, strict=True)]),
        "ratio_wall": _median([_ratio(w["wall_s"], p.wall_s)
                               for w, p in zip(runs, pov_runs, strict=True)]),
    }


# -- output ---------------------------------------------------------------------------------

def compact(n: int) -> str:
    """A ray count in a few characters: 812, 45.3k, 1.31M."""
    if n < 1000:
        return str(n)
    if n < 1_000_000:
        return f"{n / 1e3:.1f}k" if n < 100_000 else f"{n / 1e3:.0f}k"
    return f"{n / 1e6:.2f}M" if n < 100_000_000 else f"{n / 1e6:.0f}M"


TABLE_COLUMNS = ("scene", "size", "threads", "primary", "shadow", "reflection", "refraction",
                 "startup s", "compile s", "build s", "render s", "wall s", "Mrays/s",
                 "peak MiB")
POVRAY_COLUMNS = ("POV trace s", "POV wall s", "render ratio", "wall ratio",
                  "POV rays p/s/rl/rr")
EMBREE_COLUMNS = ("tracer", "trace Mrays/s", "Embree Mrays/s", "of Embree", "walk of Embree")


def table_rows(rows: list[dict[str, Any]]) -> tuple[list[str], list[list[str]]]:
    """Column headings and text cells of the results table."""
    compare = any("povray_trace_s" in r for r in rows)
    embree = any("embree_mrays_per_s" in r for r in rows)
    columns = (list(TABLE_COLUMNS) + (list(POVRAY_COLUMNS) if compare else [])
               + (list(EMBREE_COLUMNS) if embree else []))
    cells = []
    for r in rows:
        line = [r["scene"], f"{r['width']}x{r['height']}", str(r["threads"]),
                *(compact(r["rays"][k]) for k in RAY_KINDS),
                *(f"{r[k]:.3f}" for k in TIMES), f"{r['mrays_per_s']:.2f}",
                f"{r['peak_mib']:.0f}"]
        if compare:
            if "povray_trace_s" in r:
                pov = r["povray_rays"]
                line += [f"{r['povray_trace_s']:.3f}", f"{r['povray_wall_s']:.3f}",
                         f"{r['ratio_render']:.2f}", f"{r['ratio_wall']:.2f}",
                         "/".join(compact(pov[k]) for k in RAY_KINDS)]
            else:
                line += [""] * len(POVRAY_COLUMNS)
        if embree:
            if "embree_mrays_per_s" in r:
                line += [r.get("whitted_mesh_tracer", "whitted"),
                         f"{r['whitted_trace_mrays_per_s']:.2f}",
                         f"{r['embree_mrays_per_s']:.2f}", f"{r['ratio_embree']:.2f}",
                         f"{r.get('ratio_embree_walk', r['ratio_embree']):.2f}"]
            else:
                line += [""] * len(EMBREE_COLUMNS)
        cells.append(line)
    return columns, cells


def rich_table(rows: list[dict[str, Any]], title: str | None = None):
    from rich.table import Table

    columns, cells = table_rows(rows)
    table = Table(title=title, header_style="bold", pad_edge=False)
    for i, name in enumerate(columns):
        table.add_column(name, justify="left" if i == 0 else "right", no_wrap=True)
    for line in cells:
        table.add_row(*line)
    return table


def markdown_table(rows: list[dict[str, Any]]) -> str:
    columns, cells = table_rows(rows)
    out = ["| " + " | ".join(columns) + " |", "|" + "|".join(" --- " for _ in columns) + "|"]
    out += ["| " + " | ".join(line) + " |" for line in cells]
    return "\n".join(out)


def write_json(rows: list[dict[str, Any]], path: Path) -> Path:
    from ..files import atomic_write

    text = json.dumps(rows, indent=2) + "\n"
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    return path
