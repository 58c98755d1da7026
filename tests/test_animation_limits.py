"""The animation, sweep and file-reading limits that keep a
hostile but fair input from running away, and one clean line for every mistake."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from cli_run import one_line_error, run_main
from test_reliability import SCENE

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GiB = 1 << 30


# ----------------------------------------------------------- item 10: an address-space limit


def run_limited(args: list[str], cwd: Path, address_space: int = 2 * GiB
                ) -> subprocess.CompletedProcess:
    """``whitted ARGS`` in a child process whose address space is limited (as ``ulimit -v``)."""
    return run_limited_many([args], cwd, address_space)


def run_limited_many(commands: list[list[str]], cwd: Path, address_space: int = 2 * GiB
                     ) -> subprocess.CompletedProcess:
    """Several ``whitted`` commands, one after the other, in one child process whose address
    space is limited; it prints ``status: N`` after each and stops at the first failure."""
    code = textwrap.dedent(f"""
        import resource, runpy, sys
        resource.setrlimit(resource.RLIMIT_AS, ({address_space}, {address_space}))
        for args in {commands!r}:
            sys.argv = ["whitted", *args]
            try:
                runpy.run_module("whitted", run_name="__main__", alter_sys=True)
                status = 0
            except SystemExit as exc:
                status = exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1
            print(f"status: {{status}}", flush=True)
            if status:
                sys.exit(status)
    """)
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True,
                          text=True, timeout=300, env=os.environ.copy())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
def test_every_example_reads_under_a_2_gb_address_space(tmp_path: Path):
    """The OBJ reader used to ask for 8 GiB + 1 bytes up front: every scene with a model
    failed with "out of memory" under ``ulimit -v 4000000``."""
    scenes = sorted(EXAMPLES.glob("*.toml"))
    commands = [["info", str(scene)] for scene in scenes]
    # and a render of a scene with an OBJ model and its MTL file (the teapot)
    commands.append(["render", str(EXAMPLES / "teapot_glass.toml"), "-W", "8", "-H", "6",
                     "-q", "-o", "t.png"])
    result = run_limited_many(commands, tmp_path)
    assert result.returncode == 0, result.stderr
    # (a render may end its process at once, without the last status line)
    assert result.stdout.count("status: 0") >= len(scenes)
    assert result.stdout.count("bvh:") == len(scenes)
    assert (tmp_path / "t.png").stat().st_size > 0


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
def test_a_file_too_big_for_the_address_space_is_one_clear_line(tmp_path: Path):
    big = tmp_path / "big.obj"
    with big.open("wb") as f:  # 3 GiB, sparse: a valid start, then holes
        f.write(b"v 0 0 0\n" * 10_000)  # more than the head the reader checks
        f.truncate(3 * GiB)
    result = run_limited(["info", "big.obj"], tmp_path)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0] == ("error: big.obj: OBJ file too large for the memory this process may "
                        "use: 3.0 GiB could not be read (a memory or address-space limit such "
                        "as ulimit -v)")


def test_reading_a_small_file_asks_for_its_size_not_the_limit(tmp_path: Path, monkeypatch):
    """The read is sized by the file (plus one byte to notice growth), never by the limit."""
    from whitted.files import reading as files

    path = tmp_path / "a.mtl"
    path.write_bytes(b"newmtl a\nKd 1 0 0\n")
    asked: list[int] = []
    real_fdopen = os.fdopen

    class Spy:
        def __init__(self, f):
            self.f = f

        def read(self, n=-1):
            asked.append(n)
            return self.f.read(n)

        def fileno(self):
            return self.f.fileno()

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

    monkeypatch.setattr(files.os, "fdopen", lambda *a, **k: Spy(real_fdopen(*a, **k)))
    assert files.read_limited(path, 8 * GiB) == b"newmtl a\nKd 1 0 0\n"
    assert asked == [19]
    with pytest.raises(files.SceneError, match=r"too large: 18 bytes \(the limit is 10 bytes\)"):
        files.read_limited(path, 10)


# ------------------------------------------------------------------- item 9: long films

FILM = SCENE.replace('type = "sphere"', 'type = "sphere"\nname = "ball"') + """
[animation]
frames = 1000000

