"""Nothing a user types destroys a file, hangs, eats memory or prints a traceback.

One test (or a few) per hazard, section by section (A: data, B: hangs and
memory, C: one line, D: exact messages, E: the Python API). The command is run in-process
through its real entry point :func:`whitted.cli.main.main` (fast, and it includes the last
line of defence against tracebacks); a few cases need a real process (signals, FIFOs)."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import png
import pytest
from PIL import Image as PILImage

import whitted
from cli_run import one_line_error, run_main
from whitted.cli import main as cli_main
from whitted.errors import (
    ArgumentError,
    JobStateError,
    OutputError,
    SceneError,
    SceneValidationError,
    WhittedError,
)
from whitted.output import colour, formats

WHITTED = [sys.executable, "-m", "whitted"]
cli_main.EXIT_AT_ONCE_WHEN_ABANDONED = False  # in-process runs must not end the test process

SCENE = """\
[render]
width = 16
height = 12

[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]

[[lights]]
type = "point"
position = [2, 3, 4]

[[objects]]
type = "sphere"
radius = 1.0
"""

TEXTURED = SCENE + """
[[objects]]
type = "rectangle"
corner = [-2, -2, -1]
edge1 = [4, 0, 0]
edge2 = [0, 4, 0]
material = { texture = { type = "image", file = "tex.png" } }
"""


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def png_bytes(path: Path) -> bytes:
    PILImage.fromarray(np.full((4, 4, 3), 200, np.uint8)).save(path)
    return path.read_bytes()


@pytest.fixture()
def no_render(monkeypatch):
    """Fails the test if a render starts: the checks must come before the work."""
    def refuse(self):
        raise AssertionError("the render started")

    monkeypatch.setattr(whitted.RenderJob, "run", refuse)


# ============================================================================ A. data


def test_a1_export_over_its_own_scene_is_refused(tmp_path: Path):
    scene = write(tmp_path / "scene.toml", SCENE)
    line = one_line_error(run_main("export", "scene.toml", "-o", "scene.toml", cwd=tmp_path),
                          "scene.toml", "input")
    assert "choose another output name" in line
    assert scene.read_text() == SCENE


def test_a1_render_over_the_scene_texture_is_refused(tmp_path: Path, no_render):
    write(tmp_path / "scene.toml", TEXTURED)
    texture = png_bytes(tmp_path / "tex.png")
    one_line_error(run_main("render", "scene.toml", "-o", "tex.png", cwd=tmp_path),
                   "tex.png", "input")
    assert (tmp_path / "tex.png").read_bytes() == texture
    # also through another name of the same file (a hard link)
    os.link(tmp_path / "tex.png", tmp_path / "other.png")
    one_line_error(run_main("render", "scene.toml", "-o", "other.png", cwd=tmp_path), "input")
    assert (tmp_path / "tex.png").read_bytes() == texture


def test_a1_render_aov_over_an_input_is_refused(tmp_path: Path, no_render):
    write(tmp_path / "scene.toml", TEXTURED.replace("tex.png", "out.depth.npy"))
    np.save(tmp_path / "out.depth.npy", np.zeros((2, 2, 3), np.float32))
    before = (tmp_path / "out.depth.npy").read_bytes()
    one_line_error(run_main("render", "scene.toml", "-o", "out.png", "--aov", "depth",
                            cwd=tmp_path), "out.depth.npy", "input")
    assert (tmp_path / "out.depth.npy").read_bytes() == before


def test_a1_the_model_material_library_and_its_texture_are_inputs_too(tmp_path: Path,
                                                                       no_render):
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n"
                                    "vt 1 0\nvt 0 1\nusemtl skin\nf 1/1 2/2 3/3\n")
    (tmp_path / "m.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n")
    texture = png_bytes(tmp_path / "skin.png")
    write(tmp_path / "scene.toml", SCENE + '\n[[objects]]\ntype = "mesh"\nfile = "m.obj"\n')
    one_line_error(run_main("render", "scene.toml", "-o", "skin.png", cwd=tmp_path),
                   "skin.png", "input")
    one_line_error(run_main("export", "scene.toml", "-o", "m.mtl", cwd=tmp_path),
                   "m.mtl", "input")
    assert (tmp_path / "skin.png").read_bytes() == texture
    assert "map_Kd" in (tmp_path / "m.mtl").read_text()


def test_a2_export_names_the_output_from_the_whole_stem(tmp_path: Path):
    write(tmp_path / "scene.v1.toml", SCENE)
    write(tmp_path / "scene.v2.toml", SCENE.replace("radius = 1.0", "radius = 0.5"))
    assert run_main("export", "scene.v1.toml", cwd=tmp_path)[0] == 0
    assert run_main("export", "scene.v2.toml", cwd=tmp_path)[0] == 0
    assert "sphere" in (tmp_path / "scene.v1.pov").read_text()
    assert "0.5" in (tmp_path / "scene.v2.pov").read_text()
    assert not (tmp_path / "scene.pov").exists()


def _slow_compile(monkeypatch, signum: int, release: threading.Event) -> threading.Event:
    """The first compile, standing in for Numba's 30 s: sends ``signum`` to this process and
    then takes long (until ``release``). Returns the event set when the stand-in ends."""
    from whitted.render import api

    ended = threading.Event()

    def warm_up(compiled=None, builders=False) -> float:
        if compiled is None:
            os.kill(os.getpid(), signum)
            release.wait(30)
            ended.set()
            raise RuntimeError("the stand-in compile ends the abandoned job here")
        return 0.0

    monkeypatch.setattr(api, "warm_up_kernels", warm_up)
    monkeypatch.setattr(api, "kernels_cached", lambda *key: False)  # a first run
    return ended


@pytest.mark.parametrize(("signum", "status", "word"), [
    (signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_a3_a4_signal_during_the_first_compile_stops_at_once_and_writes_nothing(
        tmp_path: Path, monkeypatch, signum: int, status: int, word: str):
    write(tmp_path / "scene.toml", SCENE)
    good = png_bytes(tmp_path / "out.png")
    release = threading.Event()
    compile_ended = _slow_compile(monkeypatch, signum, release)
    try:
        code, out, err = run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path)
        # the command returned while the stand-in compile was still running: it did not wait
        assert not compile_ended.is_set()
    finally:
        release.set()
    assert code == status, (code, out, err)
    assert f"{word}: before any tile was finished: nothing written" in err
    assert (tmp_path / "out.png").read_bytes() == good  # the good image is kept


LONG_COMPILE = """
import os, signal, sys, time
from whitted.render import api
def warm_up(compiled=None, builders=False):
    if compiled is None:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(120)  # a first compile that takes long and cannot be cut short
    return 0.0
