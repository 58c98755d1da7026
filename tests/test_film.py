"""The one film API (whitted.animation.film), the one interrupt guard (cli/interrupt.py), and
the output safety of every command that writes.
Signals are sent from inside the work (a frame finished, a frame handed to
ffmpeg), never after a sleep."""

from __future__ import annotations

import ast
import hashlib
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import psutil
import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image as PILImage

from cli_run import run_main
from whitted.animation import film as film_api
from whitted.animation.film import (
    FilmPaths,
    film_paths,
    frame_name,
    parse_frame_range,
    prepare_film,
    render_film,
)
from whitted.animation.frames import frame_digest, is_whitted_frame, read_frame_digest
from whitted.errors import OutputError, RenderCancelled, SceneError
from whitted.output import video
from whitted.output.video import encode_film
from whitted.render.api import CancelToken
from whitted.scene import load_scene

SRC = Path(__file__).resolve().parents[1] / "src" / "whitted"

SCENE = """\
[render]
width = 16
height = 12
samples = 1

[camera]
position = [0, 1, 6]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [2, 5, 3]

[[objects]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = {{ color = [0.8, 0.2, 0.2] {texture} }}

[[objects]]
type = "plane"
material = {{ color = [0.6, 0.6, 0.5] }}

[animation]
frames = {frames}
fps = 8

[[animation.tracks]]
path = "objects[ball].center"
keys = [[0, [-1, 0.5, 0]], [{last}, [1, 0.5, 0]]]
"""


def _scene(folder: Path, frames: int = 4, texture: str | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    tex = ""
    if texture is not None:
        PILImage.fromarray(np.full((4, 4, 3), 200, np.uint8)).save(folder / texture)
        tex = f', texture = {{ type = "image", file = "{texture}" }}'
    path = folder / "film.toml"
    path.write_text(SCENE.format(frames=frames, last=frames - 1, texture=tex))
    return path


def _digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def one_line(result: tuple[int, str, str], code: int, *needles: str) -> str:
    status, out, err = result
    assert status == code, result
    assert "Traceback" not in err + out and "internal error" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


# ----------------------------------------------------------------- naming, paths, ranges


def test_frame_names_sort_in_frame_order_beyond_ten_thousand_frames():
    assert frame_name(7, 5) == "0007.png"
    assert frame_name(9999, 10_000) == "9999.png"
    assert frame_name(7, 10_001) == "00007.png" and frame_name(10_000, 10_001) == "10000.png"
    assert frame_name(123_456, 1_000_000) == "123456.png"
    names = [frame_name(k, 10_001) for k in range(10_001)]
    assert sorted(names) == names and len(set(names)) == 10_001


def test_film_paths_and_frame_ranges(tmp_path):
    assert film_paths(tmp_path / "a.mp4") == FilmPaths(tmp_path / "a.mp4", tmp_path / "a_frames")
    assert film_paths(tmp_path / "frames") == FilmPaths(None, tmp_path / "frames")
    assert FilmPaths(None, tmp_path).frame(3, 20_000) == tmp_path / "00003.png"
    with pytest.raises(OutputError, match="unsupported film format '.avi'"):
        film_paths(tmp_path / "a.avi")
    assert parse_frame_range("2:4", 10) == range(2, 5)
    assert parse_frame_range(":1", 10) == range(0, 2)
    assert parse_frame_range("8:", 10) == range(8, 10)
    assert parse_frame_range(" 5 ", 10) == range(5, 6)
    assert parse_frame_range(None, 3) == range(3)
    for bad, why in [("4:2", "is empty"), ("0:10", "frame 10 is outside 0..9"),
                     ("x", "expected A:B")]:
        with pytest.raises(SceneError, match=why):
            parse_frame_range(bad, 10)


def test_nothing_outside_cli_imports_cli():
    offenders = []
    for path in SRC.rglob("*.py"):
        if "cli" in path.relative_to(SRC).parts[:1] or path.parent == SRC and path.name in (
                "__main__.py", "program.py"):
            continue  # the command line itself, and the program above it that starts it
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                module = node.module or ""
                dots = "." * node.level
                if (module == "cli" or module.startswith("cli.")) and node.level >= 1 \
                        or module.startswith("whitted.cli"):
                    offenders.append(f"{path.relative_to(SRC)}: from {dots}{module}")
            elif isinstance(node, ast.Import):
                offenders += [f"{path.relative_to(SRC)}: import {a.name}" for a in node.names
                              if a.name.startswith("whitted.cli")]
    assert offenders == []


def test_one_interrupt_guard_no_hand_written_signal_handlers():
    # the kernels' first compile keeps Python's own Ctrl-C handler (render/warm_up.py): it
    # runs inside the guard's work and re-raises what Python's handler raises
    # farm/cluster.py ignores SIGINT (SIG_IGN, no handler) while a local cluster's worker
    # processes start, so that they inherit it and a terminal's Ctrl-C reaches only the client;
    # farm/probe.py does the same (SIG_IGN) in a local worker its nanny restarted
    allowed = {Path("cli/interrupt.py"), Path("render/warm_up.py"), Path("farm/cluster.py"),
               Path("farm/probe.py")}
    found = []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr == "signal" and isinstance(node.func.value, ast.Name)
                    and node.func.value.id == "signal"):
                found.append(path.relative_to(SRC))
    assert sorted(set(found) - allowed) == []