[[animation.tracks]]
path = "objects[ball].radius"
interpolation = "spline"
keys = [[0, 0.5], [999999, 1.5]]

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 0, 5]], [999999, [0, 1, 6]]]
"""


class TooManyChecks(Exception):
    """Not a ValueError: pydantic would turn that into a validation error."""


def count_checks(monkeypatch, limit: int) -> list[int]:
    from whitted.scene import timeline

    calls = [0]
    real = timeline.set_value

    def counting(*args, **kwargs):
        calls[0] += 1
        if calls[0] > limit:
            raise TooManyChecks(f"more than {limit} values checked")
        return real(*args, **kwargs)

    monkeypatch.setattr(timeline, "set_value", counting)
    return calls


def test_a_million_frame_film_is_checked_by_its_keys_not_frame_by_frame(tmp_path, monkeypatch):
    """`render --frame 500000` of a 1,000,000-frame film validated every frame first (265 s)."""
    import whitted

    path = tmp_path / "film.toml"
    path.write_text(FILM)
    calls = count_checks(monkeypatch, 5000)
    scene = whitted.load_scene(path)
    assert 0 < calls[0] <= 5000
    still = scene.at_frame(500000)
    s = 500000 / 999999
    assert still.camera.position == pytest.approx((0, s, 5 + s))
    # a spline through two keys has the slope of the line: it is the line
    assert still.objects[0].radius == pytest.approx(0.5 + s)
    code, out, err = run_main("render", "film.toml", "--frame", "500000", "-q", "-o", "f.png",
                              cwd=tmp_path)
    assert code == 0, err
    assert (tmp_path / "f.png").stat().st_size > 0


def test_a_spline_overshooting_in_a_million_frame_film_is_still_found(tmp_path, monkeypatch):
    """Checking by keys still finds where a spline leaves what the value accepts: it tries
    the frames where the spline turns."""
    film = FILM.replace('path = "objects[ball].radius"', 'path = "objects[ball].material.kt"')
    film = film.replace("keys = [[0, 0.5], [999999, 1.5]]",
                        "keys = [[0, 0.1], [500000, 1.0], [999999, 0.0]]")
    (tmp_path / "film.toml").write_text(film)
    count_checks(monkeypatch, 5000)
    line = one_line_error(run_main("info", "film.toml", cwd=tmp_path))
    # the cubic before the middle key turns (and peaks above 1) at frame 488281.25
    assert line.startswith("error: film.toml:")
    assert ("animation.tracks[0]: at frame 488281 the spline between keys gives "
            "objects[ball].material.kt: input should be less than or equal to 1") in line


def test_the_frames_tried_include_each_splines_turning_points():
    import numpy as np

    from whitted.scene.interpolate import interpolate_scalar, spline_extremes

    times, values = [0.0, 10.0, 30.0, 31.0, 40.0], [0.0, 1.0, 0.2, 5.0, -1.0]
    found = spline_extremes(times, values)
    # the same turning points by brute force: where the sampled curve changes direction
    t = np.linspace(0, 40, 80_001)[1:-1]
    y = np.array([interpolate_scalar(times, values, x, "spline") for x in t])
    dy = np.diff(y)
    turns = t[1:-1][np.sign(dy[1:]) * np.sign(dy[:-1]) < 0]
    turns = [x for x in turns if min(abs(x - k) for k in times) > 1e-3]  # not at a key
    assert len(found) == len(turns) >= 3
    np.testing.assert_allclose(sorted(found), turns, atol=1e-3)


# -------------------------------------------------------- item 7: sequence pattern widths


def sequence_scene(pattern: str) -> str:
    return SCENE + f"""
[[objects]]
type = "mesh"
file = "{pattern}"

