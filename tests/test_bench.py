"""``whitted bench``: the quick run's table and JSON, the fresh-process path, the POV-Ray
comparison (when POV-Ray is installed), the studies' plots and the generated models. No timing
assertions: only that every stage was measured and every ray kind counted."""

from __future__ import annotations

import json
import shutil
import time

import numpy as np
import pytest
from typer.testing import CliRunner

from whitted.bench.models import (
    CONE_SEGMENTS,
    bench_cache_dir,
    bumpy_torus_mesh,
    bunny_source,
    displaced_sphere_mesh,
    height_field_mesh,
    rounded_box_mesh,
    subdivide,
    vase_mesh,
)
from whitted.bench.povray import parse_povray_statistics, povray_rays
from whitted.bench.runner import TABLE_COLUMNS, BenchOptions, run_bench
from whitted.bench.scenes import SCENES, benchmarks_dir, has_meshes, load_bench_scene
from whitted.bench.studies import plot_study, study_markdown, study_thread_counts
from whitted.cli.main import app

JSON_KEYS = {"scene", "width", "height", "threads", "rays", "render_s", "wall_s", "mrays_per_s",
             "startup_s", "compile_s", "build_s", "peak_mib"}


def test_quick_bench_table_and_json(tmp_path):
    out = tmp_path / "bench.json"
    # the bunny renders where its source is, or where its quick model was made before
    has_bunny = (bunny_source() is not None
                 or (bench_cache_dir() / "quick-bunny_1m.ply").exists())
    result = CliRunner().invoke(app, ["bench", "--quick", "--json", str(out)])
    assert result.exit_code == 0, result.output
    for column in TABLE_COLUMNS:
        assert column in result.output, column
    rows = json.loads(out.read_text())
    quick_scenes = [name for name, spec in SCENES.items() if spec.quick
                    and (name != "bunny1m" or has_bunny)]
    assert [r["scene"] for r in rows] == quick_scenes  # meshes render: none skipped
    assert {"sphere1m", "vase1m", "instances100", "mesh1m"} <= set(quick_scenes)
    for row in rows:
        assert row.keys() >= JSON_KEYS
        assert row["width"] <= 64 and row["runs"] == 1
        assert row["rays"]["primary"] == row["width"] * row["height"]
        assert row["rays"]["shadow"] > 0
        assert row["render_s"] > 0 and row["wall_s"] >= row["render_s"]
    by_scene = {r["scene"]: r for r in rows}
    for name in ("seed000", "ice"):  # glass: every kind of ray
        assert all(count > 0 for count in by_scene[name]["rays"].values()), name
    assert by_scene["softshadow"]["rays"]["shadow"] > 10 * by_scene["seed000"]["rays"]["shadow"]


def test_fresh_process_run_measures_every_stage():
    """The stages are measured inside the child process and its wall time from outside: the
    stages measured inside fit within the wall time, and the wall time within the time this
    test saw pass around the whole call (startup_s is what is left over, never negative)."""
    start = time.perf_counter()
    result = run_bench(BenchOptions(scenes=["lecture"], runs=1, threads=[1], size=(16, 16),
                                    warmup=False), log=lambda line: None)
    elapsed = time.perf_counter() - start
    (row,) = result.rows
    assert row["mode"] == "process" and row["width"] == 16
    assert row["rays"]["primary"] == 256 and row["rays"]["shadow"] > 0
    inside = row["compile_s"] + row["build_s"] + row["render_s"]
    assert row["render_s"] > 0 and row["build_s"] > 0 and row["compile_s"] >= 0
    assert inside < row["wall_s"] <= elapsed
    assert row["startup_s"] == pytest.approx(row["wall_s"] - inside, abs=1e-9)
    assert row["startup_s"] > 0 and row["peak_mib"] > 10