api.warm_up_kernels = warm_up
api.kernels_cached = lambda *key: False  # a first run
from whitted.cli.main import main
sys.argv = ["whitted", "render", "scene.toml", "-o", "out.png"]
main()
"""


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_a3_ctrl_c_during_the_first_compile_ends_the_process_at_once(tmp_path: Path):
    write(tmp_path / "scene.toml", SCENE)
    # the stand-in compile sleeps 120 s: a process that waited for it would pass the timeout
    result = subprocess.run([sys.executable, "-c", LONG_COMPILE], cwd=tmp_path,
                            capture_output=True, text=True, timeout=100)
    assert result.returncode == 130, result.stderr
    assert "interrupted: before any tile was finished: nothing written" in result.stderr
    assert not (tmp_path / "out.png").exists()


def test_a3_interrupt_before_the_first_tile_keeps_the_old_image(tmp_path: Path, monkeypatch):
    """Ctrl-C after the compile but before a tile is finished: nothing to keep, nothing
    written (an existing image is not replaced by a black one)."""
    from whitted.render import api

    write(tmp_path / "scene.toml", SCENE)
    good = png_bytes(tmp_path / "out.png")
    original = api.compile_scene

    def compile_then_interrupt(scene, **options):
        compiled = original(scene, **options)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.3)  # the handler runs and cancels before the first tile
        return compiled

    monkeypatch.setattr(api, "compile_scene", compile_then_interrupt)
    code, out, err = run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path)
    assert code == 130, (out, err)
    assert "nothing written" in err
    assert (tmp_path / "out.png").read_bytes() == good


def test_a4_sigterm_during_the_write_lets_it_finish(tmp_path: Path, monkeypatch):
    write(tmp_path / "scene.toml", SCENE)
    original = formats._write_png

    def write_and_terminate(tmp, *args):
        os.kill(os.getpid(), signal.SIGTERM)  # arrives while the file is being written
        original(tmp, *args)

    monkeypatch.setattr(formats, "_write_png", write_and_terminate)
    code, out, err = run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path)
    assert code == 143, err
    assert "terminated: kept 1/1 tiles" in err
    assert PILImage.open(tmp_path / "out.png").size == (16, 12)
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a4_a_second_ctrl_c_stops_at_once_and_undoes_the_write(tmp_path: Path, monkeypatch):
    write(tmp_path / "scene.toml", SCENE)
    good = png_bytes(tmp_path / "out.png")

    def slow_write(tmp, *args):
        Path(tmp).write_bytes(b"partial")
        os.kill(os.getpid(), signal.SIGINT)
        os.kill(os.getpid(), signal.SIGINT)  # the user insists
        time.sleep(1)
        pytest.fail("the second Ctrl-C did not stop the write")

    monkeypatch.setattr(formats, "_write_png", slow_write)
    code, _out, _err = run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path)
    assert code == 130
    assert (tmp_path / "out.png").read_bytes() == good
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


SIGTERM_AFTER_FIRST_TILES = """
import os, signal, sys, time
from whitted.render import api
original = api.RenderJob._report
def report(self, done, *args):
    original(self, done, *args)
    if done and not getattr(self, "_sent", False):
        self._sent = True
        os.kill(os.getpid(), signal.SIGTERM)
        # the handler runs in the main thread once it holds the GIL: wait for it here (the
        # sleep lets it run), or a small image could finish before it does
        deadline = time.monotonic() + 30
        while not self.cancel_token.cancelled and time.monotonic() < deadline:
            time.sleep(0.001)