[animation]
frames = 2
"""


@pytest.mark.parametrize(("pattern", "problem"), [
    ("ice_{frame:>300000000}.obj", "the width 300000000 is more than 32 characters"),
    ("ice_{frame:0999999999999d}.obj", "the width 999999999999 is more than 32 characters"),
    ("ice_{frame:.99999999999999999999f}.obj",
     "the precision 99999999999999999999 is more than 32 characters"),
    ("ice_{frame:x<40}.obj", "the width 40 is more than 32 characters"),
    ("ice_{frame:{x}}.obj", "{frame:{x}} is not a number format (use for example {frame:04d})"),
    ("ice_{frame!r}.obj", "{frame!r} is not a number format (use for example {frame:04d})"),
    ("ice_{frame:c}.obj", "{frame:c} is not a number format (use for example {frame:04d})"),
])
def test_sequence_patterns_are_bounded_and_named(tmp_path: Path, pattern: str, problem: str):
    """`{frame:>300000000}` used 11.7 GB for `whitted info`."""
    (tmp_path / "s.toml").write_text(sequence_scene(pattern))
    line = one_line_error(run_main("info", "s.toml", cwd=tmp_path))
    line_no = sequence_scene(pattern).splitlines().index(f'file = "{pattern}"') + 1
    assert line == (f"error: s.toml:{line_no}: objects[1].file: file pattern {pattern!r}: "
                    f"{problem}")


def test_a_sequence_pattern_of_the_widest_allowed_format_works(tmp_path: Path):
    from whitted.scene.timeline import MAX_FORMAT_WIDTH, sequence_file

    for k in range(2):
        (tmp_path / f"ice_{k:032d}.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "s.toml").write_text(sequence_scene("ice_{frame:032d}.obj"))
    code, out, err = run_main("info", "s.toml", cwd=tmp_path)
    assert code == 0, err
    assert MAX_FORMAT_WIDTH == 32
    assert sequence_file("a_{frame:>32}", 7) == "a_" + " " * 31 + "7"


# ------------------------------------------------------- items 6 and 8: sweeps


def test_a_sweep_is_counted_before_any_cell_is_made(tmp_path: Path, monkeypatch):
    """Two 10,000-value axes built 10^8 scenes before rendering one."""
    import whitted
    from whitted.animation import sweep as sweep_module

    (tmp_path / "s.toml").write_text(SCENE)
    made = [0]
    real = sweep_module.apply_overrides

    def counting(*args, **kwargs):
        made[0] += 1
        if made[0] > 1000:  # main made all 10^8 (never finishing): fail fast instead
            raise TooManyChecks("more than 1000 scenes made")
        return real(*args, **kwargs)

    monkeypatch.setattr(sweep_module, "apply_overrides", counting)
    line = one_line_error(run_main("sweep", "s.toml", "--set", "render.width=8:10007",
                                   "--set", "render.height=6:10005", "-o", "x.png",
                                   cwd=tmp_path))
    assert line == ("error: --set: the sweep has 10000 x 10000 = 100000000 cells "
                    "(at most 10000)")
    assert made[0] == 0 and not (tmp_path / "x_cells").exists()
    # a sweep within the limit makes one scene per axis value up front, not one per cell
    scene = whitted.load_scene(tmp_path / "s.toml")
    cells = sweep_module.sweep_cells(scene, [("render.samples", list(range(1, 101))),
                                             ("render.max_depth", list(range(1, 51)))])
    assert len(cells) == 5000 == sweep_module.MAX_CELLS // 2
    assert made[0] == 150
    assert cells[4321].scene.render.samples == 4321 % 100 + 1
    assert cells[4321].scene.render.max_depth == 4321 // 100 + 1
    assert cells[-1].label == "samples = 100, max_depth = 50"
    with pytest.raises(IndexError):
        cells[5000]


def test_a_sheet_too_big_is_refused_before_rendering(tmp_path: Path, monkeypatch):
    from whitted.animation.frames import FrameRenderer

    def no_render(*args, **kwargs):
        raise TooManyChecks("a cell was rendered")

    monkeypatch.setattr(FrameRenderer, "render", no_render)
    (tmp_path / "s.toml").write_text(SCENE)
    line = one_line_error(run_main("sweep", "s.toml", "--set", "render.width=8000:8002",
                                   "--set", "render.height=6000:6010", "-o", "x.png",
                                   cwd=tmp_path))
    assert line.startswith("error: --set: the contact sheet would be about ")
    assert line.endswith("pixels, over 100 megapixels: sweep fewer values or make the cells "
                         "smaller (--width, --height)")
    assert not (tmp_path / "x_cells").exists()


def test_cells_of_different_sizes_get_a_layout_that_fits_them(tmp_path: Path):
    """`sweep --set render.width=8:16:8` pasted a bigger cell over the first cell's layout."""
    import numpy as np
    from PIL import Image as PILImage

    (tmp_path / "s.toml").write_text(SCENE)
    code, out, err = run_main("sweep", "s.toml", "--set", "render.width=8:56:48",
                              "--set", "render.height=6:30:24", "--title", "", "-q",
                              "-o", "x.png", cwd=tmp_path)
    assert code == 0, err
    cells = [np.asarray(PILImage.open(tmp_path / "x_cells" / f"{k}.png").convert("RGB"))
             for k in range(4)]
    assert [c.shape[:2] for c in cells] == [(6, 8), (6, 56), (30, 8), (30, 56)]
    sheet = np.asarray(PILImage.open(tmp_path / "x.png").convert("RGB"))
    # every cell's picture appears whole, at one place, and no two places overlap
    places = []
    for cell in cells:
        h, w = cell.shape[:2]
        hits = [(y, x) for y in range(sheet.shape[0] - h + 1)
                for x in range(sheet.shape[1] - w + 1)
                if np.array_equal(sheet[y:y + h, x:x + w], cell)]
        assert hits, cell.shape
        places.append((hits[0], (h, w)))
    for i, ((y0, x0), (h0, w0)) in enumerate(places):
        for (y1, x1), (h1, w1) in places[i + 1:]:
            assert y0 + h0 <= y1 or y1 + h1 <= y0 or x0 + w0 <= x1 or x1 + w1 <= x0
    # the grid: columns 0 and 1 left to right, rows 0 and 1 top to bottom
    (a, _), (b, _), (c, _), (d, _) = places
    assert a[0] == b[0] < c[0] == d[0] and a[1] < b[1] and c[1] < d[1]


