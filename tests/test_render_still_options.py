"""POV-Ray users' habits on ``whitted render``: ``--region``, ``--alpha``, TIFF / WebP /
JPEG ``--quality``, ``--exposure`` and ``--continue`` (an interrupted still finished from the
tiles it kept, byte for byte the uninterrupted picture)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image as PILImage

from cli_run import one_line_error, run_main
from whitted.cli import render as render_cli
from whitted.cli.region import parse_region
from whitted.cli.tile_state import load_state, state_path
from whitted.render.api import RenderJob
from whitted.render.coverage import render_coverage, straight_colour
from whitted.scene import load_scene

# a grey sphere on a blue background, seen straight on: its outline crosses pixels
BALL = """[render]
width = 16
height = 12
samples = 16
transfer = "linear"

[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 30

[background]
color = [0.0, 0.0, 0.5]

[[lights]]
type = "ambient"
intensity = 1.0

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1.0
material = { color = [0.6, 0.6, 0.6], ka = 1.0, kd = 0.0 }
"""


@pytest.fixture
def ball(tmp_path):
    (tmp_path / "ball.toml").write_text(BALL, encoding="utf-8")
    return tmp_path / "ball.toml"


def test_region_parsing():
    assert parse_region("0:320,0:240", 640, 480) == (0, 0, 320, 240)
    assert parse_region("0.25:0.75,0:0.5", 640, 480) == (160, 0, 480, 240)
    assert parse_region(":,10:", 64, 48) == (0, 10, 64, 48)
    for bad, words in [("0:0,0:10", "holds no pixels"), ("5:2,0:10", "holds no pixels"),
                       ("0:65,0:10", "outside the image"), ("0:1.5,0:1", "not between 0"),
                       ("nan:1.0,0:1", "not a finite"), ("a:b,0:1", "not a number"),
                       ("0:10", "expected X0:X1,Y0:Y1"), ("0:1:2,0:1", "expected x0:x1")]:
        with pytest.raises(ValueError, match=words):
            parse_region(bad, 64, 48)


def test_a_region_renders_the_same_pixels_into_a_black_full_size_image(ball):
    scene = load_scene(ball)
    full = RenderJob(scene, threads=1).run().pixels
    part = RenderJob(scene, threads=2, region=(3, 2, 13, 9)).run().pixels
    assert part.shape == full.shape
    assert np.array_equal(part[2:9, 3:13], full[2:9, 3:13])
    outside = np.ones(full.shape[:2], bool)
    outside[2:9, 3:13] = False
    assert not part[outside].any()


def test_region_on_the_command_line(tmp_path, ball):
    code, _, err = run_main("render", ball, "-q", "--region", "0:0.5,0:6", "-o", "r.npy",
                            cwd=tmp_path)
    assert code == 0, err
    r = np.load(tmp_path / "r.npy")
    assert r[:6, :8].any() and not r[6:].any() and not r[:, 8:].any()
    one_line_error(run_main("render", ball, "--region", "0:99,0:5", "-o", "x.png",
                            cwd=tmp_path), "--region: x = 99 is outside the image")
    assert not (tmp_path / "x.png").exists()


def test_alpha_is_the_coverage_and_the_colour_is_taken_apart_from_the_background(ball):
    scene = load_scene(ball)
    picture = RenderJob(scene).run().pixels
    alpha, background = render_coverage(scene)
    assert alpha[0, 0] == 0.0 and alpha[6, 8] == 1.0  # a corner misses, the middle hits
    edge = (alpha > 0.0) & (alpha < 1.0)
    assert edge.sum() >= 8  # the outline's pixels are partly covered
    assert np.allclose(background, [0.0, 0.0, 0.5])
    straight = straight_colour(picture, alpha, background)
    # the ball is grey (0.6) all over, its outline too, once the blue is taken out
    assert np.allclose(straight[alpha > 0], 0.6, atol=1e-5)
    assert not straight[alpha == 0].any()
    # the picture is the mix: C = a F + (1 - a) B
    mix = alpha[..., None] * straight + (1 - alpha[..., None]) * background
    assert np.allclose(mix, picture, atol=1e-5)


def test_alpha_files(tmp_path, ball):
    assert run_main("render", ball, "-q", "--alpha", "-o", "a.png", cwd=tmp_path)[0] == 0
    png = np.asarray(PILImage.open(tmp_path / "a.png"))
    assert png.shape == (12, 16, 4) and png[0, 0, 3] == 0 and png[6, 8, 3] == 255
    assert png[6, 8, 0] == round(0.6 * 255)  # linear transfer: 0.6 -> 153
    assert run_main("render", ball, "-q", "--alpha", "-o", "a.npy", cwd=tmp_path)[0] == 0
    rgba = np.load(tmp_path / "a.npy")  # premultiplied
    a = rgba[..., 3]
    assert np.allclose(rgba[..., :3][a > 0] / a[a > 0][:, None], 0.6, atol=1e-5)
    code, _, err = run_main("render", ball, "-q", "--alpha", "-o", "a.exr", cwd=tmp_path)
    assert code == 0, err
    import OpenEXR

    channels = OpenEXR.File(str(tmp_path / "a.exr"), separate_channels=True).channels()
    assert set(channels) >= {"R", "G", "B", "A"}
    assert np.allclose(np.asarray(channels["A"].pixels), a)
    one_line_error(run_main("render", ball, "--alpha", "-o", "a.jpg", cwd=tmp_path),
                   "a.jpg: JPEG has no alpha channel")


def test_tiff_webp_and_jpeg_quality(tmp_path, ball):
    for name in ("p.png", "t.tif", "w.webp"):
        assert run_main("render", ball, "-q", "-o", name, cwd=tmp_path)[0] == 0
    png = np.asarray(PILImage.open(tmp_path / "p.png"))
    assert np.array_equal(np.asarray(PILImage.open(tmp_path / "t.tif")), png)
    assert np.array_equal(np.asarray(PILImage.open(tmp_path / "w.webp")), png)  # lossless
    run_main("render", ball, "-q", "-W", "160", "-H", "120", "-o", "lo.jpg", "--quality", "20",
             cwd=tmp_path)
    run_main("render", ball, "-q", "-W", "160", "-H", "120", "-o", "hi.jpg", cwd=tmp_path)
    assert (tmp_path / "lo.jpg").stat().st_size < (tmp_path / "hi.jpg").stat().st_size
    one_line_error(run_main("render", ball, "--quality", "50", "-o", "x.png", cwd=tmp_path),
                   "--quality: a quality is for .jpg and .webp")
    for bad in ("0", "101"):
        one_line_error(run_main("render", ball, "--quality", bad, "-o", "x.jpg",
                                cwd=tmp_path), "--quality: quality must be a whole number")


def test_exposure_scales_the_picture_by_two_to_the_ev(tmp_path, ball):
    run_main("render", ball, "-q", "-o", "e0.npy", cwd=tmp_path)
    run_main("render", ball, "-q", "-o", "e1.npy", "--exposure", "1", cwd=tmp_path)
    run_main("render", ball, "-q", "-o", "em2.npy", "--exposure", "-2", cwd=tmp_path)
    base = np.load(tmp_path / "e0.npy")
    assert np.array_equal(np.load(tmp_path / "e1.npy"), base * 2)
    assert np.array_equal(np.load(tmp_path / "em2.npy"), base / 4)
    for bad in ("nan", "inf", "1e300"):
        one_line_error(run_main("render", ball, "--exposure", bad, "-o", "x.png",
                                cwd=tmp_path), "--exposure:")


def _interrupt_after_first_tile(monkeypatch):
    """The render stops after its first run of tiles, as after Ctrl-C."""
    def run(job, quiet, interrupted):
        def progress(_p):
            interrupted.set()
            job.cancel()

        job.progress = progress
        job.start()
        job.wait()

    monkeypatch.setattr(render_cli, "_run_with_progress", run)


def test_continue_finishes_an_interrupted_render_byte_for_byte(tmp_path, ball, monkeypatch):
    args = ("render", ball, "-q", "-t", "1", "-W", "64", "-H", "48", "-s", "2")
    assert run_main(*args, "-o", "whole.png", cwd=tmp_path)[0] == 0
    with monkeypatch.context() as m:
        _interrupt_after_first_tile(m)
        code, _, err = run_main(*args, "-o", "cut.png", cwd=tmp_path)
    assert code == 130, err
    assert "--continue finishes it" in err
    state = load_state(state_path(tmp_path / "cut.png"), 1 << 24)
    assert 0 < state.finished.sum() < len(state.finished) == 12
    code, _, err = run_main(*args, "-o", "cut.png", "--continue", cwd=tmp_path)
    assert code == 0, err
    assert (tmp_path / "cut.png").read_bytes() == (tmp_path / "whole.png").read_bytes()
    assert not state_path(tmp_path / "cut.png").exists()  # removed once whole


def test_continue_with_a_damaged_or_foreign_state(tmp_path, ball, monkeypatch):
    args = ("render", ball, "-q", "-t", "1", "-W", "64", "-H", "48")
    kept = state_path(tmp_path / "cut.png")
    with monkeypatch.context() as m:
        _interrupt_after_first_tile(m)
        assert run_main(*args, "-o", "cut.png", cwd=tmp_path)[0] == 130
    good = kept.read_bytes()
    # another scene (here another size) cannot continue from these tiles
    one_line_error(run_main(*args, "-W", "32", "-o", "cut.png", "--continue", cwd=tmp_path),
                   "holds tiles of another scene, settings or region")
    for damaged in (good[: len(good) // 2], b"", good[:100] + b"x" * 50 + good[150:]):
        kept.write_bytes(damaged)
        one_line_error(run_main(*args, "-o", "cut.png", "--continue", cwd=tmp_path),
                       f"--continue: {kept.name}", "render without --continue")
    # without --continue the picture is rendered whole and the stale state is removed
    assert run_main(*args, "-o", "cut.png", cwd=tmp_path)[0] == 0
    assert not kept.exists()
    # --continue with nothing kept: the whole picture, and a note
    code, _, err = run_main(*args, "-o", "new.png", "--continue", cwd=tmp_path)
    assert code == 0 and "no kept tiles" in err


def test_a_file_of_someone_elses_by_the_state_files_name_is_never_touched(tmp_path, ball,
                                                                           monkeypatch):
    args = ("render", ball, "-q", "-t", "1", "-W", "64", "-H", "48")
    theirs = state_path(tmp_path / "cut.png")
    theirs.write_text("my notes\n", encoding="utf-8")
    with monkeypatch.context() as m:
        _interrupt_after_first_tile(m)
        code, _, err = run_main(*args, "-o", "cut.png", cwd=tmp_path)
    assert code == 130 and "is not whitted's" in err
    assert theirs.read_text(encoding="utf-8") == "my notes\n"
    assert run_main(*args, "-o", "cut.png", cwd=tmp_path)[0] == 0  # whole: not removed
    assert theirs.read_text(encoding="utf-8") == "my notes\n"


@given(text=st.text(alphabet="0123456789.:,-e naif", max_size=16),
       width=st.integers(1, 5000), height=st.integers(1, 5000))
def test_fuzz_region(text, width, height):
    """Any text: a region inside the image, or one ValueError sentence."""
    try:
        x0, y0, x1, y1 = parse_region(text, width, height)
    except ValueError as exc:
        assert str(exc) and "\n" not in str(exc)
        return
    assert 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height
