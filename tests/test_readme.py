"""The README's commands and Python snippets run as written, in order, in a fresh folder
that holds what a user has after `whitted examples examples` (the README's pip route): every
shell command and every Python block, at tiny picture sizes (-W/-H added, width=/height=
rewritten, films cut to four frames) and on a small Stefan case. Left out: installing (make,
pip, activating the virtual environment: CI's `make check-wheel` does that for real),
`whitted gui` (a desktop window), POV-Ray's comparison when POV-Ray is not installed,
`whitted warm` (every kernel variant compiled: minutes on a cold cache; its own tests are in
tests/test_warm_command.py) and `whitted stefan validate` (a minute or more of solving;
tests/test_cov_stefan_validate.py checks the studies behind its tables)."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
TINY = ["-W", "32", "-H", "24"]
INSTALLING = {"make", "pip", "."}


def code_blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", README, re.MULTILINE | re.DOTALL)


def shell_commands() -> list[list[str]]:
    commands = []
    for block in code_blocks("sh"):
        for line in block.replace("\\\n", " ").splitlines():
            argv = shlex.split(line, comments=True)
            if argv:
                commands.append(argv)
    return commands


def tiny_stefan_case(folder: Path) -> Path:
    """The example case on a coarse grid for a few minutes of melting."""
    text = (folder / "examples/stefan/hollow_ice.toml").read_text(encoding="utf-8")
    text = re.sub(r"(?m)^cells = \d+", "cells = 20", text)
    text = re.sub(r"(?m)^end = [0-9.e]+", "end = 240.0", text)
    text = re.sub(r"(?m)^save_every = [0-9.e]+", "save_every = 120.0", text)
    path = folder / "tiny_hollow_ice.toml"
    path.write_text(text, encoding="utf-8")
    return path


def as_run(argv: list[str], folder: Path) -> list[str] | str:
    """The command as the test runs it, or why it is left out."""
    if argv[0] in INSTALLING:
        return "installs whitted (make check-wheel does it in CI)"
    assert argv[0] == "whitted", argv
    command = argv[1] if len(argv) > 1 else "render"
    if command == "gui":
        return "opens a desktop window"
    run = [sys.executable, "-m", "whitted", *argv[1:]]
    if command == "bench":
        if "povray" in argv and shutil.which("povray") is None:
            return "POV-Ray is not installed"
        scene = [] if "--scene" in run else ["--scene", "seed000"]
        return [*run, "--quick", *scene, "--runs", "1"]
    if "--turntable" in run:  # four frames of the film are enough to show it runs
        run[run.index("--turntable") + 1] = "4"
    if command == "animate":
        return [*run, *TINY, "--frames", "0:3"]
    if "--region" in run and ":" in run[run.index("--region") + 1] \
            and "." not in run[run.index("--region") + 1]:
        return run  # a region in pixels needs the scene's own size
    if command in ("render", "sweep"):
        return [*run, *TINY]
    if command == "warm":
        return "compiles every kernel variant (minutes when cold); tests/test_warm_command.py"
    if argv[1:3] == ["stefan", "validate"]:
        return "a minute of solving; tests/test_cov_stefan_validate.py checks its studies"
    if command == "stefan":
        case = str(tiny_stefan_case(folder))
        run = [case if a == "examples/stefan/hollow_ice.toml" else a for a in run]
        return [*run, *TINY] if argv[2] == "film" else run
    return run


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """A user's fresh folder with the examples copied in by the README's command."""
    here = tmp_path_factory.mktemp("readme")
    done = subprocess.run([sys.executable, "-m", "whitted", "examples", "examples"], cwd=here,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (here / "examples/glass_cube.toml").is_file()
    assert (here / "examples/models/cow/cow_texture.png").is_file()
    return here


def test_the_readme_shows_the_commands_this_test_runs():
    commands = shell_commands()
    assert ["make", "demo"] in commands and [".", ".venv/bin/activate"] in commands
    names = [a[1] for a in commands if a[0] == "whitted" and len(a) > 1]
    for name in ("render", "info", "export", "animate", "sweep", "stefan", "examples"):
        assert name in names
    # the activation line the README shows is what `make demo` prints
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert "VENV ?= .venv\n" in makefile and '@echo "    . $(VENV)/bin/activate"' in makefile
    # the install, minutes of a quiet pip, says first what it is doing
    recipe = makefile.split("$(BIN)/whitted: pyproject.toml\n", 1)[1].split("\n\n", 1)[0]
    assert recipe.splitlines()[0].startswith("\t@echo \"installing whitted"), recipe
    assert "--quiet -e '.[all]'" in recipe


def test_the_readme_table_lists_every_example():
    """Each example `whitted examples` lists has its row in the README's table of them."""
    from whitted.files.shipped import example_names

    rows = re.findall(r"^\| `examples/([\w/]+)\.toml` \| (.+) \|$", README, re.MULTILINE)
    described = {name: text for name, text in rows}
    assert len(rows) == len(described)  # none twice
    names = set(example_names())
    assert names <= set(described), sorted(names - set(described))
    assert set(described) <= names, sorted(set(described) - names)


def run_commands(folder: Path, stefan: bool) -> list[str]:
    ran = []
    env = {**os.environ, "WHITTED_PROGRESS_DELAY": "1000"}
    for argv in shell_commands():
        if (argv[:2] == ["whitted", "stefan"]) != stefan:
            continue
        run = as_run(argv, folder)
        if isinstance(run, str):
            continue
        done = subprocess.run(run, cwd=folder, capture_output=True, text=True, timeout=600,
                              env=env)
        assert done.returncode == 0, f"{shlex.join(argv)}: {done.stderr[-2000:]}"
        ran.append(shlex.join(argv))
    return ran


def test_the_shell_commands_run(folder):
    ran = run_commands(folder, stefan=False)
    assert len(ran) >= 15
    for made in ("cube.png", "cube.exr", "cube.depth.npy", "teapot.png", "teapot.mp4",
                 "cube.pov", "orbit.mp4", "orbit_small.gif", "f12.png", "kt.png", "render.png"):
        assert (folder / made).is_file(), made


def test_the_stefan_commands_run(folder):
    ran = run_commands(folder, stefan=True)
    assert len(ran) == 2
    assert (folder / "melt.mp4").is_file() and (folder / "melt.gif").is_file()


def test_the_python_snippets_run(folder):
    source = "\n".join(code_blocks("python"))
    source = re.sub(r"\bwidth=\d+", "width=32", source)
    source = re.sub(r"\bheight=\d+", "height=24", source)
    # the job's state line shows how it ended, never "running"
    assert "\njob.state, job.srgb()" in source
    source = source.replace("\njob.state, job.srgb()", "\nassert job.state in ('cancelled', "
                            "'finished'), job.state; job.srgb()")
    done = subprocess.run([sys.executable, "-c", source], cwd=folder, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    from PIL import Image

    for made in ("ice.png", "cow.png"):
        assert Image.open(folder / made).size == (32, 24)


def test_the_cache_files_the_readme_names_are_the_ones_whitted_writes():
    """The kernel cache's marker files by the names the code gives them."""
    source = (ROOT / "src/whitted/render/warm_up.py").read_text(encoding="utf-8")
    written = set(re.findall(r'"(whitted-ready-\w+)"', source))
    named = set(re.findall(r"`(whitted-ready-\w+)`", README))
    assert named and written == named, (named, written)
    assert "whitted-sums.json" in README and '"whitted-sums.json"' in "".join(
        p.read_text(encoding="utf-8") for p in (ROOT / "src/whitted/jit").glob("*.py"))