# -------------------------------------------------------------- item 15: the Python API


@pytest.mark.parametrize(("frame", "message"), [
    (None, "frame None is not a frame number (a whole number 0..9)"),
    (math.nan, "frame nan is not a whole number (the frames are 0..9)"),
    (math.inf, "frame inf is not a whole number (the frames are 0..9)"),
    (-math.inf, "frame -inf is not a whole number (the frames are 0..9)"),
    (2.5, "frame 2.5 is not a whole number (the frames are 0..9)"),
    ("3", "frame '3' is not a frame number (a whole number 0..9)"),
    (True, "frame True is not a frame number (a whole number 0..9)"),
    (10, "frame 10 is outside 0..9 (the scene has 10 frames)"),
    (-1, "frame -1 is outside 0..9 (the scene has 10 frames)"),
    (1e300, "is outside 0..9 (the scene has 10 frames)"),
    (10**400, "is outside 0..9 (the scene has 10 frames)"),
])
def test_at_frame_of_a_wrong_frame_is_a_whitted_error(tmp_path: Path, frame, message):
    import whitted
    from whitted.errors import SceneError, WhittedError

    path = tmp_path / "s.toml"
    path.write_text(SCENE + "\n[animation]\nframes = 10\n")
    scene = whitted.load_scene(path)
    with pytest.raises(WhittedError) as info:  # was TypeError, ValueError, OverflowError
        scene.at_frame(frame)
    from whitted.errors import FrameError

    assert isinstance(info.value, FrameError) and isinstance(info.value, SceneError | ValueError)
    text = str(info.value)
    assert text.endswith(message) and "\n" not in text and len(text) < 200
    assert scene.at_frame(3.0).render.seed == scene.at_frame(3).render.seed


@pytest.mark.parametrize(("path", "value", "message"), [
    (None, 1, "a path is text such as 'camera.position', got nothing (None)"),
    (3, 1, "a path is text such as 'camera.position', got a number"),
    (["camera"], 1, "a path is text such as 'camera.position', got a list of 1"),
    ("", 1, "empty path"),
    ("camera..position", 1, "cannot read path 'camera..position': a name is missing "
                            "before '.'"),
    ("x" * 5000, 1, "unknown key 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...(4924 more)..."),
    ("camera.position", object(), "camera.position: expected a list of 3 numbers"),
])
def test_get_value_and_set_value_raise_path_errors(tmp_path: Path, path, value, message):
    import whitted
    from whitted.animation import get_value, set_value
    from whitted.errors import SceneError, WhittedError

    (tmp_path / "s.toml").write_text(SCENE)
    scene = whitted.load_scene(tmp_path / "s.toml")
    calls = [lambda: set_value(scene, path, value)]
    if value == 1:  # a path that names nothing: reading it fails the same way
        calls.append(lambda: get_value(scene, path))
    for call in calls:
        with pytest.raises(WhittedError) as info:  # was a plain ValueError, or TypeError
            call()
        from whitted.errors import PathError

        assert isinstance(info.value, PathError) and isinstance(info.value, SceneError)
        assert isinstance(info.value, ValueError)  # as before: `except ValueError` still works
        assert message in str(info.value) and "\n" not in str(info.value)
        assert len(str(info.value)) < 400


# ------------------------------------------------------------------- item 16: --set


