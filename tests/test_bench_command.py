"""``whitted bench`` below the command line: option parsing and its one-line errors, the size
study (tables, JSON, plot, Markdown) on the tiny lecture scene in this process, the results
table with POV-Ray and Embree columns, the process timer and POV-Ray's run. No timing asserts:
only counts, sizes and texts that follow from the options."""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import pytest
from rich.console import Console

from whitted.bench import command, povray, runner
from whitted.bench.command import BenchUsageError, bench_main, parse_size, parse_threads
from whitted.bench.runner import (
    BenchError,
    BenchOptions,
    BenchResult,
    compact,
    image_size,
    markdown_table,
    run_bench,
    table_rows,
)
from whitted.bench.studies import run_study, speedups, study_markdown
from whitted.bench.timing import timed_process
from whitted.render.api import available_threads
from whitted.scene import Scene


def _consoles(width: int = 80) -> tuple[Console, Console, io.StringIO, io.StringIO]:
    out, err = io.StringIO(), io.StringIO()
    return (Console(file=out, width=width, highlight=False),
            Console(file=err, width=200, highlight=False), out, err)


def _main(**options) -> tuple[str, str]:
    out, err, out_text, err_text = _consoles(options.pop("width", 80))
    args = dict(scenes=None, runs=1, threads=None, quick=True, compare=None, study=None,
                json_path=None, plot_path=None, markdown_path=None, size=None,
                in_process=True)
    args.update(options)
    bench_main(**args, out=out, err=err)
    return out_text.getvalue(), err_text.getvalue()


def test_thread_counts_and_sizes():
    cores = available_threads()
    assert parse_threads(None) is None and parse_threads("") is None
    assert parse_threads("1, 2,2,all") == list(dict.fromkeys([1, 2, cores]))
    assert parse_threads("0") == [cores]
    with pytest.raises(BenchUsageError) as info:
        parse_threads("1,-2")
    assert str(info.value) == "--threads: expected counts like 1,2 (got '-2')"
    assert parse_size(None) is None and parse_size("32X16") == (32, 16)
    with pytest.raises(BenchUsageError) as info:
        parse_size("9")
    assert str(info.value) == "--size: expected WIDTHxHEIGHT such as 320x240 (got '9')"
    with pytest.raises(BenchUsageError) as info:
        parse_size("0x5")
    assert str(info.value) == "--size: width and height must be positive (got '0x5')"


@pytest.mark.parametrize(("options", "message"), [
    ({"compare": "mitsuba"}, "--compare: unknown renderer 'mitsuba' (known: povray, embree)"),
    ({"study": "colour"}, "--study: unknown study 'colour' (threads or size)"),
    ({"runs": 0}, "--runs: must be at least 1"),
])
def test_bad_options(options, message):
    with pytest.raises(BenchUsageError) as info:
        _main(**options)
    assert str(info.value) == message


def test_missing_tools_are_named_before_any_work(monkeypatch):
    import importlib.util

    from whitted.bench import embree

    monkeypatch.setattr(embree, "embree_available", lambda: False)
    with pytest.raises(BenchUsageError) as info:
        _main(compare="embree")
    assert str(info.value) == "--compare embree needs embreex: pip install 'whitted[bench]'"
    monkeypatch.setattr(povray, "povray_executable", lambda: None)
    with pytest.raises(BenchUsageError) as info:
        _main(compare="povray")
    assert str(info.value) == ("--compare povray: povray is not installed "
                               "(Debian: apt-get install povray)")
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "matplotlib" else real(name, *a))
    with pytest.raises(BenchUsageError) as info:
        _main(study="size")
    assert str(info.value) == ("--study size: the plot needs matplotlib: "
                               "pip install 'whitted[plots]'")


def test_no_scene_rendered_and_bench_errors_are_one_line(monkeypatch):
    monkeypatch.setattr(command, "run_bench", lambda options, log: BenchResult(
        skipped=[("bunny1m", "no source model")]))
    with pytest.raises(BenchUsageError) as info:
        _main()
    assert str(info.value) == "no scene could be rendered"

    def failing(options, log):
        raise BenchError("the render process failed (exit 1): boom")

    monkeypatch.setattr(command, "run_bench", failing)
    with pytest.raises(BenchUsageError) as info:
        _main()
    assert str(info.value) == "the render process failed (exit 1): boom"


