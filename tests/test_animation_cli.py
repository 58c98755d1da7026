"""``whitted animate`` and ``whitted render --frame``: films, resuming, Ctrl-C."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import imageio.v2 as imageio
import numpy as np
import pytest
from PIL import Image as PILImage

from whitted.animation.frames import read_frame_digest

SCENE = """\
[render]
width = {width}
height = {height}
samples = {samples}

[camera]
position = [0, 1, 6]
look_at = [0, 0.5, 0]

[[lights]]
type = "disk"
center = [2, 5, 3]
radius = 1.0
samples = 8

[[objects]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = {{ preset = "glass" }}

[[objects]]
type = "plane"
material = {{ color = [0.6, 0.6, 0.5] }}

[animation]
frames = {frames}
fps = 8

[[animation.tracks]]
path = "objects[ball].center"
keys = [[0, [-1, 0.5, 0]], [{last}, [1, 0.5, 0]]]
interpolation = "smooth"
"""


def _scene(tmp_path: Path, frames: int = 5, width: int = 24, height: int = 16,
           samples: int = 1) -> Path:
    path = tmp_path / "film.toml"
    path.write_text(SCENE.format(frames=frames, last=frames - 1, width=width, height=height,
                                 samples=samples))
    return path


def _whitted(*args: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "whitted", *args], capture_output=True,
                          text=True, **kw)


def _rendered(stdout: str) -> list[int]:
    return [int(m) for m in re.findall(r"^frame (\d+) \(\d+/\d+\): [\d.]+ s$", stdout, re.M)]


def _kept(stdout: str) -> list[int]:
    return [int(m) for m in re.findall(r"^frame (\d+) \(\d+/\d+\): already done$", stdout,
                                       re.M)]


def test_animate_writes_frames_and_an_mp4_then_resumes(tmp_path):
    scene = _scene(tmp_path)
    film = tmp_path / "out" / "film.mp4"
    film.parent.mkdir()
    result = _whitted("animate", str(scene), "-o", str(film), "--threads", "2")
    assert result.returncode == 0, result.stderr
    frames = sorted((tmp_path / "out" / "film_frames").iterdir())
    assert [f.name for f in frames] == [f"{k:04d}.png" for k in range(5)]
    assert _rendered(result.stdout) == [0, 1, 2, 3, 4]
    reader = imageio.get_reader(film, format="FFMPEG")
    assert reader.get_meta_data()["fps"] == 8.0 and reader.get_meta_data()["size"] == (24, 16)
    assert len([f for f in reader]) == 5  # noqa: C416 - list(reader) asks len(): inf
    reader.close()
    # the ball moves: the frames differ
    a, b = (np.asarray(PILImage.open(frames[k])) for k in (0, 4))
    assert not np.array_equal(a, b)

    # a missing frame and a truncated one are rendered again, the others are kept
    frames[2].unlink()
    frames[3].write_bytes(frames[3].read_bytes()[:100])
    again = _whitted("animate", str(scene), "-o", str(film), "--threads", "1")
    assert again.returncode == 0, again.stderr
    assert _rendered(again.stdout) == [2, 3] and _kept(again.stdout) == [0, 1, 4]
    # a changed setting renders everything
    bigger = _whitted("animate", str(scene), "-o", str(film), "--frames", "1:2", "-W", "26")
    assert _rendered(bigger.stdout) == [1, 2]


def test_render_frame_equals_the_films_frame_at_any_thread_count(tmp_path):
    scene = _scene(tmp_path)
    film = tmp_path / "f"
    assert _whitted("animate", str(scene), "-o", str(film), "--threads", "2").returncode == 0
    still = tmp_path / "still.png"
    result = _whitted("render", str(scene), "--frame", "3", "-o", str(still), "--threads", "1",
                      "-q")
    assert result.returncode == 0, result.stderr
    assert np.array_equal(np.asarray(PILImage.open(still)),
                          np.asarray(PILImage.open(film / "0003.png")))
    assert still.read_bytes() == (film / "0003.png").read_bytes()  # the same file, hash too
    assert not (tmp_path / "f.mp4").exists()  # a folder: frames only


def test_animate_errors_are_one_line(tmp_path):
    scene = _scene(tmp_path)
    for args, message in [
        (["--frames", "2:9"], "error: --frames: frame 9 is outside 0..4 (the scene has 5 "
                              "frames)"),
        (["-o", str(tmp_path / "x.avi")], "unsupported film format '.avi'"),
        (["--set", "objects[ball].radius=-1"], "error: --set: objects[ball].radius: input "
                                               "should be greater than 0"),
        (["--fps", "0"], "error: --fps: must be 0.01 .. 1000 frames a second for MP4, got 0"),
    ]:
        result = _whitted("animate", str(scene), *args)
        assert result.returncode == 2
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], result.stderr


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to a child process")
def test_ctrl_c_keeps_finished_frames_and_the_next_run_continues(tmp_path):
    scene = _scene(tmp_path, frames=12, width=160, height=120, samples=4)
    film = tmp_path / "film.gif"
    folder = tmp_path / "film_frames"
    proc = subprocess.Popen([sys.executable, "-m", "whitted", "animate", str(scene), "-o",
                             str(film), "--threads", "1"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (folder / "0001.png").exists() and time.monotonic() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert "interrupted:" in stderr and "run the same command again" in stderr
    done = sorted(p.name for p in folder.iterdir())
    assert 2 <= len(done) < 12 and not film.exists()
    assert all(read_frame_digest(folder / name) for name in done)  # every file is whole
    rest = _whitted("animate", str(scene), "-o", str(film), "--threads", "2")
    assert rest.returncode == 0, rest.stderr
    assert _kept(rest.stdout) == list(range(len(done)))
    assert _rendered(rest.stdout) == list(range(len(done), 12))
    with PILImage.open(film) as im:
        assert im.n_frames == 12
