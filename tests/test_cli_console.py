"""The command line's progress bars on a terminal: rich is given a console it can use to the
end (a ``Live`` ends by calling ``console.line()``), so a command that showed a bar ends with
its result, not an internal error."""

from __future__ import annotations

import ast
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

FILM = """
[render]
width = 24
height = 16

[camera]
position = [0, 1.5, 5]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5

[animation]
frames = 2
fps = 12

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 1.5, 5]], [1, [3, 1.5, 4]]]
"""


def test_a_progress_bar_given_the_lazy_console_runs_to_its_end():
    from rich.progress import BarColumn, Progress, TextColumn

    from whitted.cli.console import LazyConsole

    screen = io.StringIO()
    console = LazyConsole(file=screen, force_terminal=True, width=60, highlight=False)
    with Progress(TextColumn("{task.description}"), BarColumn(), console=console,
                  transient=True) as bar:
        task = bar.add_task("frames", total=2)
        bar.update(task, advance=2)
        bar.console.print("a line above the bar")
    console.echo("after the bar")
    shown = screen.getvalue()
    assert "frames" in shown and "a line above the bar" in shown
    assert shown.endswith("after the bar\n")


def test_the_lazy_console_adds_no_name_that_hides_one_of_rich_s():
    # rich calls its console's methods on whatever it was given: the wrapper may add names,
    # and answer is_terminal (by rich's own rules), but never replace another of rich's
    from rich.console import Console

    from whitted.cli.console import LazyConsole

    real = Console(file=io.StringIO())
    own = {name for name in vars(LazyConsole) if not name.startswith("__")}
    own |= set(vars(LazyConsole(file=io.StringIO())))
    hidden = {name for name in own if hasattr(real, name)}
    assert hidden == {"is_terminal"}
    assert LazyConsole(file=io.StringIO()).is_terminal is real.is_terminal is False


def _lazy_names(tree: ast.Module) -> set[str]:
    """Names a module binds to a LazyConsole: ``err``/``out`` imported from the CLI's console
    (or app) module, and any name assigned ``LazyConsole(...)``."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[-1] in (
                "console", "app"):
            names |= {a.asname or a.name for a in node.names if a.name in ("err", "out")}
        elif (isinstance(node, ast.Assign) and isinstance(node.value, ast.Call)
              and getattr(node.value.func, "id", None) == "LazyConsole"):
            names |= {t.id for t in node.targets if isinstance(t, ast.Name)}
    return names


def test_every_console_handed_to_rich_is_rich_s_own():
    # render, stefan, animate and the farm give their bars `err.console` (one rule, whatever
    # the wrapper can do)
    handed = []
    for path in sorted((SRC / "whitted").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        lazy = _lazy_names(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                for kw in node.keywords:
                    if kw.arg == "console":
                        handed.append(path.name)
                        assert not (isinstance(kw.value, ast.Name) and kw.value.id in lazy), (
                            f"{path.relative_to(SRC)}:{node.lineno}: console={kw.value.id} "
                            "hands rich the wrapper; give it .console")
    assert {"animate.py", "farm.py", "render.py", "stefan.py"} <= set(handed)


def _on_a_terminal(*args: object, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "TTY_COMPATIBLE": "1", "COLUMNS": "100", "PYTHONPATH": str(SRC)}
    env.pop("FORCE_COLOR", None)
    return subprocess.run([sys.executable, "-m", "whitted", *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_a_film_on_a_terminal_ends_with_its_summary(tmp_path):
    scene = tmp_path / "turn.toml"
    scene.write_text(FILM)
    done = _on_a_terminal("animate", scene, "-o", tmp_path / "turn.gif", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "internal error" not in done.stderr
    assert "frames" in done.stderr  # the bar was shown
    assert "2 frames (2 rendered" in done.stdout and (tmp_path / "turn.gif").is_file()


def test_a_film_on_a_farm_on_a_terminal_ends_with_its_summary(tmp_path):
    pytest.importorskip("distributed")
    scene = tmp_path / "turn.toml"
    scene.write_text(FILM)
    done = _on_a_terminal("animate", scene, "-o", tmp_path / "turn.gif", "--cluster",
                          "local:1", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "internal error" not in done.stderr
    assert "2 frames (2 rendered" in done.stdout and (tmp_path / "turn.gif").is_file()
