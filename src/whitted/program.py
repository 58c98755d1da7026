"""The ``whitted`` program: the command line (``cli/``) and the editor's ``whitted gui``
(``gui/``). The two are clients on one layer that never import each other; this module, above
both, puts the editor's command into the command line."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Annotated

import typer

from .cli.app import app, fail, no_such_example
from .cli.main import main as _cli_main
from .errors import WhittedError


@app.command()
def gui(
    scene_path: Annotated[
        Path | None, typer.Argument(
            metavar="[SCENE]", help="Scene file (a new one if missing), model file (.obj, .ply, "
            ".stl, .off, .glb, .gltf) or example name")
    ] = None,
) -> None:
    """Open the scene editor (a desktop window) on SCENE, or on the built-in default scene. A
    model file opens as a new scene (the model on a lit ground, framed), to save as a scene
    file."""
    from .scene import load_scene

    scene = None
    try:
        exists = scene_path is not None and scene_path.exists()
    except (OSError, ValueError) as exc:
        raise fail(f"{scene_path}: {getattr(exc, 'strerror', None) or exc}") from None
    from .files.shipped import example_path
    from .studio import is_model_file, model_scene

    example = None if exists or scene_path is None else example_path(str(scene_path))
    if scene_path is not None and is_model_file(scene_path):
        try:  # the model on a lit ground, framed: an untitled scene, saved where the user says
            scene, scene_path = model_scene(scene_path), None
        except WhittedError as exc:
            raise fail(str(exc)) from None
    elif exists or example is not None:
        try:
            scene = load_scene(example or scene_path)
        except WhittedError as exc:
            raise fail(str(exc)) from None
        if example is not None:  # untitled: a save never writes into whitted's own examples
            scene_path = None
    elif scene_path is not None and not scene_path.suffix:  # meant as an example's name
        raise fail(f"{scene_path}: {no_such_example(str(scene_path))}")
    elif scene_path is not None and scene_path.suffix.lower() not in (".toml", ".json"):
        raise fail(f"{scene_path}: unknown scene format {scene_path.suffix!r} (use .toml or .json)")
    # Qt is imported by the editor only, after its check of the system libraries Qt needs
    if importlib.util.find_spec("PySide6") is None:
        raise fail("the editor needs PySide6, which is not installed: install whitted[gui] "
                   "(pip install 'whitted[gui]')")
    try:
        from .gui.app import run_editor
    except ImportError as exc:
        raise fail(f"the editor needs PySide6 ({exc}): install whitted[gui] "
                   "(pip install 'whitted[gui]')") from None
    from .cli.interrupt import command_began

    # a SIGTERM or Ctrl-C while the window is open: the editor autosaves and says so
    raise typer.Exit(run_editor(scene, scene_path, on_running=command_began))


def main() -> None:
    """Console entry point of ``whitted`` (and ``python -m whitted``)."""
    from .cli.interrupt import install_process_handlers

    install_process_handlers()  # SIGINT, SIGTERM outside a command's guard: one line, at once
    _cli_main()