def test_no_copies_of_the_frame_naming():
    for path in SRC.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        if path.name != "film.py" or path.parent.name != "animation":
            assert "def frame_name" not in text and "def frame_file_name" not in text, path
            assert "def parse_frame_range" not in text and "def film_paths" not in text, path


# ----------------------------------------------------------------- render_film


def test_render_film_progress_cancel_and_resume(tmp_path):
    scene = load_scene(_scene(tmp_path, frames=4))
    out = tmp_path / "f.gif"
    cancel = CancelToken()
    events = []

    def progress(p):
        events.append((p.event, p.frame, p.done, p.total))
        if p.event == "done" and p.frame == 1:
            cancel.cancel()  # stop once frame 1 is finished

    first = render_film(scene, out, progress=progress, cancel=cancel, threads=1)
    assert first.cancelled and not first.complete and first.film is None
    assert first.rendered == [0, 1] and first.kept == []
    assert [p.name for p in first.files] == ["0000.png", "0001.png"]
    assert sorted(p.name for p in (tmp_path / "f_frames").iterdir()) == ["0000.png", "0001.png"]
    assert not out.exists()
    assert [e for e in events if e[0] != "tiles"] == [
        ("frame", 0, 0, 4), ("done", 0, 1, 4), ("frame", 1, 1, 4), ("done", 1, 2, 4)]
    assert any(e[0] == "tiles" for e in events)

    rest = render_film(scene, out, threads=1)
    assert rest.complete and not rest.cancelled and rest.film == out
    assert rest.kept == [0, 1] and rest.rendered == [2, 3]
    assert rest.size == (16, 12)
    with PILImage.open(out) as im:
        assert im.n_frames == 4 and im.info["duration"] == 120  # 8 fps: 1/8 s in whole 1/100 s
    again = render_film(scene, out, frames=range(1, 3), threads=1)
    assert again.kept == [1, 2] and again.rendered == []


def test_render_film_frames_only_into_a_folder(tmp_path):
    scene = load_scene(_scene(tmp_path, frames=3))
    result = render_film(scene, tmp_path / "frames", threads=1)
    assert result.complete and result.film is None and result.rendered == [0, 1, 2]
    for k, path in enumerate(result.files):
        assert read_frame_digest(path) == frame_digest(scene.at_frame(k), k)


# -----------------------------------------------------------------


