"""``python -m whitted.farm.measure`` (the numbers behind docs/farm.md): a tiny real run whose
JSON report is checked field by field, and its helpers' worked values."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from whitted import machine
from whitted.farm import measure
from whitted.scene import load_scene
from whitted.scene.io import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]


def test_a_still_scene_gets_a_half_radian_camera_turn():
    scene = measure.film_scene(str(ROOT / "examples" / "textured.toml"), 3)
    assert scene.is_animated and scene.frame_count == 3
    # eye (0, 2.2, 7.5) turns about the target (0, 0.9, 0) from 0 to 0.5 rad, height kept
    first = [float(v) for v in scene.at_frame(0).camera.position]
    last = [float(v) for v in scene.at_frame(2).camera.position]
    assert first == pytest.approx([0.0, 2.2, 7.5], abs=1e-12)
    assert last == pytest.approx([7.5 * math.sin(0.5), 2.2, 7.5 * math.cos(0.5)], rel=1e-9)


def test_an_animated_scene_keeps_its_own_animation_and_the_default_scene_turns():
    path = ROOT / "examples" / "camera_orbit.toml"
    own = load_scene(path)
    assert own.is_animated
    scene = measure.film_scene(str(path), 5)
    assert scene.frame_count == own.frame_count  # not the 5 asked for
    assert scene.at_frame(1).camera == own.at_frame(1).camera
    default = measure.film_scene(None, 4)
    assert default.frame_count == 4
    assert default.at_frame(0).camera.position != default.at_frame(3).camera.position


def test_layouts_medians_and_cpu_name():
    assert measure._layout("2") == (2, 1)
    assert measure._layout("3x4") == (3, 4)
    rows = [{"n": 1, "wall_s": 3.0, "ok": True, "tag": "a"},
            {"n": 5, "wall_s": 1.0, "ok": False, "tag": "b"},
            {"n": 2, "wall_s": 2.0, "ok": False, "tag": "c"}]
    # numbers: the median; booleans and text: the first round's
    assert measure._medians(rows) == {"n": 2, "wall_s": 2.0, "ok": True, "tag": "a"}
    model = [line.split(":", 1)[1].strip()
             for line in Path("/proc/cpuinfo").read_text().splitlines()
             if line.startswith("model name")]
    assert machine.cpu_name() == model[0]
    assert measure.cpu_name is machine.cpu_name  # the farm names the CPU as bench does


def test_cpu_name_without_proc_cpuinfo(monkeypatch):
    import platform

    class NoProc(type(Path())):
        def read_text(self, *args, **kwargs):
            raise OSError("no /proc here")

    monkeypatch.setattr(machine, "Path", NoProc)
    assert machine.cpu_name() == (platform.processor() or platform.machine() or "unknown")


def test_hd_frame_is_a_1080p_png(tmp_path):
    empty = scene_from_dict({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
                             "objects": []})
    row = measure.measure_hd(empty, tmp_path)
    assert (row["width"], row["height"], row["threads"]) == (1920, 1080, 1)
    assert row["png_bytes"] == (tmp_path / "hd.png").stat().st_size
    with Image.open(tmp_path / "hd.png") as image:
        assert image.size == (1920, 1080)
    assert row["frame_s"] > 0


def test_measure_reports_the_local_and_the_farm_film(tmp_path):
    out = tmp_path / "out.json"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    done = subprocess.run([sys.executable, "-m", "whitted.farm.measure",
                           str(ROOT / "examples" / "textured.toml"), "--frames", "2",
                           "--width", "16", "--height", "12", "--workers", "1x1",
                           "--rounds", "1", "--json", str(out)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("round 0 local: {'threads': 2,")
    assert lines[1].startswith("round 0 1x1 worker(s): {'workers': 1, 'threads_per_worker': 1,")
    report = json.loads(out.read_text())
    assert report["frames"] == 2 and report["size"] == [16, 12]
    assert report["scene"] == str(ROOT / "examples" / "textured.toml")
    assert report["cpu"] == machine.cpu_name()
    assert report["scene_pickle_bytes"] > 0
    local = report["local"]
    assert local["threads"] == 2
    assert local["per_frame_s"] == pytest.approx(local["wall_s"] / 2)
    assert local["per_frame_cpu_s"] == pytest.approx(local["cpu_s"] / 2)
    (farm,) = report["cluster"]
    assert (farm["workers"], farm["threads_per_worker"]) == (1, 1)
    assert farm["speedup_vs_local"] == pytest.approx(local["wall_s"] / farm["wall_s"])
    assert len(farm["worker_warm_s"]) == 1
    assert farm["tasks"] >= 1 and 1 <= farm["chunk"] <= 2
    assert 0 < farm["png_bytes_mean"] < 16 * 12 * 3 + 1000  # a 16x12 PNG
    assert farm["asset_bytes"] == 0  # "auto": every worker is on this machine, none travel
    # the last layout also measures Dask's per-task overhead
    assert farm["task_round_trip_ms"] > 0 and farm["task_throughput_per_s"] > 0
    assert report["rounds"]["local"] == [local]
    assert report["rounds"]["cluster"]["1x1"][0]["wall_s"] == farm["wall_s"]
    assert len(report["load_before"]) == len(report["load_after"]) == 3
