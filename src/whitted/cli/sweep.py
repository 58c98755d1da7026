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
    check_default_output,
    fail,
    load_scene_argument,
    out,
    override_error,
    with_options,
)
from .interrupt import InterruptGuard


def _sheet_columns(cells, columns: int | None) -> int:
    """Cells per row of the sheet: the first axis's values for a grid, else --columns, else
    one row up to 6 cells and a square-ish grid beyond."""
    if len(cells.axes) == 2:
        return cells.columns
    n = len(cells)
    return max(1, min(n, columns or (n if n <= 6 else math.ceil(math.sqrt(n)))))


@app.command()
def sweep(
    scene_path: SceneArgument = None,
    set_values: Annotated[
        list[str] | None, typer.Option(
            "--set", help="PATH=VALUES to sweep (START:STOP:STEP or a,b,c; one or two), "
                          "or PATH=VALUE to fix")
    ] = None,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="The sheet (PNG; default: sheet.png)")] = None,
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
    from ..animation.overrides import apply_overrides, is_range, parse_assignment, parse_values
    from ..animation.sweep import cell_size_bounds, check_sheet_size, sweep_cells
    from ..files import atomic_write
    from ..output.safety import check_memory, check_outputs, input_files
    from ..render.api import CancelToken

    started = time.perf_counter()
    named = output is not None
    output = output or Path("sheet.png")
    if output.suffix.lower() != ".png":
        raise fail(f"{output}: the sheet is a PNG (use a .png name)")
    if not named:
        check_default_output(output)
    try:
        scene, name = load_scene_argument(scene_path)
        axes, fixed = [], []
        for text in set_values or []:
            path, value_text = parse_assignment(text)
            values = parse_values(value_text)
            if len(values) > 1 or is_range(value_text):  # a range of one value is an axis
                axes.append((path, values))
            else:
                fixed.append((path, value_text))
        scene = apply_overrides(scene, fixed)
        scene = with_options(scene, width=width, height=height, samples=samples,
                             max_depth=max_depth)
        cells = sweep_cells(scene, axes)  # counted and checked value by value, made lazily
        scene.at_frame(frame)
        ncols = _sheet_columns(cells, columns)
        widths, heights = cell_size_bounds(cells)
        if ncols != cells.columns:  # one axis wrapped onto several rows
            widths = [max(widths)] * ncols
            heights = [heights[0]] * math.ceil(len(cells) / ncols)
        check_sheet_size(widths, heights, title != "")
        # before anything is written: the sheet and the cells can be written, none is a file
        # the sweep reads, and no file in the cells' way was written by anyone but whitted.
        # A swept value may name other files: those of the scene with each value alone set
        # (one scene per value, not one per cell).
        inputs = list(dict.fromkeys(
            f for each in [scene, *cells.axis_scenes()] for f in input_files(each, scene_path)))
        check_outputs([output], inputs=inputs)
        folder = output.with_name(f"{output.stem}_cells")
        digits = len(str(len(cells) - 1))
        cell_files = [folder / f"{k:0{digits}d}.png" for k in range(len(cells))]
        check_frame_files(folder, cell_files, inputs)
        check_memory(max(widths), max(heights), "png")  # the largest cell, at most
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
            for cell, path in zip(cells, cell_files, strict=True):
                if cancel.cancelled:
                    break
                try:
                    still = cell.scene.at_frame(frame)  # each cell's scene made when its turn
                except ValidationError as exc:
                    raise fail(override_error(exc)) from None
                result = renderer.render(still, frame, path, cancel=cancel)
                if result.cancelled:
                    break
                rendered += int(result.rendered)
                paths.append(path)
                if not quiet:
                    state = f"{result.seconds:.2f} s" if result.rendered else "already done"
                    out.echo(f"{cell.label} ({cell.index + 1}/{len(cells)}): {state}")
        except WhittedError as exc:
            raise fail(str(exc)) from None
        except OSError as exc:
            raise fail(f"{folder}: cannot write: {exc.strerror or exc}") from None
        if len(paths) < len(cells):
            raise guard.exit(f"{len(paths)} of {len(cells)} images finished in {folder}; "
                             "run the same command again to continue")
        _write_sheet(output, paths, cells, axes, ncols, title, guard, atomic_write)
    if not quiet:
        out.print(f"{len(cells)} images ({rendered} rendered) -> {folder}; sheet "
                  f"{_sheet_size(output)} -> {output}; "
                  f"{time.perf_counter() - started:.1f} s", highlight=False)


def _write_sheet(output, paths, cells, axes, ncols, title, guard, atomic_write) -> None:
    """The contact sheet, written atomically (a signal during the write lets it finish: the
    cells are all there, and the sheet is whole or not written)."""
    import numpy as np
    from PIL import Image as PILImage

    from ..animation.sweep import contact_sheet
    from ..output.png import software_text

    images = [np.asarray(PILImage.open(p).convert("RGB")) for p in paths]
    heading = title if title is not None else " / ".join(path for path, _ in axes)
    sheet = contact_sheet(images, [c.label for c in cells], ncols, heading)
    try:
        atomic_write(output, lambda tmp: PILImage.fromarray(sheet).save(
            tmp, format="PNG", pnginfo=software_text()))
    except OSError as exc:
        raise fail(f"{output}: cannot write: {exc.strerror or exc}") from None
    if guard.interrupted:
        raise guard.exit(f"every image is in {output.with_name(output.stem + '_cells')} and "
                         f"the sheet was written to {output}")


def _sheet_size(output: Path) -> str:
    from PIL import Image as PILImage

    with PILImage.open(output) as im:
        return f"{im.width}x{im.height}"