def test_animate_never_writes_over_files_whitted_did_not_write(tmp_path, monkeypatch):
    scene = _scene(tmp_path / "s")
    photos = tmp_path / "photos"
    photos.mkdir()
    for k in range(3):
        PILImage.fromarray(np.full((8, 8, 3), 40 * k, np.uint8)).save(photos / f"{k:04d}.png")
    before = _digest(photos)
    line = one_line(run_main("animate", scene, "-o", photos, "-q", cwd=tmp_path),
                    2, str(photos / "0000.png"), "whitted did not write it")
    assert line.startswith("error: ")
    assert _digest(photos) == before  # nothing changed, nothing added
    # a film's frames folder with a foreign file further on: nothing is written at all
    film = tmp_path / "out.mp4"
    (tmp_path / "out_frames").mkdir()
    (tmp_path / "out_frames" / "0002.png").write_bytes(b"my notes")
    one_line(run_main("animate", scene, "-o", film, "-q", cwd=tmp_path), 2,
             "0002.png", "whitted did not write it")
    assert sorted(p.name for p in (tmp_path / "out_frames").iterdir()) == ["0002.png"]
    assert not film.exists()


def test_frames_that_carry_the_record_are_resumed_or_replaced(tmp_path):
    scene = load_scene(_scene(tmp_path, frames=3))
    render_film(scene, tmp_path / "f", threads=1)
    damaged = tmp_path / "f" / "0001.png"
    damaged.write_bytes(damaged.read_bytes()[:120])  # cut short: still whitted's own
    assert is_whitted_frame(damaged) and read_frame_digest(damaged) is None
    again = render_film(scene, tmp_path / "f", threads=1)
    assert again.rendered == [1] and again.kept == [0, 2]


def _refingerprint(path: Path, fingerprint: str) -> None:
    """``path`` as another renderer would have written it: the same pixels and frame hash,
    its fingerprint recorded instead of this process's."""
    from PIL.PngImagePlugin import PngInfo

    from whitted.fingerprint import FINGERPRINT_KEY

    with PILImage.open(path) as im:
        info = PngInfo()
        for key, value in im.text.items():
            info.add_text(key, fingerprint if key == FINGERPRINT_KEY else value)
        im.save(path, pnginfo=info)


def test_a_resume_never_keeps_frames_of_another_renderer(tmp_path):
    """Frames carry the fingerprint they were made with: a frame whose hash matches but whose
    renderer differs (another source, Numba, CPU target) is rendered again, the rest kept."""
    from whitted.fingerprint import FINGERPRINT_KEY, fingerprint_fields, renderer_fingerprint

    scene = load_scene(_scene(tmp_path, frames=4))
    render_film(scene, tmp_path / "f", threads=1)
    ours = renderer_fingerprint()
    fields = fingerprint_fields(ours)
    others = {1: ours.replace(fields["source"], "0123456789abcdef"),
              2: ours.replace(f"cpu {fields['cpu']}", "cpu generic/e3b0c442"),
              3: ours.replace(f"numba {fields['numba']}", "numba 0.61.0")}
    for frame, fingerprint in others.items():
        assert fingerprint != ours
        _refingerprint(tmp_path / "f" / frame_name(frame, 4), fingerprint)
    again = render_film(scene, tmp_path / "f", threads=1)
    assert again.kept == [0] and again.rendered == [1, 2, 3]
    for k in range(4):
        with PILImage.open(tmp_path / "f" / frame_name(k, 4)) as im:
            assert im.text[FINGERPRINT_KEY] == ours


