"""The ``whitted`` command end to end (``python -m whitted`` in a subprocess; the many error cases
also in-process through typer's CliRunner, which is faster): outputs, AOVs, one-line errors with
exit status 2 and no traceback, and Ctrl-C keeping the part of the image rendered so far."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

import whitted
from test_scene_errors import BAD_SCENES, BadScene, bad_scene_params
from whitted.cli.main import app

WHITTED = [sys.executable, "-m", "whitted"]

# Cases also run in a real process (exit status, no traceback); all run in-process, faster,
# except those only the console entry point (not the typer app) turns into one line.
IN_SUBPROCESS = {"malformed-toml", "unknown-object-key", "negative-radius", "missing-file",
                 "not-utf8", "colour-not-hex", "width-0", "aov-foo", "missing-folder",
                 "too-many-pixels"}
ONLY_SUBPROCESS = {"width-not-a-number", "unknown-option"}


def run_whitted(*args: object, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run the command with the caller's environment (WHITTED_CACHE_DIR included)."""
    return subprocess.run(
        [*WHITTED, *map(str, args)], cwd=cwd, env=dict(os.environ), capture_output=True,
        text=True, timeout=timeout,
    )


def run_in_process(*args: object, cwd: Path) -> subprocess.CompletedProcess:
    """The same through typer's CliRunner (no interpreter start-up); an uncaught exception is
    reported as a traceback, as the real command would show one."""
    previous = Path.cwd()
    os.chdir(cwd)
    try:
        result = CliRunner().invoke(app, [str(a) for a in args])
    finally:
        os.chdir(previous)
    stderr = result.stderr
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        stderr += "Traceback (most recent call last):\n" + repr(result.exception)
    return subprocess.CompletedProcess(args, result.exit_code, result.stdout, stderr)


def run(how: str, *args: object, cwd: Path) -> subprocess.CompletedProcess:
    return (run_whitted if how == "subprocess" else run_in_process)(*args, cwd=cwd)


def with_runners(params: list) -> list:
    """Each case in-process, the IN_SUBPROCESS ones also (and the ONLY_SUBPROCESS ones only)
    through a real process."""
    out = []
    for param in params:
        hows = ["in-process", "subprocess"]
        if param.id in ONLY_SUBPROCESS:
            hows = ["subprocess"]
        elif param.id not in IN_SUBPROCESS:
            hows = ["in-process"]
        for how in hows:
            out.append(pytest.param(how, *param.values, id=f"{param.id}-{how}",
                                    marks=param.marks))
    return out


def assert_one_line_error(result: subprocess.CompletedProcess, *needles: str) -> str:
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    assert "Traceback" not in result.stderr and "Traceback" not in result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    line = lines[0]
    assert line.startswith("error: "), line
    for needle in needles:
        assert needle in line, (needle, line)
    return line


# ------------------------------------------------------------------------------ happy paths


