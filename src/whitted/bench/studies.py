"""The seeds' research sections, reproduced: render time versus the number of threads and
versus the image size, as tables and as plots (matplotlib PNG).

001 (Core i3-10100F, 8 logical cores, its own C++ tracer) timed its ice scene at square sizes
S = 128 ... 640 with 1, 2, 4, 8 and 16 threads; 000 (Core i3-8130U, 4 logical cores) timed its
809 x 817 scene against the thread count. :data:`SEED_001_TIMES` keeps 001's table for context.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..render.api import available_threads
from .runner import BenchOptions, BenchResult, run_bench

STUDY_SIZES = (128, 256, 352, 448, 512, 640)
STUDY_DEFAULT_SCENE = {"threads": "seed000", "size": "ice"}

#: 001's table 4.1: S -> microseconds (serial, then 1, 2, 4, 8, 16 threads)
SEED_001_TIMES: dict[int, tuple[int, ...]] = {
    128: (273_311, 556_595, 339_305, 278_957, 279_667, 292_878),
    256: (2_023_442, 3_103_714, 1_829_316, 1_395_264, 1_397_786, 1_384_682),
    352: (3_739_262, 5_731_390, 3_464_986, 2_533_300, 2_478_940, 2_608_794),
    448: (6_302_434, 9_693_502, 5_783_250, 4_178_672, 4_100_138, 4_188_324),
    512: (9_245_362, 13_801_280, 8_086_786, 5_764_098, 5_463_540, 6_166_600),
    640: (14_072_760, 20_832_840, 12_204_240, 8_941_954, 8_551_252, 9_452_858),
}
SEED_001_THREADS = ("serial", 1, 2, 4, 8, 16)


def study_thread_counts(cores: int | None = None) -> list[int]:
    """1, 2, 4, ... up to the number of cores (and the core count itself)."""
    cores = cores or available_threads()
    counts = []
    n = 1
    while n <= cores:
        counts.append(n)
        n *= 2
    if counts[-1] != cores:
        counts.append(cores)
    return counts


def run_study(kind: str, options: BenchOptions,
              log: Callable[[str], None] = print) -> BenchResult:
    """``kind`` = ``threads``: one scene at its own size, 1, 2, 4, ... threads; ``size``: one
    scene at S x S for every S of 001's table, at each thread count asked (default 1 and
    every core)."""
    if kind not in STUDY_DEFAULT_SCENE:
        raise ValueError(f"unknown study {kind!r} (threads or size)")
    scenes = options.scenes or [STUDY_DEFAULT_SCENE[kind]]
    if kind == "threads":
        return run_bench(replace(options, scenes=scenes,
                                 threads=options.threads or study_thread_counts()), log)
    cores = available_threads()
    threads = options.threads or sorted({1, cores})
    sizes = [(s, s) for s in STUDY_SIZES] if not options.quick else [(16, 16), (32, 32)]
    result = BenchResult()
    for size in sizes:
        part = run_bench(replace(options, scenes=scenes, threads=threads, size=size), log)
        result.rows += part.rows
        result.skipped += part.skipped
    return result


def speedups(rows: list[dict[str, Any]]) -> dict[tuple[str, int, int], float]:
    """render_s with the fewest threads / render_s, per (scene, width, threads)."""
    base: dict[tuple[str, int], dict[str, Any]] = {}
    for r in rows:
        key = (r["scene"], r["width"])
        if key not in base or r["threads"] < base[key]["threads"]:
            base[key] = r
    return {(r["scene"], r["width"], r["threads"]):
            base[(r["scene"], r["width"])]["render_s"] / r["render_s"] if r["render_s"] else 0.0
            for r in rows}


def study_markdown(kind: str, rows: list[dict[str, Any]]) -> str:
    """The study as a Markdown table (times in seconds)."""
    compare = any("povray_trace_s" in r for r in rows)
    gains = speedups(rows)
    head = ["scene", "size", "threads", "render s", "wall s", "speed-up", "Mrays/s"]
    if compare:
        head += ["POV trace s", "POV wall s", "render ratio"]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(" --- " for _ in head) + "|"]
    for r in sorted(rows, key=lambda r: (r["scene"], r["width"], r["threads"])):
        cells = [r["scene"], f"{r['width']}x{r['height']}", str(r["threads"]),
                 f"{r['render_s']:.3f}", f"{r['wall_s']:.3f}",
                 f"{gains[(r['scene'], r['width'], r['threads'])]:.2f}",
                 f"{r['mrays_per_s']:.2f}"]
        if compare:
            cells += [f"{r.get('povray_trace_s', float('nan')):.3f}",
                      f"{r.get('povray_wall_s', float('nan')):.3f}",
                      f"{r.get('ratio_render', float('nan')):.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot_study(kind: str, rows: list[dict[str, Any]], path: Path,
               with_seed: bool = True) -> Path:
    """Plot the study to a PNG: time against threads, or against S with a line per thread
    count (POV-Ray dashed when measured; 001's own numbers in grey for context)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.4), dpi=110)
    scenes = sorted({r["scene"] for r in rows})
    if kind == "threads":
        for scene in scenes:
            mine = sorted((r for r in rows if r["scene"] == scene), key=lambda r: r["threads"])
            x = [r["threads"] for r in mine]
            ax.plot(x, [r["render_s"] for r in mine], "o-", label=f"whitted {scene}: render")
            ax.plot(x, [r["wall_s"] for r in mine], "s-", label=f"whitted {scene}: whole process")
            if all("povray_trace_s" in r for r in mine):
                ax.plot(x, [r["povray_trace_s"] for r in mine], "o--",
                        label=f"POV-Ray {scene}: trace")
                ax.plot(x, [r["povray_wall_s"] for r in mine], "s--",
                        label=f"POV-Ray {scene}: whole process")
            ax.set_xticks(x)
        ax.set_xlabel("threads")
        ax.set_title("Render time against the number of threads")
    else:
        for scene in scenes:
            for threads in sorted({r["threads"] for r in rows if r["scene"] == scene}):
                mine = sorted((r for r in rows if r["scene"] == scene and r["threads"] == threads),
                              key=lambda r: r["width"])
                x = [r["width"] for r in mine]
                line, = ax.plot(x, [r["render_s"] for r in mine], "o-",
                                label=f"whitted {scene}, {threads} thread(s)")
                if all("povray_trace_s" in r for r in mine):
                    ax.plot(x, [r["povray_trace_s"] for r in mine], "o--",
                            color=line.get_color(),
                            label=f"POV-Ray {scene}, {threads} thread(s)")
        if with_seed:
            sizes = sorted(SEED_001_TIMES)
            for column, style in ((1, ":"), (4, "-.")):
                ax.plot(sizes, [SEED_001_TIMES[s][column] / 1e6 for s in sizes], style,
                        color="grey", label=f"001 (C++, i3-10100F), "
                                            f"{SEED_001_THREADS[column]} thread(s)")
        ax.set_xlabel("image side S (S x S pixels)")
        ax.set_yscale("log")
        ax.set_title("Render time against the image size")
    ax.set_ylabel("seconds (median)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    from ..files import atomic_write
    from ..output.png import SOFTWARE

    # the PNG says whitted wrote it (Software): the default name is replaced only then
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png",
                                               metadata={"Software": SOFTWARE.decode()}))
    plt.close(fig)
    return path
