"""``whitted examples [DIR]``: the example scenes that come with whitted, listed by the short
names ``render`` takes (``whitted render glass_cube``), or copied into DIR with their models
and textures to edit and render (never over a file that is already there)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import app, fail
from .console import out


@app.command()
def examples(
    folder: Annotated[Path | None, typer.Argument(
        metavar="[DIR]", help="Folder to copy the examples into (made if missing)")] = None,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="The same as DIR")] = None,
) -> None:
    """List the example scenes (render one by name: whitted render glass_cube), or copy them
    with their models and textures into DIR; files already in DIR are kept as they are."""
    from ..files.shipped import copy_examples, example_names, shipped_dir

    if folder is not None and output is not None and folder != output:
        raise fail(f"give the folder once: DIR ({folder}) or -o ({output})")
    folder = folder or output
    if folder is None:
        names = example_names()
        if not names:
            raise fail("whitted's examples are not installed with this copy of whitted")
        for name in names:
            out.echo(name)
        out.echo(f"(in {shipped_dir('examples')}; `whitted examples DIR` copies them)")
        return
    try:
        copied, kept = copy_examples(folder)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except OSError as exc:
        raise fail(f"{getattr(exc, 'filename', None) or folder}: cannot write: "
                   f"{exc.strerror or exc}") from None
    line = f"copied {len(copied)} files into {folder}"
    if kept:
        line += f"; kept {len(kept)} already there (not replaced)"
    out.echo(line)
    if copied or kept:
        out.echo(f"try: whitted render {folder / 'glass_cube.toml'} -o cube.png")
