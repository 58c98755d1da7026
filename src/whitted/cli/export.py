"""``whitted export``: the scene for another renderer (POV-Ray 3.7's scene language)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import SceneArgument, app, fail, load_scene_argument, override_error, with_scene_key
from .console import Text, out


@app.command()
def export(
    scene_path: SceneArgument = None,
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="File to write; default: SCENE.pov")
    ] = None,
    export_format: Annotated[str, typer.Option("--format", "-f", help="Only 'pov'")] = "pov",
    width: Annotated[int | None, typer.Option("--width", "-W", help="Image width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Image height")] = None,
) -> None:
    """Write SCENE for another renderer: POV-Ray 3.7 scene language (--format pov)."""
    from pydantic import ValidationError

    from ..export.pov import export_pov

    if export_format != "pov":
        raise fail(f"--format: unknown format {export_format!r} (known: pov)")
    try:
        scene, name = load_scene_argument(scene_path)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    try:
        scene = scene.with_settings(width=width, height=height)
        if scene.is_animated:  # POV-Ray gets the first frame, mesh sequences named
            scene = scene.at_frame(0)
    except ValidationError as exc:
        raise fail(override_error(exc)) from None
    if output is None:  # the whole stem: scene.v1.toml -> scene.v1.pov
        output = Path((scene_path.stem if scene_path else "default") + ".pov")
    try:
        export_pov(scene, output, source=str(scene_path) if scene_path else name)
    except WhittedError as exc:
        raise fail(with_scene_key(exc, scene, name)) from None
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None
    r = scene.render
    out.print(Text(f"{name} -> {output} (POV-Ray 3.7; render with: povray +I{output} "
                   f"+W{r.width} +H{r.height} -A)"))


