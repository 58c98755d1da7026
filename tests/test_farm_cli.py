"""The farm from the command line: ``whitted render --cluster local:N`` writes the image a
local render writes; bad farm options and a missing dask.distributed are one error line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from whitted import load_scene
from whitted.cli.main import app
from whitted.render.api import RenderJob

pytest.importorskip("distributed")


def whitted(*args: object, cwd: Path, prelude: str = "") -> subprocess.CompletedProcess:
    code = (f"{prelude}import sys; from whitted.cli.main import main; "
            "sys.argv[0] = 'whitted'; main()")
    return subprocess.run([sys.executable, "-c", code, *map(str, args)], cwd=cwd,
                          env=dict(os.environ), capture_output=True, text=True, timeout=300)


def test_render_on_a_local_cluster_writes_the_local_image(tmp_path, examples_dir):
    scene_path = examples_dir / "textured.toml"
    result = whitted("render", scene_path, "-W", 80, "-H", 45, "-s", 2, "-o",
                     tmp_path / "farm.png", "--cluster", "local:2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "farm: 2 workers (2 Dask threads) at tcp://127.0.0.1:" in result.stdout
    assert "on 2 workers" in result.stdout
    scene = load_scene(scene_path).with_settings(width=80, height=45, samples=2)
    RenderJob(scene).run().save(tmp_path / "local.png")
    farm = np.asarray(Image.open(tmp_path / "farm.png"))
    local = np.asarray(Image.open(tmp_path / "local.png"))
    assert farm.shape == (45, 80, 3) and np.array_equal(farm, local)


@pytest.mark.parametrize(("options", "message"), [
    (["--cluster", "pool:4"], "error: --cluster: unknown cluster 'pool:4' (use local:N, or "
                              "--scheduler tcp://HOST:PORT for a running one)"),
    (["--cluster", "local:0"], "error: --cluster: 'local:0': N must be a whole number of "
                               "workers, 1 or more"),
    (["--cluster", "local:2", "--scheduler", "tcp://127.0.0.1:9"],
     "error: give one of --cluster local:N and --scheduler tcp://HOST:PORT"),
])
def test_bad_farm_options_are_one_line(tmp_path, options, message):
    result = CliRunner().invoke(app, ["render", "-W", "8", "-H", "8", "-o",
                                      str(tmp_path / "x.png"), *options])
    assert result.exit_code == 2
    assert result.stderr.strip() == message
    assert not (tmp_path / "x.png").exists()


def test_without_dask_the_farm_says_what_to_install(tmp_path):
    hide_dask = "import sys; sys.modules['distributed'] = None; "  # as if not installed
    result = whitted("render", "-W", 8, "-H", 8, "-o", tmp_path / "x.png", "--cluster",
                     "local:2", cwd=tmp_path, prelude=hide_dask)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0] == ("error: the render farm needs dask.distributed, which is not "
                        "installed: install whitted[farm] (pip install 'whitted[farm]')")


FILM = """
[render]
width = 48
height = 32

[camera]
position = [0, 1.5, 5]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
type = "plane"
material = { kd = 0.8, texture = { type = "checker", checks = 2.0 } }