def test_size_study_writes_table_json_plot_and_markdown(tmp_path):
    out, err = _main(scenes=["lecture"], threads="1", study="size",
                     json_path=tmp_path / "rows.json", plot_path=tmp_path / "plot.png",
                     markdown_path=tmp_path / "study.md", width=40)
    rows = json.loads((tmp_path / "rows.json").read_text())
    # quick: the sizes 16 and 32, one thread, one run each in this process
    assert [(r["scene"], r["width"], r["height"], r["threads"], r["runs"], r["mode"])
            for r in rows] == [("lecture", 16, 16, 1, 1, "in-process"),
                               ("lecture", 32, 32, 1, 1, "in-process")]
    assert [r["rays"]["primary"] for r in rows] == [256, 1024]
    assert (tmp_path / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = (tmp_path / "study.md").read_text().splitlines()
    assert table[0] == "| scene | size | threads | render s | wall s | speed-up | Mrays/s |"
    assert table[2].startswith("| lecture | 16x16 | 1 | ") and table[2].endswith(" |")
    assert table[2].split(" | ")[5] == "1.00"  # one thread: its own base
    words = "".join(out.split())  # the 40-column console wraps long lines
    for name in ("rows.json", "plot.png", "study.md"):
        assert f"wrote{tmp_path / name}" in words
    # the table is printed whole, wider than the 40-column console it goes to (not a tty)
    line = next(ln for ln in out.splitlines() if "lecture" in ln and "16x16" in ln)
    assert len(line) > 40 and "256" in line
    assert "whitted bench --study size" in out
    assert "median of" not in err and "quick" in err


def test_plain_run_with_markdown(tmp_path):
    out, _ = _main(scenes=["lecture"], threads="1", size="8x6",
                   markdown_path=tmp_path / "bench.md")
    text = (tmp_path / "bench.md").read_text()
    assert text.startswith("| scene | size | threads | primary | shadow |")
    assert "| lecture | 8x6 | 1 | 48 |" in text
    assert f"wrote {tmp_path / 'bench.md'}" in out


def test_threads_study_and_an_unknown_study():
    rows = run_study("threads", BenchOptions(scenes=["lecture"], quick=True, size=(8, 8),
                                             threads=[1], warmup=False), log=lambda s: None)
    assert [(r["scene"], r["threads"], r["rays"]["primary"]) for r in rows.rows] == [
        ("lecture", 1, 64)]
    with pytest.raises(ValueError, match="unknown study 'light' \\(threads or size\\)"):
        run_study("light", BenchOptions(quick=True))


def test_speedups_and_study_markdown_with_povray_columns():
    rows = [{"scene": "ice", "width": 64, "height": 64, "threads": t, "render_s": 2.0 / t,
             "wall_s": 3.0, "mrays_per_s": 1.5} for t in (1, 2, 4)]
    rows[1]["povray_trace_s"], rows[1]["povray_wall_s"], rows[1]["ratio_render"] = 0.5, 0.75, 2
    assert speedups(rows) == {("ice", 64, 1): 1.0, ("ice", 64, 2): 2.0, ("ice", 64, 4): 4.0}
    rows.append({"scene": "ice", "width": 32, "height": 32, "threads": 1, "render_s": 0.0,
                 "wall_s": 1.0, "mrays_per_s": 0.0})
    assert speedups(rows)[("ice", 32, 1)] == 0.0  # no time measured: no speed-up
    lines = study_markdown("threads", rows).splitlines()
    assert lines[0].endswith("| POV trace s | POV wall s | render ratio |")
    assert lines[2] == "| ice | 32x32 | 1 | 0.000 | 1.000 | 0.00 | 0.00 | nan | nan | nan |"
    assert lines[4] == "| ice | 64x64 | 2 | 1.000 | 3.000 | 2.00 | 1.50 | 0.500 | 0.750 | 2.00 |"


# ---------------------------------------------------------------------- runner pieces


def test_compact_counts():
    assert [compact(n) for n in (812, 45_300, 450_000, 1_310_000, 450_000_000)] == [
        "812", "45.3k", "450k", "1.31M", "450M"]


def _row(**extra):
    row = {"scene": "s", "width": 4, "height": 2, "threads": 1,
           "rays": {"primary": 8, "shadow": 2, "reflection": 0, "refraction": 0},
           "startup_s": 0.1, "compile_s": 0.2, "build_s": 0.3, "render_s": 0.4, "wall_s": 1.0,
           "mrays_per_s": 0.5, "peak_mib": 99.6}
    row.update(extra)
    return row


def test_results_table_with_povray_and_embree_columns():
    pov = _row(povray_trace_s=0.25, povray_wall_s=0.5, ratio_render=1.6, ratio_wall=2.0,
               povray_rays={"primary": 8, "shadow": 1500, "reflection": 0, "refraction": 3})
    emb = _row(scene="m", embree_mrays_per_s=10.0, whitted_trace_mrays_per_s=2.5,
               ratio_embree=0.25, whitted_mesh_tracer="embree", ratio_embree_walk=0.1)
    columns, cells = table_rows([pov, emb])
    assert columns[-10:] == ["POV trace s", "POV wall s", "render ratio", "wall ratio",
                             "POV rays p/s/rl/rr", "tracer", "trace Mrays/s",
                             "Embree Mrays/s", "of Embree", "walk of Embree"]
    assert cells[0][:14] == ["s", "4x2", "1", "8", "2", "0", "0", "0.100", "0.200", "0.300",
                             "0.400", "1.000", "0.50", "100"]
    assert cells[0][14:] == ["0.250", "0.500", "1.60", "2.00", "8/1.5k/0/3", "", "", "", "",
                             ""]
    assert cells[1][14:] == ["", "", "", "", "", "embree", "2.50", "10.00", "0.25", "0.10"]
    md = markdown_table([emb]).splitlines()
    assert md[1].count("---") == len(md[0].split(" | ")) and "| m | 4x2 |" in md[2]


def test_image_size_follows_the_options():
    scene = Scene(render={"width": 200, "height": 100})
    assert image_size(scene, BenchOptions()) == (200, 100)
    assert image_size(scene, BenchOptions(quick=True)) == (48, 24)
    assert image_size(scene, BenchOptions(quick=True, size=(5, 7))) == (5, 7)


def test_runs_below_one_and_failing_renders(monkeypatch):
    with pytest.raises(BenchError, match="--runs must be at least 1"):
        run_bench(BenchOptions(runs=0))

    class Failing:
        def __init__(self, scene, threads):
            pass

        def run(self):
            raise MemoryError("no room")

    monkeypatch.setattr(runner, "RenderJob", Failing)
    with pytest.raises(BenchError) as info:  # a scene without meshes: its failure is an error
        run_bench(BenchOptions(scenes=["lecture"], quick=True, size=(4, 4)), log=lambda s: None)
    assert str(info.value) == "MemoryError: no room"


def test_a_mesh_scene_that_does_not_render_is_skipped(monkeypatch):
    def fail(*args):
        raise BenchError("meshes missing")

    monkeypatch.setattr(runner, "_bench_whitted", fail)
    lines = []
    result = run_bench(BenchOptions(scenes=["seed000"], quick=True), log=lines.append)
    assert result.rows == []
    assert result.skipped == [("seed000", "its meshes do not render: meshes missing")]
    assert lines[-1] == "  skipped seed000: meshes missing"


def test_a_missing_source_model_skips_its_scene(monkeypatch):
    from whitted.bench.models import MissingSourceModel

    def missing(name, quick=False):
        raise MissingSourceModel("the bunny's source is not on this machine")

    monkeypatch.setattr(runner, "load_bench_scene", missing)
    result = run_bench(BenchOptions(scenes=["bunny1m"], quick=True), log=lambda s: None)
    assert result.skipped == [("bunny1m", "the bunny's source is not on this machine")]


def test_a_failing_render_process_is_one_line(monkeypatch, tmp_path):
    from whitted.bench.timing import ProcessResult

    monkeypatch.setattr(runner, "timed_process", lambda command, env=None: ProcessResult(
        returncode=3, stdout="", stderr="a\nb\nc\nd\n", wall_s=1.0, peak_mib=1.0))
    with pytest.raises(BenchError) as info:
        runner._process_run(Scene(), 1, tmp_path)
    assert str(info.value) == "the render process failed (exit 3): b | c | d"
    assert (tmp_path / "scene.json").is_file()


def test_a_timed_run_is_a_whitted_render_process_and_its_figures_are_the_jobs(tmp_path):
    from whitted.bench.scenes import load_bench_scene
    from whitted.render.api import RenderJob

    scene = load_bench_scene("lecture", quick=True)
    run = runner._process_run(scene, 1, tmp_path)
    job = RenderJob(scene, threads=1)
    job.run()
    # the same rays as this process's render of the scene, kind by kind
    assert run["rays"] == {kind: n for kind, n in job.stats.rays.items()}
    assert sum(run["rays"].values()) > 0
    assert run["wall_s"] >= run["compile_s"] + run["build_s"] + run["render_s"] > 0
    assert run["startup_s"] == pytest.approx(
        run["wall_s"] - run["compile_s"] - run["build_s"] - run["render_s"])
    assert (tmp_path / "whitted.png").stat().st_size > 0


def test_a_render_process_that_notes_no_figures_is_one_line(monkeypatch, tmp_path):
    from whitted.bench.timing import ProcessResult

    monkeypatch.setattr(runner, "timed_process", lambda command, env=None: ProcessResult(
        returncode=0, stdout="", stderr="", wall_s=1.0, peak_mib=1.0))
    with pytest.raises(BenchError) as info:
        runner._process_run(Scene(), 1, tmp_path)
    assert str(info.value) == ("the render process noted no kernels:seconds, build:seconds, "
                               "render:seconds")


def test_timed_process_reports_exit_output_and_memory(tmp_path):
    run = timed_process([sys.executable, "-c",
                         "import sys; print('out'); print('err', file=sys.stderr); "
                         "sys.exit(3)"], cwd=tmp_path)
    assert (run.returncode, run.stdout, run.stderr) == (3, "out\n", "err\n")
    assert run.wall_s > 0 and run.peak_mib > 1
    with pytest.raises(FileNotFoundError):
        timed_process([str(tmp_path / "no-such-program")])


def test_povray_version_and_a_failing_povray(monkeypatch, tmp_path):
    monkeypatch.setattr(povray, "povray_executable", lambda: None)
    assert povray.povray_version() == "not installed"
    fake = tmp_path / "povray"
    fake.write_text("#!/bin/sh\necho 'Persistence of Vision(tm) Ray Tracer Version 3.7.0.10'"
                    " >&2\necho 'Parse Error: oops' >&2\nexit 1\n")
    fake.chmod(0o755)
    monkeypatch.setattr(povray, "povray_executable", lambda: str(fake))
    assert povray.povray_version() == "unknown version"
    with pytest.raises(povray.PovrayError) as info:
        povray.run_povray(tmp_path / "x.pov", tmp_path / "x.png", 4, 4, 1, linear=True)
    assert str(info.value) == ("povray failed on x.pov (exit 1): Persistence of Vision(tm) "
                               "Ray Tracer Version 3.7.0.10 | Parse Error: oops")
    fake.write_text("#!/bin/sh\necho 'POV-Ray 3.7.0.10.unofficial' >&2\n")
    assert povray.povray_version() == "3.7.0.10.unofficial"
    monkeypatch.setattr(povray, "povray_executable", lambda: None)
    with pytest.raises(povray.PovrayError, match="povray is not installed"):
        povray.run_povray(Path("x.pov"), Path("x.png"), 4, 4, 1, False)


def test_an_interrupted_timing_kills_its_child(monkeypatch):
    import signal
    import subprocess

    from whitted.bench import timing

    started = []

    class Recorded(subprocess.Popen):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            started.append(self)

    def interrupted(pid, options):
        raise KeyboardInterrupt

    monkeypatch.setattr(timing.subprocess, "Popen", Recorded)
    monkeypatch.setattr(timing.os, "wait4", interrupted)
    with pytest.raises(KeyboardInterrupt):
        timed_process([sys.executable, "-c", "import time; time.sleep(600)"])
    (child,) = started
    assert child.returncode == -signal.SIGKILL  # killed and reaped, not left running


def _row_only(spec, scene, threads, options, folder):
    return {"scene": spec.name, "width": scene.render.width, "height": scene.render.height,
            "threads": threads, "render_s": 1.0, "wall_s": 2.0}


def test_the_embree_columns_join_the_mesh_scenes_rows(monkeypatch):
    from whitted.bench import embree

    monkeypatch.setattr(runner, "_bench_whitted", _row_only)
    seen = []
    monkeypatch.setattr(embree, "compare_embree", lambda scene: seen.append(scene) or {
        "embree_mrays_per_s": 7.0})
    lines = []
    result = run_bench(BenchOptions(scenes=["lecture", "mesh1m"], quick=True, size=(8, 4),
                                    threads=[1, 2], compare="embree"), log=lines.append)
    assert [(r["scene"], r["threads"], r.get("embree_mrays_per_s")) for r in result.rows] == [
        ("lecture", 1, None), ("lecture", 2, None), ("mesh1m", 1, 7.0), ("mesh1m", 2, 7.0)]
    assert len(seen) == 1 and (seen[0].render.width, seen[0].render.height) == (8, 4)
    assert "mesh1m: the same camera and shadow rays, whitted and Embree, 1 thread" in lines

    def no_light(scene):
        raise ValueError("the scene has no point light to cast shadow rays toward")

    monkeypatch.setattr(embree, "compare_embree", no_light)
    with pytest.raises(BenchError, match="^the scene has no point light to cast shadow rays "
                                         "toward$"):
        run_bench(BenchOptions(scenes=["mesh1m"], quick=True, size=(8, 4), compare="embree"),
                  log=lambda s: None)


def test_a_failing_povray_is_a_bench_error(monkeypatch):
    def failing(*args):
        raise povray.PovrayError("povray failed on lecture.pov (exit 1): Parse Error")

    monkeypatch.setattr(runner, "_bench_whitted", _row_only)
    monkeypatch.setattr(povray, "run_povray", failing)
    with pytest.raises(BenchError, match=r"^povray failed on lecture.pov \(exit 1\): Parse "
                                         "Error$"):
        run_bench(BenchOptions(scenes=["lecture"], quick=True, size=(8, 4), compare="povray"),
                  log=lambda s: None)


def test_beside_povray_the_runs_alternate_and_the_ratios_are_medians_of_the_pairs(monkeypatch):
    """whitted, POV-Ray, whitted, ... after a warm-up of each; a machine that drifts (here:
    whitted's runs 1, 2, 9 s beside POV-Ray's 4, 1, 3 s) gives the pairs' ratios 0.25, 2, 3,
    whose median is 2 (the ratio of the medians, 2/3, mixes runs made at different times)."""
    from types import SimpleNamespace

    order: list[str] = []
    whitted_s = iter([5.0, 1.0, 2.0, 9.0])  # the warm-up first
    povray_s = iter([5.0, 4.0, 1.0, 3.0])

    def whitted_run(scene, threads, folder):
        order.append("whitted")
        t = next(whitted_s)
        return {"rays": {"primary": 1}, "compile_s": 0.0, "build_s": 0.0, "render_s": t,
                "wall_s": 2 * t, "startup_s": t, "peak_mib": 1.0}

    def runner_for(spec, scene, threads, folder):
        def once():
            order.append("povray")
            t = next(povray_s)
            return SimpleNamespace(trace_s=t, parse_s=0.0, bounding_s=0.0, wall_s=t,
                                   peak_mib=1.0, rays={"primary": 1})
        return once

    monkeypatch.setattr(runner, "_process_run", whitted_run)
    monkeypatch.setattr(runner, "_povray_runner", runner_for)
    result = run_bench(BenchOptions(scenes=["lecture"], runs=3, threads=[1], size=(8, 4),
                                    compare="povray"), log=lambda s: None)
    (row,) = result.rows
    assert order == ["whitted", "povray"] * 4
    assert row["render_s"] == 2.0 and row["povray_trace_s"] == 3.0
    assert row["ratio_render"] == 2.0
    assert row["ratio_wall"] == 4.0  # wall: 2, 4, 18 s against 4, 1, 3 s


def test_the_scene_option_names_every_bench_scene():
    from whitted.bench.scenes import SCENES
    from whitted.cli.bench import SCENE_HELP

    names = list(SCENES)
    listed = SCENE_HELP.split(":", 1)[1].split("(")[0].replace(" ", "").split(",")
    assert listed == names