def test_a_frame_made_for_another_cpu_target_is_not_kept(tmp_path):
    """A process compiling for another CPU target (``NUMBA_CPU_NAME=generic``) has another
    fingerprint: its frames are rendered again by this one."""
    from whitted.fingerprint import FINGERPRINT_KEY, renderer_fingerprint

    scene_path = _scene(tmp_path, frames=2)
    code = ("from whitted.fingerprint import renderer_fingerprint as f; print(f())")
    env = dict(os.environ, NUMBA_CPU_NAME="generic", PYTHONPATH=str(SRC.parent))
    theirs = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                            text=True, check=True, timeout=120).stdout.strip()
    assert theirs != renderer_fingerprint() and "cpu generic/" in theirs
    render_film(load_scene(scene_path), tmp_path / "f", threads=1)
    _refingerprint(tmp_path / "f" / "0001.png", theirs)
    again = render_film(load_scene(scene_path), tmp_path / "f", threads=1)
    assert again.kept == [0] and again.rendered == [1]
    with PILImage.open(tmp_path / "f" / "0001.png") as im:
        assert im.text[FINGERPRINT_KEY] == renderer_fingerprint()


# -----------------------------------------------------------------


def test_animate_sweep_export_refuse_to_write_over_their_inputs(tmp_path, monkeypatch):
    scene = _scene(tmp_path, texture="0000.png")
    texture = tmp_path / "0000.png"
    before = texture.read_bytes()
    for args, needle in [
        (["animate", scene, "-o", "."], "is an input of this job"),
        (["animate", scene, "-o", "0000.gif"], None),  # fine: not an input
        (["sweep", scene, "-o", "0000.png", "--set", "objects[ball].radius=0.3,0.4"],
         "is an input of this job"),
        (["export", scene, "-o", "0000.png"], "is an input of this job"),
        (["animate", scene, "-o", "film.toml.gif"], None),
    ]:
        result = run_main(*args, "-q", cwd=tmp_path) if args[0] != "export" \
            else run_main(*args, cwd=tmp_path)
        if needle is None:
            assert result[0] == 0, result
        else:
            one_line(result, 2, needle, "0000.png")
        assert texture.read_bytes() == before
    scene_text = scene.read_bytes()
    (tmp_path / "tex.gif").write_bytes(b"GIF89a")
    gif_scene = tmp_path / "gif.toml"
    gif_scene.write_text(scene.read_text().replace("0000.png", "tex.gif"))
    one_line(run_main("animate", gif_scene, "-o", "tex.gif", cwd=tmp_path), 2,
             "is an input of this job")
    assert (tmp_path / "tex.gif").read_bytes() == b"GIF89a"
    assert scene.read_bytes() == scene_text


def test_stefan_film_refuses_to_write_over_its_case_file(tmp_path, monkeypatch):
    case = tmp_path / "case.gif"  # a case file named like a film
    case.write_text("[grid]\ncells = 8\n")
    one_line(run_main("stefan", "film", case, "-o", case, cwd=tmp_path), 2,
             "is an input of this job")
    assert case.read_text() == "[grid]\ncells = 8\n"
    assert not (tmp_path / "case_stefan").exists()


# -----------------------------------------------------------------


@pytest.mark.parametrize(("args", "needle"), [
    (["--fps", "1e-9"], "--fps: must be 0.01 .. 1000 frames a second for MP4, got 1e-09"),
    (["--fps", "inf"], "--fps: must be 0.01 .. 1000"),
    (["--fps", "nan"], "--fps: must be 0.01 .. 1000"),
    (["--fps", "1e300"], "--fps: must be 0.01 .. 1000"),
    (["--fps", "0.001", "-o", "f.gif"], "--fps: must be 0.01 .. 50 frames a second for GIF"),
    (["--fps", "60", "-o", "f.gif"], "whole hundredths of a second"),
    (["--crf", "52"], "--crf: must be 0 .. 51"),
])
def test_film_options_checked_before_rendering(tmp_path, monkeypatch, args, needle):
    scene = _scene(tmp_path)
    film = tmp_path / "f.mp4"
    film.write_bytes(b"a good film")
    one_line(run_main("animate", scene, "-o", "f.mp4", *args, cwd=tmp_path), 2,
             needle)
    assert film.read_bytes() == b"a good film"
    assert not (tmp_path / "f_frames").exists()  # nothing rendered