def test_compare_povray(tmp_path):
    if shutil.which("povray") is None:
        message = "povray is not on PATH: whitted bench --compare povray was not run"
        print(message)
        pytest.skip(message)
    out = tmp_path / "compare.json"
    result = CliRunner().invoke(app, ["bench", "--quick", "--scene", "seed000", "--compare",
                                      "povray", "--json", str(out)])
    assert result.exit_code == 0, result.output
    assert "POV trace s" in result.output
    (row,) = json.loads(out.read_text())
    for key in ("povray_trace_s", "povray_wall_s", "ratio_render", "ratio_wall"):
        assert row[key] > 0, key
    assert row["ratio_render"] == pytest.approx(row["render_s"] / row["povray_trace_s"])
    assert row["povray_rays"]["primary"] == row["width"] * row["height"]
    assert row["povray_rays"]["shadow"] > 0


def test_povray_statistics_are_parsed():
    text = """
Pixels:           164832   Samples:               0   Smpls/Pxl: 0.00
Rays:             775935   Saved:            119739   Max Level: 6/6
Shadow Ray Tests:            924552   Succeeded:                297866
Reflected Rays:              421376
Refracted Rays:              189727
  Parse Time:       0 hours  0 minutes  0 seconds (0.012 seconds)
  Trace Time:       0 hours  0 minutes  1 seconds (1.265 seconds)
"""
    stats = parse_povray_statistics(text)
    assert stats["trace_s"] == 1.265 and stats["parse_s"] == 0.012
    assert povray_rays(stats) == {"primary": 164832, "shadow": 924552, "reflection": 421376,
                                  "refraction": 189727}


def test_bad_options_are_one_line_errors():
    for args in (["--compare", "mitsuba"], ["--study", "colour"], ["--threads", "x"],
                 ["--scene", "nonesuch", "--quick"], ["--runs", "0"], ["--size", "9"]):
        result = CliRunner().invoke(app, ["bench", *args])
        assert result.exit_code == 2, (args, result.output)


def test_study_tables_and_plots(tmp_path):
    assert study_thread_counts(6) == [1, 2, 4, 6] and study_thread_counts(1) == [1]
    rows = [
        {"scene": "ice", "width": s, "height": s, "threads": t, "render_s": s * s / 1e5 / t,
         "wall_s": 1 + s * s / 1e5 / t, "mrays_per_s": 2.0, "povray_trace_s": s * s / 2e5 / t,
         "povray_wall_s": 0.5 + s * s / 2e5 / t, "ratio_render": 2.0}
        for s in (128, 256) for t in (1, 2)
    ]
    for kind in ("size", "threads"):
        png = plot_study(kind, rows, tmp_path / f"{kind}.png")
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = study_markdown("size", rows)
    assert "| ice | 256x256 | 2 |" in table and "2.00" in table  # speed-up of 2 threads


def test_benchmark_scenes_and_models():
    folder = benchmarks_dir()
    assert (folder / "seed000.toml").is_file()
    seed = load_bench_scene("seed000")
    assert (seed.render.width, seed.render.height, seed.render.max_depth) == (809, 817, 5)
    cones = [obj for obj in seed.objects if obj.type == "mesh"]
    assert len(cones) == 4 and has_meshes(seed)
    from whitted.assets import load_mesh

    assert sum(len(load_mesh(c.file).faces) for c in cones) == 642 == 2 * sum(CONE_SEGMENTS)
    soft = load_bench_scene("softshadow")
    assert [light.type for light in soft.lights] == ["ambient", "disk"]
    assert soft.lights[1].samples == 64
    vertices, faces = rounded_box_mesh((1.0, 0.5, 0.8), 0.2, 6)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).tolist()
    directed = set(map(tuple, edges))
    assert len(directed) == len(edges) and all((b, a) in directed for a, b in directed)  # closed
    _, field = height_field_mesh(quads=(10, 5))
    assert len(field) == 100