api.RenderJob._report = report
from whitted.cli.main import main
sys.argv = ["whitted", "render", "scene.toml", "-o", "out.png", "--threads", "1"]
main()
"""


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_a4_sigterm_during_the_render_keeps_the_finished_tiles(tmp_path: Path):
    write(tmp_path / "scene.toml", SCENE.replace("width = 16\nheight = 12",
                                                 "width = 256\nheight = 256"))
    result = subprocess.run([sys.executable, "-c", SIGTERM_AFTER_FIRST_TILES], cwd=tmp_path,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 143, result.stderr
    assert "terminated: kept" in result.stderr and "Traceback" not in result.stderr
    kept = int(result.stderr.split("kept ")[1].split("/")[0])
    assert 0 < kept < 256
    assert PILImage.open(tmp_path / "out.png").size == (256, 256)


KILLED_WRITER = """
import os, signal, sys
from whitted.files import atomic_write
def die(tmp):
    open(tmp, "wb").write(b"partial")
    os.kill(os.getpid(), signal.SIGKILL)
atomic_write(sys.argv[1], die)
"""


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_a4_temporary_files_of_a_killed_write_are_removed_by_the_next(tmp_path: Path):
    target = tmp_path / "out.png"
    result = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(target)],
                            capture_output=True, timeout=60)
    assert result.returncode == -signal.SIGKILL
    left = [p for p in tmp_path.iterdir() if p.name != "out.png"]
    assert len(left) == 1 and left[0].read_bytes() == b"partial"
    # a live writer's temporary file (this process) is not touched
    live = tmp_path / f".out.png.tmp-{os.getpid()}.abcdef.png"
    live.write_bytes(b"live")
    formats.write_image(target, np.zeros((2, 2, 3), np.float32))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["out.png", live.name])


def test_a5_png_and_jpeg_encode_in_strips(tmp_path: Path):
    """An 8-bit image costs a few bytes per pixel at the encoder, not ~130 (float64 copies of
    the whole image): measured with tracemalloc (NumPy's allocations)."""
    pixels = np.random.default_rng(1).random((1000, 1000, 3), dtype=np.float32) * 1.5
    expected = colour.encode_ldr(pixels, bits=8, transfer="srgb", tonemap="reinhard")
    for name in ("a.png", "a.jpg"):
        tracemalloc.start()
        formats.write_image(tmp_path / name, pixels, tonemap="reinhard")
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        # ~8 MB for the strips (one of 65,536 pixels at a time); whole-image: ~130 MB
        assert peak < 24 * pixels.shape[0] * pixels.shape[1], (name, peak)
    # strips change nothing: the PNG holds exactly the whole-image encoding
    assert np.array_equal(np.asarray(PILImage.open(tmp_path / "a.png")), expected)
    formats.write_image(tmp_path / "b.png", pixels, bit_depth=16)
    reader = png.Reader(filename=str(tmp_path / "b.png"))
    w, h, rows, _info = reader.asDirect()
    stored = np.vstack([np.asarray(r, np.uint16) for r in rows]).reshape(h, w, 3)
    assert np.array_equal(stored, colour.encode_ldr(pixels, bits=16))


def test_a5_memory_need_is_checked_before_the_render(tmp_path: Path, monkeypatch, no_render):
    from whitted.output import safety

    write(tmp_path / "scene.toml", SCENE)
    from whitted.files.memory import MemoryRoom

    monkeypatch.setattr(safety, "memory_room", lambda: MemoryRoom(1000, "is free"))
    line = one_line_error(run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path),
                          "needs about", "memory")
    assert "16x12" in line
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize(("output", "needle"), [
    ("folder", "is a directory"),
    ("missing/out.png", "does not exist"),
    ("/proc/out.png", "cannot write"),
    ("x" * 300 + ".png", "too long"),
])
def test_a6_output_place_is_checked_before_rendering(tmp_path: Path, no_render, output: str,
                                                     needle: str):
    write(tmp_path / "scene.toml", SCENE)
    (tmp_path / "folder").mkdir()
    one_line_error(run_main("render", "scene.toml", "-o", output, cwd=tmp_path), needle)


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="root writes into read-only folders")
def test_a6_read_only_folder(tmp_path: Path, no_render):
    write(tmp_path / "scene.toml", SCENE)
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        one_line_error(run_main("render", "scene.toml", "-o", "locked/out.png", cwd=tmp_path),
                       "cannot write", "locked")
    finally:
        locked.chmod(0o755)