def test_set_a_path_whose_quoted_name_holds_brackets(tmp_path: Path):
    """`--set 'objects["a]b"].radius=0.2'` was refused though tracks accept that path."""
    import numpy as np
    from PIL import Image as PILImage

    scene = SCENE.replace('type = "sphere"', 'type = "sphere"\nname = "a]b=c"')
    (tmp_path / "s.toml").write_text(scene)
    for radius, name in (("0.6", "small.png"), ("1.0", "big.png")):
        code, out, err = run_main("render", "s.toml", "-q", "-o", name, "--set",
                                  f'objects["a]b=c"].radius={radius}', cwd=tmp_path)
        assert code == 0, err
    small, big = (np.asarray(PILImage.open(tmp_path / n)) for n in ("small.png", "big.png"))
    lit = [int((img.sum(axis=2) > 0).sum()) for img in (small, big)]
    assert 0 < lit[0] < lit[1]  # the smaller sphere covers fewer pixels
    plain = tmp_path / "plain.png"
    assert run_main("render", "s.toml", "-q", "-o", plain.name, cwd=tmp_path)[0] == 0
    assert np.array_equal(np.asarray(PILImage.open(plain)), big)  # radius 1 is the file's


@pytest.mark.parametrize(("text", "path", "value"), [
    ('objects["a]b"].radius=0.2', 'objects["a]b"].radius', "0.2"),
    ("objects['x=]'].r=2", "objects['x=]'].r", "2"),
    ('objects["[["].material.kt=0.5', 'objects["[["].material.kt', "0.5"),
    ("a.b=[1, 2]", "a.b", "[1, 2]"),
    ("lights[0].color=#ff0000", "lights[0].color", "#ff0000"),
])
def test_parse_assignment_respects_quotes_in_brackets(text: str, path: str, value: str):
    from whitted.animation.overrides import parse_assignment
    from whitted.scene.paths import parse_path

    assert parse_assignment(text) == (path, value)
    parse_path(path)  # and the path reader reads the same path


def test_a_one_value_range_sweeps_one_value(tmp_path: Path):
    """`kt=1:1:0.1` (a one-value range) was reported as "unable to parse a number"."""
    scene = SCENE.replace("radius = 1.0", "radius = 1.0\nmaterial = { kt = 0.5 }")
    (tmp_path / "s.toml").write_text(scene)
    code, out, err = run_main("sweep", "s.toml", "--set", "objects[0].material.kt=1:1:0.1",
                              "-o", "x.png", cwd=tmp_path)
    assert code == 0, err
    progress = [line for line in (out + err).splitlines() if line.startswith("kt = ")]
    assert len(progress) == 1 and progress[0].startswith("kt = 1 (1/1): ")
    assert sorted(p.name for p in (tmp_path / "x_cells").iterdir()) == ["0.png"]
    from whitted.animation.overrides import parse_values

    assert parse_values("1:1:0.1") == [1.0]
    assert parse_values("1:1") == [1]
    assert parse_values("9007199254740993:9007199254740995") == [
        9007199254740993, 9007199254740994, 9007199254740995]  # whole numbers stay exact
    assert parse_values("0:1e-12:2.5e-13") == [0.0, 2.5e-13, 5e-13, 7.5e-13, 1e-12]


def test_a_range_given_to_render_says_ranges_are_for_sweeps(tmp_path: Path):
    scene = SCENE.replace("radius = 1.0", "radius = 1.0\nmaterial = { kt = 0.5 }")
    (tmp_path / "s.toml").write_text(scene)
    line = one_line_error(run_main("render", "s.toml", "--set", "objects[0].material.kt=1:1:0.1",
                                   "-o", "x.png", cwd=tmp_path))
    assert line.startswith("error: --set: objects[0].material.kt: expected a number")
    assert line.endswith("(got '1:1:0.1'); a range START:STOP:STEP is for whitted sweep, "
                         "here give one value")
    # a text value that looks like a range is still text where text is wanted
    code, out, err = run_main("render", "s.toml", "--set", "objects[0].name=1:2", "-q",
                              "-o", "y.png", cwd=tmp_path)
    assert code == 0, err


def test_a_combination_of_good_values_that_does_not_fit_is_one_line_at_its_cell(tmp_path):
    """Each value is checked alone up front; a cell whose values clash (the camera on its
    look-at point) is made at its turn: one line, the cells before it kept."""
    (tmp_path / "s.toml").write_text(SCENE)
    line = one_line_error(run_main(
        "sweep", "s.toml", "--set", "camera.position=[0, 0, 5],[0, 0, 1]",
        "--set", "camera.look_at=[0, 0, 0],[0, 0, 1]", "-W", "4", "-H", "3", "-q",
        "-o", "c.png", cwd=tmp_path))
    assert line == "error: --set: camera: look_at coincides with position"  # as a file says
    assert sorted(p.name for p in (tmp_path / "c_cells").iterdir()) == [
        "0.png", "1.png", "2.png"]
    assert not (tmp_path / "c.png").exists()