def test_a_scene_fps_the_gif_cannot_show_names_the_key(tmp_path, monkeypatch):
    scene = _scene(tmp_path)
    scene.write_text(scene.read_text().replace("fps = 8", "fps = 1e-9"))
    one_line(run_main("animate", scene, "-o", "f.gif", cwd=tmp_path), 2,
             "animation.fps: must be 0.01 .. 50")


def test_a_failed_encode_never_replaces_a_good_film(tmp_path, monkeypatch):
    frames = [np.full((8, 8, 3), 60 * k, np.uint8) for k in range(3)]
    film = encode_film(frames, tmp_path / "f.mp4", fps=4)
    good = film.read_bytes()
    real = video._ffmpeg_command
    monkeypatch.setattr(video, "_ffmpeg_command",
                        lambda *a: [*real(*a)[:-1], "-no-such-option", a[0]])
    with pytest.raises(ValueError, match=r"ffmpeg failed \(exit status"):
        encode_film(frames, film, fps=4)
    assert film.read_bytes() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.mp4"]  # no temporary left


def test_a_cancelled_encode_stops_ffmpeg_and_keeps_the_old_film(tmp_path, monkeypatch):
    film = encode_film([np.zeros((8, 8, 3), np.uint8)] * 2, tmp_path / "f.mp4", fps=4)
    good = film.read_bytes()
    cancel = CancelToken()
    children: list[psutil.Process] = []
    real = video._frames

    def frames(items):
        for k, frame in enumerate(real(items)):
            if k == 3:  # three frames are with ffmpeg: it is running
                children.extend(c for c in psutil.Process().children() if "ffmpeg" in c.name())
                cancel.cancel()
            yield frame

    monkeypatch.setattr(video, "_frames", frames)
    with pytest.raises(RenderCancelled):
        encode_film([np.full((64, 64, 3), k, np.uint8) for k in range(50)], film, fps=4,
                    cancel=cancel)
    assert len(children) == 1
    assert not children[0].is_running() or children[0].status() == psutil.STATUS_ZOMBIE
    assert film.read_bytes() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.mp4"]


def test_frames_folder_that_is_a_file_and_odd_outputs_are_one_line(tmp_path, monkeypatch):
    scene = _scene(tmp_path)
    (tmp_path / "f_frames").write_text("mine")
    one_line(run_main("animate", scene, "-o", "f.mp4", cwd=tmp_path), 2,
             "f_frames: is a file, not a folder for the frames")
    assert (tmp_path / "f_frames").read_text() == "mine"
    (tmp_path / "plain").write_text("mine")
    one_line(run_main("animate", scene, "-o", "plain", cwd=tmp_path), 2,
             "plain: is a file, not a folder")
    (tmp_path / "sheet_cells").write_text("mine")
    one_line(run_main("sweep", scene, "-o", "sheet.png", "--set",
                      "objects[ball].radius=0.3,0.4", cwd=tmp_path), 2,
             "sheet_cells: is a file, not a folder")
    one_line(run_main("animate", scene, "-o", "missing/f.mp4", cwd=tmp_path), 2,
             "does not exist")


@pytest.mark.skipif(shutil.which("setpriv") is None or os.name != "posix",
                    reason="needs setpriv to drop root's right to write anywhere")
@pytest.mark.parametrize("command", ["animate", "sweep"])
def test_read_only_output_folder_is_one_line(tmp_path, command):
    scene = _scene(tmp_path)
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    extra = ["--set", "objects[ball].radius=0.3,0.4"] if command == "sweep" else []
    name = "locked/f.mp4" if command == "animate" else "locked/s.png"
    try:
        cmd = [sys.executable, "-m", "whitted", command, str(scene), "-o", name, *extra]
        if os.geteuid() == 0:
            cmd = ["setpriv", "--bounding-set", "-dac_override,-dac_read_search,-fowner", *cmd]
        result = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=120)
        one_line((result.returncode, result.stdout, result.stderr), 2, "locked")
        assert list(locked.iterdir()) == []
    finally:
        locked.chmod(0o755)