def _directed_edges(faces: np.ndarray) -> set[tuple[int, int]]:
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).tolist()
    directed = set(map(tuple, edges))
    assert len(directed) == len(edges)  # no edge used twice the same way: consistent winding
    return directed


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def test_mesh_benchmark_models_closed_outward_and_counted():
    vertices, faces = displaced_sphere_mesh((40, 21), bumps=0.0)
    assert len(faces) == 2 * 40 * 20  # fans at the poles + quads: 2·n_lon·(n_lat − 1)
    directed = _directed_edges(faces)
    assert all((b, a) in directed for a, b in directed)  # closed
    # outward, and with no bumps close to the unit sphere's volume (inscribed polyhedron)
    assert 0.97 * 4 / 3 * np.pi < _signed_volume(vertices, faces) < 4 / 3 * np.pi

    vertices, faces = bumpy_torus_mesh((30, 16))
    assert len(faces) == 2 * 30 * 16
    directed = _directed_edges(faces)
    assert all((b, a) in directed for a, b in directed)
    assert _signed_volume(vertices, faces) > 0  # outward (about 2π²·R·r²)

    vertices, faces = vase_mesh((400, 6))
    assert len(faces) == 2 * 400 * 6 + 400
    directed = _directed_edges(faces)
    open_edges = [e for e in directed if (e[1], e[0]) not in directed]
    assert len(open_edges) == 400  # only the rim at the top is open
    p = vertices[faces]
    longest = np.max(np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2), axis=1)
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) / 2
    assert np.median(longest ** 2 / (2 * area)) > 20  # long and thin
    assert np.all(np.cross(p[-400:, 1] - p[-400:, 0], p[-400:, 2] - p[-400:, 0])[:, 1] < 0)


def test_subdivide_keeps_the_surface_and_closedness():
    vertices, faces = rounded_box_mesh((1.0, 0.5, 0.8), 0.2, 3)
    fine_v, fine_f = subdivide(vertices, faces, levels=2)
    assert len(fine_f) == 16 * len(faces)
    directed = _directed_edges(fine_f)
    assert all((b, a) in directed for a, b in directed)
    # midpoint subdivision only splits flat triangles: same volume, same area
    assert _signed_volume(fine_v, fine_f) == pytest.approx(_signed_volume(vertices, faces))
    rough_v, rough_f = subdivide(vertices, faces, levels=1, roughness=0.3)
    assert np.array_equal(rough_v[:len(vertices)], vertices)  # old points stay
    assert not np.allclose(rough_v[len(vertices):], subdivide(vertices, faces, 1)[0][
        len(vertices):])


def test_compare_embree_traces_the_same_rays():
    pytest.importorskip("embreex")
    from whitted.bench.embree import compare_embree

    scene = load_bench_scene("sphere1m", quick=True).with_settings(width=32, height=18)
    row = compare_embree(scene, repeats=1)
    assert row["embree_rays"] == 32 * 18 + row["walk_hits"]  # camera + one shadow per hit
    assert row["embree_triangles"] == 2 * 100 * 50 + 2  # the sphere and the ground's two
    # the same world: the same camera rays hit the sphere or the ground (the top row is sky),
    # traced by whitted's walk, by Embree inside whitted's render, and by Embree alone
    assert row["walk_hits"] == row["whitted_embree_hits"] == row["embree_hits"] == 32 * 17
    assert abs(row["walk_occluded"] - row["embree_occluded"]) <= 2
    assert abs(row["whitted_embree_occluded"] - row["embree_occluded"]) <= 2
    # the headline is what a render uses: Embree inside whitted
    assert row["whitted_mesh_tracer"] == "embree"
    assert row["whitted_trace_mrays_per_s"] == row["whitted_embree_mrays_per_s"]
    assert row["ratio_embree"] == pytest.approx(
        row["whitted_trace_mrays_per_s"] / row["embree_mrays_per_s"])
    assert row["ratio_embree_walk"] == pytest.approx(
        row["walk_mrays_per_s"] / row["embree_mrays_per_s"])