def test_version(tmp_path: Path):
    result = run_whitted("--version", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"whitted {whitted.__version__}"


def test_render_quiet_writes_png_and_prints_nothing(tmp_path: Path, lecture_scene: Path):
    result = run_whitted(
        "render", lecture_scene, "-o", "out.png", "--width", 40, "--height", 40, "--quiet",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "" and result.stderr == ""
    with Image.open(tmp_path / "out.png") as image:
        assert image.format == "PNG"
        assert image.size == (40, 40)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png"]


def test_render_prints_a_summary_line(tmp_path: Path, lecture_scene: Path):
    result = run_whitted(
        "render", lecture_scene, "-o", "out.png", "--width", 40, "--height", 30, cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 1, result.stdout
    summary = lines[0]
    for needle in ("40x30", "Mrays/s", " rays", "out.png"):
        assert needle in summary, (needle, summary)
    with Image.open(tmp_path / "out.png") as image:
        assert image.size == (40, 30)


def test_render_writes_aovs(tmp_path: Path, lecture_scene: Path):
    result = run_whitted(
        "render", lecture_scene, "-o", "out.png", "--aov", "depth,normal,id", "--quiet",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    with Image.open(tmp_path / "out.png") as image:
        assert image.size == (161, 161)  # the scene's own size
    depth = np.load(tmp_path / "out.depth.npy")
    normal = np.load(tmp_path / "out.normal.npy")
    ids = np.load(tmp_path / "out.id.npy")
    assert depth.dtype == np.float32 and depth.shape == (161, 161)
    assert np.issubdtype(normal.dtype, np.floating) and normal.shape == (161, 161, 3)
    assert ids.dtype == np.int32 and ids.shape == (161, 161)
    miss = ids == -1
    assert miss[0, 0] and not miss.all()  # the top-left corner sees only sky
    assert np.array_equal(np.isinf(depth), miss)
    assert np.all(depth[miss] > 0)  # +inf, not -inf
    assert np.all(np.isfinite(depth[~miss])) and np.all(depth[~miss] > 0)
    assert set(np.unique(ids[~miss])) <= {0, 1}
    np.testing.assert_allclose(np.linalg.norm(normal[~miss], axis=-1), 1.0, atol=1e-5)
    # the lecture's ray through (50, 0, 0) from (0, 0, 100) hits rectangle 2 at z = 20
    assert depth[80, 130] == pytest.approx(89.4427191, abs=1e-4)
    assert ids[80, 130] == 1
    np.testing.assert_allclose(normal[80, 130], (0.0, 0.0, 1.0), atol=1e-6)


def test_info(tmp_path: Path, lecture_scene: Path):
    result = run_whitted("info", lecture_scene, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    text = result.stdout
    assert "objects: 2" in text
    assert "lights: 2" in text
    assert "ambient" in text and "point" in text
    assert "rectangle" in text
    assert "161x161" in text


# ------------------------------------------------------------------------------- user errors


@pytest.mark.parametrize(("how", "case"), with_runners(bad_scene_params("cli_xfail")))
def test_render_bad_scene_is_one_line_error(how: str, case: BadScene, tmp_path: Path):
    case.write(tmp_path)
    result = run(how, "render", case.name, "-o", "out.png", "--quiet", cwd=tmp_path)
    line = case.line_number()
    place = f"{case.name}:{line}: " if line else f"{case.name}: "
    error = assert_one_line_error(result, place + (f"{case.where}: " if case.where else ""))
    for word in case.words:
        assert word.lower() in error.lower(), (word, error)
    assert result.stdout == ""
    assert not (tmp_path / "out.png").exists()


def test_info_bad_scene_is_one_line_error(tmp_path: Path):
    case = next(c for c in BAD_SCENES if c.id == "negative-radius")
    case.write(tmp_path)
    result = run_whitted("info", case.name, cwd=tmp_path)
    place = f"{case.name}:{case.line_number()}: {case.where}: "
    assert_one_line_error(result, place, "greater than 0")


@pytest.mark.parametrize(
    ("how", "options", "needles", "written"),
    with_runners([
        pytest.param(["--width", "0"], ["--width", "greater than or equal to 1"], "out.png",
                     id="width-0"),
        pytest.param(["--height", "-3"], ["--height", "-3"], "out.png", id="height-negative"),
        pytest.param(["--max-depth", "65"], ["--max-depth", "64"], "out.png", id="max-depth-65"),
        pytest.param(["--samples", "0"], ["--samples"], "out.png", id="samples-0"),
        pytest.param(["--width", "20000", "--height", "10000"],
                     ["--width", "20000x10000", "megapixels"], "out.png", id="too-many-pixels"),
        pytest.param(["--width", "abc"], ["--width", "integer"], "out.png",
                     id="width-not-a-number"),
        pytest.param(["--bogus"], ["--bogus"], "out.png", id="unknown-option"),
        pytest.param(["--aov", "foo"], ["--aov", "'foo'"], "out.png", id="aov-foo"),
        pytest.param(["-o", "out.xyz"], ["out.xyz", "format"], "out.xyz", id="format-xyz"),
        pytest.param(["-o", "missing/out.png"], ["missing", "does not exist"],
                     "missing/out.png", id="missing-folder"),
        pytest.param(["--bit-depth", "12"], ["--bit-depth: must be 8 or 16 (got 12)"],
                     "out.png", id="bit-depth-12"),
        pytest.param(["--transfer", "gamma"], ["--transfer", "gamma"], "out.png",
                     id="transfer-gamma"),
    ]),
)
def test_render_bad_option_is_one_line_error(
    how: str, options: list[str], needles: list[str], written: str, tmp_path: Path,
    lecture_scene: Path,
):
    args = ["render", lecture_scene, *options]
    if "-o" not in options:
        args += ["-o", "out.png"]
    result = run(how, *args, "--quiet", cwd=tmp_path)
    assert_one_line_error(result, *needles)
    assert not (tmp_path / written).exists()
    assert list(tmp_path.iterdir()) == []


def test_help_exits_0(tmp_path: Path):
    result = run_whitted("render", "--help", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Usage" in result.stdout and "--aov" in result.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        pytest.param([], "command", id="no-command"),
        pytest.param(["bogus"], "bogus", id="unknown-command"),
        pytest.param(["render", "a.toml", "b.toml"], "b.toml", id="extra-argument"),
    ],
)
def test_usage_mistake_is_one_line_error(args: list[str], needle: str, tmp_path: Path):
    result = run_whitted(*args, cwd=tmp_path)
    assert_one_line_error(result, needle)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------ Ctrl-C


@pytest.mark.timing  # sends SIGINT after a sleep sized to the machine
@pytest.mark.skipif(os.name != "posix", reason="sends SIGINT to a child process (POSIX only)")
def test_ctrl_c_keeps_the_part_rendered_so_far(tmp_path: Path):
    # A tiny render first, so that the kernels are compiled and cached: the interrupt must land
    # in the render itself, not in the compiler. A second one times the start-up.
    for _ in range(2):
        start = time.perf_counter()
        warm = run_whitted("render", "-o", "warm.png", "-W", 8, "-H", 8, "--quiet", cwd=tmp_path)
        startup = time.perf_counter() - start
        assert warm.returncode == 0, warm.stderr
    size = 2400  # some 45 million rays: many seconds of work
    out = tmp_path / "big.png"
    # on a loaded machine the first tile may not be finished after the first wait: an
    # interrupt then writes nothing (and says so), so wait longer and try again
    for extra in (1.0, 4.0, 10.0):
        proc = subprocess.Popen(
            [*WHITTED, "render", "-o", str(out), "--width", str(size), "--height", str(size),
             "--max-depth", "8"],
            cwd=tmp_path, env=dict(os.environ), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True,
        )
        try:
            time.sleep(startup + extra)  # well into the render
            assert proc.poll() is None, "the render ended before it could be interrupted"
            proc.send_signal(signal.SIGINT)
            stdout, stderr = proc.communicate(timeout=30)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        if "nothing written" not in stderr:
            break
        assert not out.exists()
    assert proc.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr
    assert "interrupted" in stderr
    with Image.open(out) as image:
        image.load()
        assert image.size == (size, size)
        pixels = np.asarray(image)
    assert pixels.max() > 0  # some tiles were rendered and kept


def test_one_command_built_gives_the_same_help_and_errors_as_all(tmp_path: Path):
    """main() lets typer build only the command the arguments name (cli/main.py
    ``only_the_command_named``): each command's --help, a bad option, a missing value and a
    bad value print the same as with every command built; without a command name, or with
    the stefan group or a misspelt name, all are kept."""
    import whitted.cli.main as cli

    everything = list(cli.app.registered_commands), list(cli.app.registered_groups)
    names = [cli._command_name(info) for info in cli.app.registered_commands]
    assert {"render", "export", "animate", "bench", "info", "sweep"} <= set(names)
    cases = [[name, "--help"] for name in names]
    cases += [["render", "--no-such-option"], ["render", "--width"], ["render", "-W", "x"],
              ["info", "a", "b", "c"], ["animate", "--frames"]]
    for args in cases:
        whole = CliRunner().invoke(app, args)
        with cli.only_the_command_named(["whitted", *args]):
            assert len(cli.app.registered_commands) == 1, args
            assert cli.app.registered_groups == [], args
            narrowed = CliRunner().invoke(app, args)
        assert (narrowed.exit_code, narrowed.stdout, narrowed.stderr) == (
            whole.exit_code, whole.stdout, whole.stderr), args
        assert (cli.app.registered_commands, cli.app.registered_groups) == everything
    for argv in (["whitted"], ["whitted", "--help"], ["whitted", "stefan", "--help"],
                 ["whitted", "rendr"], ["whitted", "--version", "render"]):
        with cli.only_the_command_named(argv):
            assert (cli.app.registered_commands, cli.app.registered_groups) == everything