# -----------------------------------------------------------------


def test_the_frame_record_covers_a_models_mtl_and_its_textures(tmp_path):
    (tmp_path / "box.obj").write_text(
        "mtllib box.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "usemtl paint\nf 1/1 2/2 3/3\n")
    (tmp_path / "box.mtl").write_text("newmtl paint\nKd 0.8 0.1 0.1\nmap_Kd wood.png\n")
    PILImage.fromarray(np.full((4, 4, 3), 90, np.uint8)).save(tmp_path / "wood.png")
    scene_path = tmp_path / "s.toml"
    scene_path.write_text('[[objects]]\ntype = "mesh"\nfile = "box.obj"\n'
                          '[[lights]]\ntype = "point"\nposition = [0, 3, 3]\n')

    def digest() -> str:
        from whitted.assets.mesh import clear_mesh_cache

        clear_mesh_cache()
        return frame_digest(load_scene(scene_path), 0)

    first = digest()
    assert digest() == first
    mtl = tmp_path / "box.mtl"
    mtl.write_text(mtl.read_text().replace("0.8", "0.7"))
    second = digest()
    assert second != first  # the MTL file changed
    PILImage.fromarray(np.full((4, 4, 3), 30, np.uint8)).save(tmp_path / "wood.png")
    os.utime(tmp_path / "wood.png", ns=(1, 1))
    assert digest() != second  # the texture the MTL names changed


# -----------------------------------------------------------------


@pytest.mark.parametrize(("args", "needle"), [
    (["-W", "0"], "--width: "),
    (["-H", "-3"], "--height: "),
    (["--fps", "0"], "--fps: must be 0.01"),
    (["--fps", "nan"], "--fps: must be 0.01"),
    (["--gif", "x.gif", "--fps", "60"], "--fps: must be 0.01 .. 50"),
    (["--gif", "x.avi"], "--gif: x.avi: unsupported film format"),
])
def test_stefan_film_options_checked_before_the_solve(tmp_path, monkeypatch, args, needle):
    case = tmp_path / "case.toml"
    case.write_text("[grid]\ncells = 8\n")
    one_line(run_main("stefan", "film", case, "-o", "melt.mp4", *args,
                      cwd=tmp_path), 2, needle)
    assert not (tmp_path / "melt_stefan").exists()  # nothing solved


# ----------------------------------------------------------------- signals


def _signal_after_frames(monkeypatch, signum: int, count: int) -> None:
    """Send ``signum`` to this process once ``count`` frames (or cells) are written: from
    the work itself, no sleeping."""
    from whitted.animation import frames as frames_module

    real = frames_module.FrameRenderer.render
    calls: list[int] = []

    def render(self, still, frame, path, **kwargs):
        result = real(self, still, frame, path, **kwargs)
        calls.append(frame)
        if len(calls) == count:
            os.kill(os.getpid(), signum)
        return result

    monkeypatch.setattr(frames_module.FrameRenderer, "render", render)


@pytest.mark.parametrize(("signum", "status", "word"), [
    (signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_animate_signal_keeps_finished_frames_and_the_old_film(tmp_path, monkeypatch, signum,
                                                               status, word):
    scene = _scene(tmp_path, frames=5)
    film = tmp_path / "f.mp4"
    film.write_bytes(b"the old film")
    _signal_after_frames(monkeypatch, signum, 2)
    line = one_line(run_main("animate", scene, "-o", "f.mp4", "-t", "1",
                             cwd=tmp_path), status, f"{word}: 2 of 5 frames finished",
                    "run the same command again")
    assert "f_frames" in line
    assert sorted(p.name for p in (tmp_path / "f_frames").iterdir()) == ["0000.png", "0001.png"]
    assert film.read_bytes() == b"the old film"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.mp4", "f_frames", "film.toml"]
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the guard is gone


@pytest.mark.parametrize(("signum", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_animate_signal_during_the_encode_stops_ffmpeg(tmp_path, monkeypatch, signum, status):
    scene = _scene(tmp_path, frames=6)
    film = tmp_path / "f.mp4"
    film.write_bytes(b"the old film")
    seen: list[psutil.Process] = []
    real = video._frames

    def frames(items):
        for k, frame in enumerate(real(items)):
            if k == 2:  # ffmpeg has two frames: stop now
                seen.extend(c for c in psutil.Process().children() if "ffmpeg" in c.name())
                os.kill(os.getpid(), signum)
            yield frame

    monkeypatch.setattr(video, "_frames", frames)
    one_line(run_main("animate", scene, "-o", "f.mp4", "-t", "1", cwd=tmp_path),
             status, "every frame is in", "the film was not encoded")
    assert len(seen) == 1
    assert not seen[0].is_running() or seen[0].status() == psutil.STATUS_ZOMBIE
    assert film.read_bytes() == b"the old film"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.mp4", "f_frames", "film.toml"]
    assert len(list((tmp_path / "f_frames").iterdir())) == 6


@pytest.mark.parametrize(("signum", "status", "word"), [
    (signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_sweep_signal_keeps_finished_cells(tmp_path, monkeypatch, signum, status, word):
    scene = _scene(tmp_path)
    _signal_after_frames(monkeypatch, signum, 1)
    one_line(run_main("sweep", scene, "-o", "s.png", "--set",
                      "objects[ball].radius=0.2,0.3,0.4", "-q", cwd=tmp_path), status,
             f"{word}: 1 of 3 images finished")
    assert sorted(p.name for p in (tmp_path / "s_cells").iterdir()) == ["0.png"]
    assert not (tmp_path / "s.png").exists()


def test_stefan_run_sigterm_keeps_saved_times_and_exits_143(tmp_path, monkeypatch):
    from whitted.stefan import run as stefan_run

    case = tmp_path / "case.toml"
    case.write_text("[grid]\ncells = 12\n[time]\nend = 1200.0\nsave_every = 300.0\n")
    real = stefan_run.run_case

    def run_case(*args, should_stop=None, **kwargs):
        def stop() -> bool:  # SIGTERM as the solver first asks whether to stop
            if not stopped:
                stopped.append(True)
                os.kill(os.getpid(), signal.SIGTERM)
            return should_stop()

        return real(*args, should_stop=stop, **kwargs)

    stopped: list[bool] = []
    monkeypatch.setattr(stefan_run, "run_case", run_case)
    one_line(run_main("stefan", "run", case, "-o", "out", "-q", cwd=tmp_path),
             143, "terminated: at t = ", "run the same command again")
    assert (tmp_path / "out" / "case.toml").exists()
    assert not [p for p in (tmp_path / "out").rglob("*") if "tmp" in p.name]


def test_prepare_film_writes_nothing(tmp_path):
    scene = load_scene(_scene(tmp_path))
    plan = prepare_film(scene, tmp_path / "f.gif", frames=[1, 2])
    assert plan.files == [tmp_path / "f_frames" / "0001.png", tmp_path / "f_frames" / "0002.png"]
    assert plan.fps == 8.0 and plan.count == 4
    assert not (tmp_path / "f_frames").exists() and not (tmp_path / "f.gif").exists()
    with pytest.raises(SceneError, match="frame 7 is outside"):
        prepare_film(scene, tmp_path / "f.gif", frames=[7])
    assert film_api.film_fps(scene) == 8.0


def test_the_editors_film_job_runs_the_film_api_and_stops(tmp_path):
    from whitted.gui.film_job import FilmJob

    scene = load_scene(_scene(tmp_path, frames=3))
    job = FilmJob(scene, tmp_path / "f.gif", threads=1)
    job.start()
    job.join(120)
    assert job.finished and job.error is None and not job.stopped
    assert (job.done, job.rendered, job.kept, job.total) == (3, 3, 0, 3)
    assert job.fraction == 1.0 and job.frames_dir == tmp_path / "f_frames"
    with PILImage.open(tmp_path / "f.gif") as im:
        assert im.n_frames == 3
    again = FilmJob(scene, tmp_path / "f.gif", threads=1)
    again.start()
    again.join(120)
    assert (again.done, again.rendered, again.kept) == (3, 0, 3)
    stopped = FilmJob(scene, tmp_path / "g.gif", threads=1)
    stopped.cancel.cancel()  # stopped before its first frame
    stopped.start()
    stopped.join(120)
    assert stopped.finished and stopped.stopped and stopped.done == 0
    assert not (tmp_path / "g.gif").exists()
    with pytest.raises(ValueError, match="a film is .mp4 or .gif"):
        FilmJob(scene, tmp_path / "folder").start()
    (tmp_path / "h_frames").mkdir()
    (tmp_path / "h_frames" / "0000.png").write_bytes(b"mine")
    with pytest.raises(OutputError, match="whitted did not write it"):
        FilmJob(scene, tmp_path / "h.gif").start()


# ----------------------------------------------------------------- the guard itself


def test_the_guard_handles_sigint_and_sigterm_alike(capsys):
    import typer

    from whitted.cli.interrupt import InterruptGuard

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    cancelled = []
    with InterruptGuard() as guard:
        guard.on_interrupt(lambda: cancelled.append(True))
        assert not guard.interrupted
        os.kill(os.getpid(), signal.SIGTERM)  # handled between two bytecodes of this thread
        assert guard.interrupted and guard.terminated and cancelled == [True]
        assert guard.exit_code == 143 and guard.word == "terminated"
        with pytest.raises(KeyboardInterrupt):  # the second one stops at once
            os.kill(os.getpid(), signal.SIGINT)
        late = []
        guard.on_interrupt(lambda: late.append(True))  # registered after: called at once
        assert late == [True]
        exit_ = guard.exit("kept  3 of 5\nframes")
    assert isinstance(exit_, typer.Exit) and exit_.exit_code == 143
    assert capsys.readouterr().err == "terminated: kept 3 of 5 frames\n"
    assert {s: signal.getsignal(s) for s in before} == before  # restored
    with pytest.raises(KeyboardInterrupt), InterruptGuard(at_once=True) as guard:
        os.kill(os.getpid(), signal.SIGINT)
    assert guard.exit_code == 130 and guard.word == "interrupted"


# ----------------------------------------------------------------- fuzzing the new inputs


@given(st.text(max_size=30), st.integers(1, 20_000))
def test_frame_ranges_are_in_the_film_or_one_line(text, count):
    try:
        frames = parse_frame_range(text, count)
    except SceneError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("--frames: ")
        return
    assert len(frames) >= 1 and 0 <= frames[0] <= frames[-1] < count


@given(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10, 10**400),
                 st.text(max_size=8), st.none()),
       st.sampled_from(["mp4", "gif"]))
def test_fps_is_a_rate_the_format_takes_or_one_line(fps, fmt):
    try:
        rate = video.check_fps(fps, fmt)
    except ValueError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("must be")
        return
    assert video.FPS_MIN <= rate <= video.FPS_MAX[fmt]
    if fmt == "gif":  # the delay fits a GIF's 16 bits of hundredths of a second
        assert 2 <= round(100 / rate) <= 65_535


def test_stefan_run_refuses_to_write_over_its_case_file(tmp_path, monkeypatch):
    project = tmp_path / "proj"
    project.mkdir()
    case = project / "case.toml"
    case.write_text("[grid]\ncells = 12\n")
    os.utime(case, ns=(1, 1))
    one_line(run_main("stefan", "run", case, "-o", project, cwd=tmp_path), 2,
             "case.toml: is an input of this job")
    assert case.stat().st_mtime_ns == 1 and sorted(project.iterdir()) == [case]