def test_a6_write_failure_after_the_render_is_one_line(tmp_path: Path, monkeypatch):
    write(tmp_path / "scene.toml", SCENE)

    def full_disk(self, path, **kwargs):
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(whitted.Image, "save", full_disk)
    one_line_error(run_main("render", "scene.toml", "-o", "out.png", cwd=tmp_path),
                   "out.png", "cannot write", "No space left on device")


def test_a6_bench_json_in_a_missing_folder(tmp_path: Path, monkeypatch):
    from whitted.bench import command

    monkeypatch.setattr(command, "run_bench", lambda *a, **k: pytest.fail("bench ran"))
    one_line_error(run_main("bench", "--quick", "--json", "nowhere/b.json", cwd=tmp_path),
                   "--json", "does not exist")


# ============================================================================ B. hangs, memory


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_b1_scene_link_to_a_device_is_refused(tmp_path: Path):
    (tmp_path / "zero.toml").symlink_to("/dev/zero")
    one_line_error(run_main("render", "zero.toml", cwd=tmp_path), "zero.toml",
                   "character device")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_b1_fifo_scene_and_texture_do_not_hang(tmp_path: Path):
    from whitted.assets.images import load_image

    os.mkfifo(tmp_path / "pipe.toml")
    result = subprocess.run([*WHITTED, "info", "pipe.toml"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "named pipe (FIFO)" in result.stderr
    os.mkfifo(tmp_path / "tex.png")
    write(tmp_path / "scene.toml", TEXTURED)
    one_line_error(run_main("info", "scene.toml", cwd=tmp_path), "objects[1]", "named pipe")
    with pytest.raises(SceneError, match="named pipe"):
        load_image(tmp_path / "tex.png")
    with pytest.raises(ArgumentError, match="named pipe"):
        whitted.Image.load(tmp_path / "tex.png")


def test_b1_scene_size_limit(tmp_path: Path, monkeypatch):
    from whitted.scene import io as scene_io

    write(tmp_path / "big.toml", SCENE + "#" * 2000 + "\n")
    monkeypatch.setattr(scene_io, "MAX_SCENE_BYTES", 1000)
    one_line_error(run_main("info", "big.toml", cwd=tmp_path), "scene file too large")


def _png16(path: Path, width: int, height: int) -> Path:
    writer = png.Writer(width=width, height=height, greyscale=True, bitdepth=16)
    with open(path, "wb") as f:
        writer.write(f, [[1000] * width for _ in range(height)])
    return path


def test_b2_16_bit_png_size_is_checked_before_decoding(tmp_path: Path, monkeypatch):
    from whitted.assets import images

    images.clear_image_cache()
    monkeypatch.setattr(images, "MAX_TEXTURE_PIXELS", 100, raising=False)
    with pytest.raises(SceneError, match="image too large: 20x20"):
        images.load_image(_png16(tmp_path / "deep.png", 20, 20))
    PILImage.fromarray(np.zeros((20, 20, 3), np.uint8)).save(tmp_path / "flat.png")
    with pytest.raises(SceneError, match="image too large: 20x20"):
        images.load_image(tmp_path / "flat.png")


def test_b2_huge_header_is_refused_without_decoding(tmp_path: Path):
    """A 16-bit PNG that claims 100000 x 100000 pixels (the pixels would need 60+ GB)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", 100_000, 100_000, 16, 2, 0, 0, 0)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(
        b"IDAT", zlib.compress(b"\0" * 1000)) + chunk(b"IEND", b"")
    (tmp_path / "bomb.png").write_bytes(data)
    with pytest.raises(SceneError, match="image too large: 100000x100000"):
        whitted.assets.images.load_image(tmp_path / "bomb.png")


def test_b3_binary_model_is_refused_from_its_first_bytes(tmp_path: Path):
    """A 3 GiB sparse file of zero bytes named .obj: refused at once, not read whole."""
    from whitted.assets import load_mesh

    big = tmp_path / "huge.obj"
    with open(big, "wb") as f:
        f.truncate(3 << 30)
    start = time.perf_counter()
    with pytest.raises(SceneError, match="binary data .* not an OBJ text file"):
        load_mesh(big)
    assert time.perf_counter() - start < 2.0
    ply = tmp_path / "huge.ply"
    with open(ply, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.truncate(3 << 30)
    with pytest.raises(SceneError, match="PLY file too large"):
        load_mesh(ply)
    (tmp_path / "fake.ply").write_bytes(b"\x00\x01binary junk" * 100)
    with pytest.raises(SceneError, match="not a PLY file"):
        load_mesh(tmp_path / "fake.ply")
    (tmp_path / "fake.glb").write_bytes(b"junk" * 100)
    with pytest.raises(SceneError, match="not a GLB file"):
        load_mesh(tmp_path / "fake.glb")


# ============================================================================ C. one line


def _toml_case(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    return write(tmp_path / name, text)


@pytest.mark.parametrize(("text", "needles"), [
    (SCENE + '\n[[lights]]\ntype = "directional"\ndirection = [1e200, 0, 0]\n',
     ["lights[1].direction[0]", "too large"]),
    (SCENE.replace("radius = 1.0", 'radius = 1.0\nmaterial = { preset = ["glass"] }'),
     ["preset"]),
    (SCENE.replace("radius = 1.0", "radius = 1.0\nmaterial = { preset = { a = 1 } }"),
     ["preset"]),
    ("a = " + "[" * 1000 + "]" * 1000 + "\n", ["nested more than"]),
    (SCENE + '\n[[objects]]\ntype = "mesh"\nvertices = [[0,0,0],[1,0,0],[0,1,0]]\n'
     "faces = [[0, 1, 9223372036854775808]]\n", ["objects[1].faces", "too large"]),
    (SCENE.replace("radius = 1.0", "radius = 1e300"), ["objects[0].radius", "too large"]),
], ids=["direction-1e200", "preset-list", "preset-table", "nesting-1000", "face-2^63",
        "radius-1e300"])
def test_c_former_tracebacks_are_one_line(tmp_path: Path, text: str, needles: list[str]):
    _toml_case(tmp_path, text)
    one_line_error(run_main("render", "case.toml", "-o", "x.png", cwd=tmp_path), *needles)


def test_c_json_nesting_and_huge_integer(tmp_path: Path):
    write(tmp_path / "deep.json", "[" * 1000 + "]" * 1000)
    one_line_error(run_main("info", "deep.json", cwd=tmp_path), "nested more than")
    write(tmp_path / "big.json", '{"render": {"width": ' + "9" * 5000 + "}}")
    one_line_error(run_main("info", "big.json", cwd=tmp_path), "too large")
    write(tmp_path / "big.toml", "[render]\nwidth = " + "9" * 5000 + "\n")
    one_line_error(run_main("info", "big.toml", cwd=tmp_path), "big.toml")


def test_c_path_component_over_255_bytes(tmp_path: Path):
    one_line_error(run_main("render", "y" * 300 + ".toml", cwd=tmp_path), "too long")
    write(tmp_path / "scene.toml", SCENE + '\n[[objects]]\ntype = "mesh"\nfile = "'
          + "m" * 300 + '.obj"\n')
    one_line_error(run_main("render", "scene.toml", cwd=tmp_path), "objects[1].file", "too long")


def test_c_user_text_is_printed_literally(tmp_path: Path):
    write(tmp_path / "scene.toml", SCENE.replace(
        "radius = 1.0", 'radius = 1.0\nname = "[/bold] and [red]kept[/red] :100:"'))
    code, out, err = run_main("info", "scene.toml", cwd=tmp_path)
    assert code == 0, err
    assert "[/bold] and [red]kept[/red] :100:" in out
    # an error on line 100 shows ":100:", not an emoji; a bracketed name stays in the message
    write(tmp_path / "long.toml", SCENE + "\n" * (100 - SCENE.count("\n") - 2)
          + '[background]\ncolor = "[bold]red"\n')
    line = one_line_error(run_main("render", "long.toml", cwd=tmp_path), "long.toml:100:",
                          "'[bold]red'")
    assert "\N{HUNDRED POINTS SYMBOL}" not in line


# ============================================================================ D. messages


@pytest.mark.parametrize(("change", "needles"), [
    (("radius = 1.0", 'radius = "2"'), ["objects[0].radius", "expected a number", "'2'"]),
    (("radius = 1.0", "radius = true"), ["objects[0].radius", "expected a number"]),
    (("radius = 1.0", 'radius = 1.0\nmaterial = { fresnel = "yes" }'),
     ["fresnel", "true or false"]),
    (("width = 16", 'width = "32"'), ["render.width", "expected an integer"]),
    (("width = 16", "width = 32.0"), ["render.width", "integer"]),
    (("radius = 1.0", "radius = 1.0\nname = 5"), ["objects[0].name", "expected a string"]),
], ids=["radius-str", "radius-bool", "fresnel-str", "width-str", "width-float", "name-int"])
@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_d1_strict_types_in_toml_and_json(tmp_path: Path, change, needles, suffix: str):
    import tomllib

    text = SCENE.replace(*change)
    if suffix == ".json":
        text = json.dumps(tomllib.loads(text), indent=1)
    write(tmp_path / f"case{suffix}", text)
    one_line_error(run_main("info", f"case{suffix}", cwd=tmp_path), *needles)


def test_d1_documented_forms_stay_valid(tmp_path: Path):
    text = SCENE.replace("radius = 1.0", 'radius = 2\nmaterial = { color = "#ff8000" }')
    write(tmp_path / "ok.toml", text)
    scene = whitted.load_scene(tmp_path / "ok.toml")
    assert scene.objects[0].radius == 2.0
    assert scene.objects[0].material.color[0] == 1.0


def test_d2_json_duplicate_keys_are_rejected(tmp_path: Path):
    write(tmp_path / "dup.json", '{\n "render": {"width": 16},\n "render": {"width": 32}\n}\n')
    one_line_error(run_main("info", "dup.json", cwd=tmp_path), "dup.json:3:",
                   "duplicate key 'render'")


def test_d3_no_raw_warnings(tmp_path: Path, monkeypatch):
    from whitted.assets import images

    # an image over Pillow's own warning threshold but under whitted's limit: read silently
    monkeypatch.setattr(PILImage, "MAX_IMAGE_PIXELS", 100)
    PILImage.fromarray(np.zeros((10, 15, 3), np.uint8)).save(tmp_path / "t.png")
    images.clear_image_cache()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert images.load_image(tmp_path / "t.png").shape == (10, 15, 3)


def test_d3_extreme_values_are_errors_not_warnings(tmp_path: Path):
    write(tmp_path / "big.toml", SCENE.replace("radius = 1.0", "radius = 1e200"))
    code, out, err = run_main("render", "big.toml", "-o", "x.png", cwd=tmp_path)
    assert "Warning" not in err
    one_line_error((code, out, err), "too large")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX")
def test_d4_what_a_path_is(tmp_path: Path):
    os.mkfifo(tmp_path / "fifo.toml")
    (tmp_path / "loop.toml").symlink_to(tmp_path / "loop.toml")
    (tmp_path / "broken.toml").symlink_to(tmp_path / "absent.toml")
    for name, needle in (("fifo.toml", "is a named pipe (FIFO), not a regular file"),
                         ("loop.toml", "a symbolic link loop"),
                         ("broken.toml", "a broken symbolic link"),
                         ("absent.toml", "no such file")):
        one_line_error(run_main("info", name, cwd=tmp_path), name, needle)


def test_d5_model_errors_name_the_scene_key_and_no_internals(tmp_path: Path):
    (tmp_path / "bad.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0\n1\n2\n")
    write(tmp_path / "scene.toml", SCENE + '\n[[objects]]\ntype = "mesh"\nfile = "bad.ply"\n')
    for command in (["render", "scene.toml", "-o", "x.png"], ["info", "scene.toml"],
                    ["export", "scene.toml"]):
        one_line_error(run_main(*command, cwd=tmp_path), "scene.toml", "objects[1].file",
                       "bad.ply", "PLY", "missing element or property 'y'")
    (tmp_path / "latin.stl").write_bytes(
        "solid caf\xe9\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 1 0\nendloop\nendfacet\nendsolid\n".encode("latin-1"))
    with contextlib.suppress(SceneError):
        mesh = whitted.assets.load_mesh(tmp_path / "latin.stl")
        assert mesh.triangle_records == 1
    try:
        whitted.assets.load_mesh(tmp_path / "latin.stl")
    except SceneError as exc:
        assert "charset_normalizer" not in str(exc) and "No module" not in str(exc)


def test_d6_truncated_toml_bom_and_long_keys(tmp_path: Path):
    write(tmp_path / "cut.toml", SCENE + '[[objects]]\ntype = "sph')
    one_line_error(run_main("info", "cut.toml", cwd=tmp_path),
                   f"cut.toml:{SCENE.count(chr(10)) + 2}:", "cut off")
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + SCENE.encode())
    assert run_main("info", "bom.toml", cwd=tmp_path)[0] == 0
    (tmp_path / "bom.json").write_bytes(b"\xef\xbb\xbf" + json.dumps({"objects": []}).encode())
    assert run_main("info", "bom.json", cwd=tmp_path)[0] == 0
    write(tmp_path / "key.toml", SCENE + "k" * 100_000 + " = 1\n")
    line = one_line_error(run_main("info", "key.toml", cwd=tmp_path), "unknown key")
    assert len(line) < 500


def test_d7_bench_unknown_scene_is_one_line(tmp_path: Path):
    one_line_error(run_main("bench", "--scene", "nope", cwd=tmp_path), "nope", "seed000")


def test_d8_bit_depth_16_png_from_the_command_line(tmp_path: Path):
    write(tmp_path / "scene.toml", SCENE)
    code, out, err = run_main("render", "scene.toml", "-o", "deep.png", "--bit-depth", "16",
                              "-q", cwd=tmp_path)
    assert code == 0, err
    _w, _h, _rows, info = png.Reader(filename=str(tmp_path / "deep.png")).read()
    assert info["bitdepth"] == 16 and (_w, _h) == (16, 12)
    one_line_error(run_main("render", "scene.toml", "-o", "x.jpg", "--bit-depth", "16",
                            cwd=tmp_path),
                   "x.jpg: --bit-depth 16 is only for .png output (got jpeg")


# ============================================================================ E. Python API


@pytest.mark.parametrize("make", [
    lambda: whitted.Sphere(radius=-1),
    lambda: whitted.Sphere(radius=1, colour=3),
    lambda: whitted.Scene(render={"width": 0}),
    lambda: whitted.Material(preset="nope"),
    lambda: whitted.Box(min=[0, 0, 0], max=[0, 1, 1]),
    lambda: whitted.Scene.model_validate({"objects": [{"type": "cube"}]}),
    lambda: whitted.load_scene("/nonexistent/scene.toml"),
    lambda: whitted.DirectionalLight(direction=[1e200, 0, 0]),
    lambda: whitted.Sphere(radius=1e300),
    lambda: whitted.Material(preset=["glass"]),
], ids=["radius", "unknown-key", "width", "preset", "box", "model-validate", "load",
        "direction-1e200", "radius-1e300", "preset-list"])
def test_e_bad_values_raise_whitted_errors(make):
    with pytest.raises(WhittedError) as info:
        make()
    assert "\n" not in str(info.value)
    if isinstance(info.value, SceneValidationError):
        assert info.value.errors()  # still pydantic's details


def test_e_assignment_is_validated_with_the_library_error():
    sphere = whitted.Sphere(radius=1)
    with pytest.raises(SceneValidationError, match=r"Sphere\.radius: .*greater than 0"):
        sphere.radius = -2
    assert sphere.radius == 1


def test_e_render_accepts_a_path_and_refuses_other_things(tmp_path: Path):
    write(tmp_path / "scene.toml", SCENE)
    image = whitted.render(str(tmp_path / "scene.toml"), width=8, height=6)
    assert (image.width, image.height) == (8, 6)
    assert whitted.render(tmp_path / "scene.toml", width=4, height=3).width == 4
    with pytest.raises(ArgumentError, match="Scene or the path of a scene file"):
        whitted.render(42)
    with pytest.raises(SceneValidationError, match="unknown key"):
        whitted.render(tmp_path / "scene.toml", widht=8)


@pytest.mark.parametrize(("kwargs", "needle"), [
    ({"tile_size": 0}, "tile_size must be between 1"),
    ({"tile_size": -16}, "tile_size must be between 1"),
    ({"tile_size": 2.5}, "tile_size must be a whole number"),
    ({"threads": 30000}, "threads must be between 0 and 1024"),
    ({"threads": -1}, "threads must be between"),
    ({"progress": 3}, "progress must be callable"),
    ({"cancel": "yes"}, "cancel must be a CancelToken"),
])
def test_e_render_job_checks_its_arguments(kwargs, needle):
    with pytest.raises(ArgumentError, match=needle):
        whitted.RenderJob(whitted.default_scene(), **kwargs)


def test_e_render_job_states(tmp_path: Path):
    scene = whitted.default_scene().with_settings(width=8, height=6)
    job = whitted.RenderJob(scene)
    with pytest.raises(JobStateError, match="before start"):
        job.wait()
    job.start()
    with pytest.raises(JobStateError, match="already started"):
        job.start()
    image = job.wait()
    assert image is not None and image.width == 8
    ran = whitted.RenderJob(scene)
    assert ran.run() is ran.wait()  # run() then wait(): the image, not an error


def test_e_other_public_functions_raise_the_documented_errors(tmp_path: Path):
    pixels = np.zeros((2, 2, 3), np.float32)
    with pytest.raises(ArgumentError, match="unsupported image format"):
        whitted.Image(pixels).save(tmp_path / "x.gif")
    with pytest.raises(ArgumentError, match="bit_depth=16 is only supported for .png"):
        whitted.Image(pixels).save(tmp_path / "x.jpg", bit_depth=16)
    with pytest.raises(ArgumentError, match="shape"):
        whitted.Image(np.zeros((2, 2)))
    with pytest.raises(ArgumentError, match="path of a scene file"):
        whitted.load_scene(3)
    with pytest.raises(ArgumentError, match="colorspace"):
        whitted.assets.images.load_image(tmp_path / "x.png", colorspace="rgb")
    assert issubclass(ArgumentError, ValueError)  # what these raised before


def test_e_error_classes_are_documented():
    doc = (Path(__file__).resolve().parents[1] / "docs" / "scene-format.md").read_text()
    for cls in (WhittedError, SceneError, SceneValidationError, ArgumentError, JobStateError,
                OutputError):
        assert cls.__name__ in doc, cls
        assert issubclass(cls, WhittedError)


# ============================================================================ F. documentation


def test_f_aov_files_are_as_documented(tmp_path: Path):
    doc = (Path(__file__).resolve().parents[1] / "docs" / "scene-format.md").read_text()
    for needle in ("`STEM.depth.npy` | float32, (H, W)", "`STEM.normal.npy` | float32, (H, W, 3)",
                   "`STEM.id.npy` | int32, (H, W)", "**vertical** by default",
                   "counter-clockwise when looking down the axis", "positions in float64"):
        assert needle in doc, needle
    write(tmp_path / "scene.v1.toml", SCENE)
    code, _out, err = run_main("render", "scene.v1.toml", "-o", "out.v1.png", "--aov",
                               "depth,normal,id", "-q", cwd=tmp_path)
    assert code == 0, err
    depth = np.load(tmp_path / "out.v1.depth.npy")
    normal = np.load(tmp_path / "out.v1.normal.npy")
    ids = np.load(tmp_path / "out.v1.id.npy")
    assert (depth.dtype, depth.shape) == (np.float32, (12, 16))
    assert (normal.dtype, normal.shape) == (np.float32, (12, 16, 3))
    assert (ids.dtype, ids.shape) == (np.int32, (12, 16))
    # a corner misses the sphere, the centre hits it at distance 5 - 1 = 4 facing the camera
    assert depth[0, 0] == np.inf and ids[0, 0] == -1 and not normal[0, 0].any()
    assert ids[6, 8] == 0 and abs(depth[6, 8] - 4.0) < 0.05 and normal[6, 8, 2] > 0.95


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
@pytest.mark.parametrize(("signum", "status", "word"), [
    (signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_a_signal_after_the_first_tiles_keeps_them(tmp_path: Path, monkeypatch, signum: int,
                                                   status: int, word: str):
    """The signal arrives when the first tiles are done (an event, not a sleep): the image
    is written with them, at full size, the rest black, and the status says which signal."""
    from whitted.render import api

    write(tmp_path / "scene.toml", 'background = "#808080"\n' + SCENE.replace(
        "width = 16", "width = 256").replace("height = 12", "height = 192"))
    original = api.RenderJob._report
    sent = []

    def report_then_signal(self, *args, **kwargs):
        original(self, *args, **kwargs)
        if not sent:
            sent.append(True)
            os.kill(os.getpid(), signum)
            # the handler (main thread) cancels the job: go on only once it has
            assert self.cancel_token._event.wait(30)

    monkeypatch.setattr(api.RenderJob, "_report", report_then_signal)
    code, out, err = run_main("render", "scene.toml", "-o", "out.png", "--threads", "1",
                              cwd=tmp_path)
    assert code == status, (out, err)
    assert word in err and "Traceback" not in err
    with PILImage.open(tmp_path / "out.png") as image:
        assert image.size == (256, 192)
        pixels = np.asarray(image.convert("RGB"))
    # 16-pixel tiles (render/api.py DEFAULT_TILE) on a grey background: rendered or black
    lit = pixels.reshape(12, 16, 16, 16, 3).max(axis=(1, 3, 4))
    assert 0 < (lit > 0).sum() < lit.size  # some tiles kept, not all rendered
