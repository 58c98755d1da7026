"""``whitted export``: the scene for another renderer (POV-Ray 3.7's scene language).

Without ``-o`` the file is written in the current folder (``SCENE.pov``), as ``whitted
render`` writes its ``render.png`` there: the scene's own folder may be one the user cannot
or should not write to (an installed package's examples, a shared project). Either way an
export replaces only a file whitted exported (its first line says so); anything else there
is kept, unless ``--force``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import (
    SceneArgument,
    app,
    fail,
    load_scene_argument,
    override_error,
    with_options,
    with_scene_key,
)
from .console import Text, out


@app.command()
def export(
    scene_path: SceneArgument = None,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="File to write; default: SCENE.pov in the current folder")] = None,
    export_format: Annotated[str, typer.Option("--format", "-f", help="Only 'pov'")] = "pov",
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace a file at the output that whitted did not write")] = False,
) -> None:
    """Write SCENE for another renderer: POV-Ray 3.7 scene language (--format pov).
    A file at the output that whitted did not export is never replaced without --force."""
    from pydantic import ValidationError

    from ..export.pov import export_pov, foreign_file, povray_antialias_options
    from ..output.safety import check_outputs

    if export_format != "pov":
        raise fail(f"--format: unknown format {export_format!r} (known: pov)")
    try:
        scene, name = load_scene_argument(scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    scene = with_options(scene, width=width, height=height)
    try:
        if scene.is_animated:  # POV-Ray gets the first frame, mesh sequences named
            scene = scene.at_frame(0)
    except ValidationError as exc:
        raise fail(override_error(exc)) from None
    if output is None:  # the whole stem: scene.v1.toml -> scene.v1.pov
        output = Path((scene_path.stem if scene_path else "default") + ".pov")
    source = str(scene_path) if scene_path else name
    try:
        check_outputs([output], scene, scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    if not force and foreign_file(output):
        raise fail(f"{output}: exists and was not written by whitted; it is kept (give "
                   "--force to replace it, or another -o)")
    try:
        export_pov(scene, output, source=source, force=force)
    except WhittedError as exc:
        raise fail(with_scene_key(exc, scene, name)) from None
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None
    r = scene.render
    out.print(Text(f"{name} -> {output} (POV-Ray 3.7; render with: povray +I{output} "
                   f"+W{r.width} +H{r.height} {povray_antialias_options(scene)})"))
