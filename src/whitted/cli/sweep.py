"""``whitted sweep``: one image per value of a scene value, laid out as a labelled sheet."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import WhittedError
from .app import (
    SceneArgument,
    app,
    fail,
    load_scene_argument,
    out,
    override_error,
)
from .interrupt import InterruptGuard


@app.command()
def sweep(
    scene_path: SceneArgument = None,
    set_values: Annotated[
        list[str] | None, typer.Option(
            "--set", help="PATH=VALUES to sweep (START:STOP:STEP or a,b,c; one or two), "
                          "or PATH=VALUE to fix")
    ] = None,
    output: Annotated[Path, typer.Option("-o", "--output", help="The sheet (PNG)")] = Path(
        "sheet.png"),
    columns: Annotated[
        int | None, typer.Option("--columns", help="Cells per row (one swept value)")
    ] = None,
    title: Annotated[str | None, typer.Option("--title", help="Text above the sheet")] = None,
    frame: Annotated[int, typer.Option("--frame", "-f", help="Frame of an animated scene")] = 0,
    width: Annotated[int | None, typer.Option("--width", "-W", help="Cell width")] = None,
    height: Annotated[int | None, typer.Option("--height", "-H", help="Cell height")] = None,
    samples: Annotated[int | None, typer.Option("--samples", "-s", help="Samples/pixel")] = None,
    max_depth: Annotated[int | None, typer.Option("--max-depth", "-d", help="Recursion")] = None,
    threads: Annotated[int | None, typer.Option("--threads", "-t", help="0 = all cores")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress output")] = False,
) -> None:
    """Render SCENE once per value of a --set with several values (the first such --set gives
    the columns, a second one the rows), keep each image in SHEET_cells/, and write a
    contact sheet with the values under the images. Example: --set
    "objects[glass sphere].material.kt=1:0:-0.2" (1, 0.8, ... 0)."""
    from pydantic import ValidationError

    from ..animation.film import check_frame_files
    from ..animation.frames import FrameRenderer
    from ..animation.overrides import apply_overrides, parse_assignment, parse_values
    from ..animation.sweep import sweep_cells
    from ..files import atomic_write
    from ..output.safety import check_memory, check_outputs, input_files
    from ..render.api import CancelToken

    started = time.perf_counter()
    if output.suffix.lower() != ".png":
        raise fail(f"{output}: the sheet is a PNG (use a .png name)")
    try:
        scene, name = load_scene_argument(scene_path)
        axes, fixed = [], []
        for text in set_values or []:
            path, value_text = parse_assignment(text)
            values = parse_values(value_text)
            if len(values) > 1:
                axes.append((path, values))
            else:
                fixed.append((path, value_text))
        scene = apply_overrides(scene, fixed)
        scene = scene.with_settings(width=width, height=height, samples=samples,
                                    max_depth=max_depth)
        cells = sweep_cells(scene, axes)
        stills = [cell.scene.at_frame(frame) for cell in cells]
        # before anything is written: the sheet and the cells can be written, none is a file
        # the sweep reads, and no file in the cells' way was written by anyone but whitted
        inputs = list(dict.fromkeys(  # a swept value may name other files
            f for cell in cells for f in input_files(cell.scene, scene_path)))
        check_outputs([output], inputs=inputs)
        folder = output.with_name(f"{output.stem}_cells")
        digits = len(str(len(cells) - 1))
        cell_files = [folder / f"{cell.index:0{digits}d}.png" for cell in cells]
        check_frame_files(folder, cell_files, inputs)
        for still in stills:
            check_memory(still.render.width, still.render.height, "png")
        folder.mkdir(exist_ok=True)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:
        raise fail(override_error(exc)) from None
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None

    renderer = FrameRenderer(threads)
    cancel = CancelToken()
    paths: list[Path] = []
    rendered = 0
    with InterruptGuard() as guard:
        guard.on_interrupt(cancel.cancel)
        try:
            for cell, still, path in zip(cells, stills, cell_files, strict=True):
                if cancel.cancelled:
                    break
                result = renderer.render(still, frame, path, cancel=cancel)
                if result.cancelled:
                    break
                rendered += int(result.rendered)
                paths.append(path)
                if not quiet:
                    state = f"{result.seconds:.2f} s" if result.rendered else "already done"
                    out.line(f"{cell.label} ({cell.index + 1}/{len(cells)}): {state}")
        except WhittedError as exc:
            raise fail(str(exc)) from None
        except OSError as exc:
            raise fail(f"{folder}: cannot write: {exc.strerror or exc}") from None
        if len(paths) < len(cells):
            raise guard.exit(f"{len(paths)} of {len(cells)} images finished in {folder}; "
                             "run the same command again to continue")
        _write_sheet(output, paths, cells, axes, columns, title, guard, atomic_write)
    if not quiet:
        out.print(f"{len(cells)} images ({rendered} rendered) -> {folder}; sheet "
                  f"{_sheet_size(output)} -> {output}; "
                  f"{time.perf_counter() - started:.1f} s", highlight=False)


def _write_sheet(output, paths, cells, axes, columns, title, guard, atomic_write) -> None:
    """The contact sheet, written atomically (a signal during the write lets it finish: the
    cells are all there, and the sheet is whole or not written)."""
    import numpy as np
    from PIL import Image as PILImage

    from ..animation.sweep import contact_sheet

    images = [np.asarray(PILImage.open(p).convert("RGB")) for p in paths]
    if len(axes) == 2:
        ncols = len(axes[0][1])
    else:
        ncols = columns or (len(cells) if len(cells) <= 6 else math.ceil(math.sqrt(len(cells))))
    heading = title if title is not None else " / ".join(path for path, _ in axes)
    sheet = contact_sheet(images, [c.label for c in cells], ncols, heading)
    try:
        atomic_write(output, lambda tmp: PILImage.fromarray(sheet).save(tmp, format="PNG"))
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None
    if guard.interrupted:
        raise guard.exit(f"every image is in {output.with_name(output.stem + '_cells')} and "
                         f"the sheet was written to {output}")


def _sheet_size(output: Path) -> str:
    from PIL import Image as PILImage

    with PILImage.open(output) as im:
        return f"{im.width}x{im.height}"