[[objects]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "glass"

[animation]
frames = 6
fps = 12

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 1.5, 5]], [5, [3, 1.5, 4]]]
"""


def test_animate_on_a_local_cluster_writes_the_local_frames_and_film(tmp_path):
    import imageio_ffmpeg

    scene = tmp_path / "turn.toml"
    scene.write_text(FILM)
    local = CliRunner().invoke(app, ["animate", str(scene), "-o", str(tmp_path / "local"),
                                     "-q"])
    assert local.exit_code == 0, local.stderr
    result = whitted("animate", scene, "-o", tmp_path / "farm.mp4", "--cluster", "local:2",
                     cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "6 frames (6 rendered" in result.stdout
    names = [f"{k:04d}.png" for k in range(6)]
    assert sorted(p.name for p in (tmp_path / "farm_frames").iterdir()) == names
    for name in names:  # the same PNG bytes: pixels and the frame hash that resumes
        assert (tmp_path / "farm_frames" / name).read_bytes() == (
            tmp_path / "local" / name).read_bytes()
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(tmp_path / "farm.mp4"))
    meta = next(imageio_ffmpeg.read_frames(str(tmp_path / "farm.mp4")))
    assert frames == 6 and tuple(meta["size"]) == (48, 32)
    again = whitted("animate", scene, "-o", tmp_path / "farm.mp4", "--cluster", "local:2",
                    cwd=tmp_path)  # resume: every frame is current
    assert again.returncode == 0 and "6 already done" in again.stdout
    assert "farm:" not in again.stderr  # nothing to render: no cluster was started


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="Numba's default pool is 1 thread")
def test_worker_threads_agree_with_numba_when_numba_came_first(tmp_path):
    # A spawned Dask worker re-imports the client's main module (whitted's CLI, and Numba with
    # it) before the Nanny sets NUMBA_NUM_THREADS: Numba's config then says one pool size and
    # the environment another, and the next compile (a cold cache) raised RuntimeError.
    code = """
import os
os.environ.pop("NUMBA_NUM_THREADS", None)
import numba                                  # config: one thread per core
os.environ["NUMBA_NUM_THREADS"] = "1"        # what the Nanny sets afterwards
from whitted.farm.worker import set_worker_threads
set_worker_threads(1)

@numba.njit
def twice(x):
    return 2 * x

assert twice(21) == 42                       # a compile re-reads the environment
print(numba.get_num_threads(),
      os.environ["NUMBA_NUM_THREADS"] == str(numba.config.NUMBA_NUM_THREADS))
"""
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                            text=True, timeout=120, env=dict(os.environ))
    assert result.returncode == 0, result.stderr
    # renders use one thread; environment and pool agree (the size Numba was imported with)
    assert result.stdout.split() == ["1", "True"]


def test_help_names_the_farm_extra():
    result = CliRunner().invoke(app, ["render", "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0
    assert "(needs whitted[farm])" in " ".join(result.stdout.split())


def test_a_frame_rendered_on_a_cluster_is_the_local_frame_file(tmp_path):
    scene = tmp_path / "turn.toml"
    scene.write_text(FILM)
    local = CliRunner().invoke(app, ["render", str(scene), "-f", "4", "-o",
                                     str(tmp_path / "local.png"), "-q"])
    assert local.exit_code == 0, local.stderr
    result = whitted("render", scene, "-f", 4, "-o", tmp_path / "farm.png", "-q",
                     "--cluster", "local:1", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    # the record (frame hash, renderer) too: `whitted animate` takes it as its frame 4
    assert (tmp_path / "farm.png").read_bytes() == (tmp_path / "local.png").read_bytes()
    from whitted.animation.frames import read_frame_digest

    assert read_frame_digest(tmp_path / "farm.png") is not None


def test_ctrl_c_in_a_terminal_keeps_the_frames_and_the_workers_stop_quietly(tmp_path):
    import signal
    import time

    scene = tmp_path / "long.toml"
    scene.write_text(FILM.replace("frames = 6", "frames = 300"))
    folder = tmp_path / "frames"
    code = ("import sys; from whitted.cli.main import main; sys.argv[0] = 'whitted'; main()")
    run = subprocess.Popen([sys.executable, "-c", code, "animate", str(scene), "-o",
                            str(folder), "--cluster", "local:2", "-q"], cwd=tmp_path,
                           env=dict(os.environ), stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        end = time.monotonic() + 240
        while len(list(folder.glob("*.png"))) < 3 and run.poll() is None:
            assert time.monotonic() < end, "no frames arrived"
            time.sleep(0.05)
        os.killpg(run.pid, signal.SIGINT)  # a terminal's Ctrl-C: every process of the group
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    line = lines[0]
    written = sorted(folder.glob("*.png"))
    assert line == (f"interrupted: {len(written)} of 300 frames finished in {folder}; run the "
                    "same command again to continue")
    from whitted.animation.frames import read_frame_digest

    assert all(read_frame_digest(p) is not None for p in written)  # whole frames only
