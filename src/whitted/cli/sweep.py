"""``whitted sweep``: one image per value of a scene value, laid out as a labelled sheet."""

from __future__ import annotations

import math
import signal
import threading
import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import SceneError, WhittedError
from .main import (
    EXIT_INTERRUPTED,
    SceneArgument,
    _load,
    _override_error,
    app,
    err,
    fail,
    out,
)


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

    from ..animation.frames import FrameRenderer
    from ..animation.overrides import apply_overrides, parse_assignment, parse_values
    from ..animation.sweep import contact_sheet, sweep_cells
    from ..files import atomic_write
    from ..render.api import CancelToken

    started = time.perf_counter()
    if output.suffix.lower() != ".png":
        raise fail(f"{output}: the sheet is a PNG (use a .png name)")
    try:
        scene, name = _load(scene_path)
        if scene_path is not None and output.resolve() == scene_path.resolve():
            raise SceneError("would write over the scene file", where=str(output))
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
    except WhittedError as exc:
        raise fail(str(exc)) from None
    except ValidationError as exc:
        raise fail(_override_error(exc)) from None
    if not output.parent.exists():
        raise fail(f"{output}: the folder {output.parent} does not exist")
    folder = output.with_name(f"{output.stem}_cells")
    folder.mkdir(exist_ok=True)

    renderer = FrameRenderer(threads)
    cancel = CancelToken()
    interrupted = threading.Event()
    previous = signal.getsignal(signal.SIGINT)

    def on_interrupt(signum, frame_) -> None:
        interrupted.set()
        cancel.cancel()

    signal.signal(signal.SIGINT, on_interrupt)
    paths: list[Path] = []
    rendered = 0
    digits = len(str(len(cells) - 1))
    try:
        for cell, still in zip(cells, stills, strict=True):
            if interrupted.is_set():
                break
            path = folder / f"{cell.index:0{digits}d}.png"
            result = renderer.render(still, frame, path, cancel=cancel)
            if result.cancelled:
                break
            rendered += int(result.rendered)
            paths.append(path)
            if not quiet:
                state = f"{result.seconds:.2f} s" if result.rendered else "already done"
                err.print(f"{cell.label} ({cell.index + 1}/{len(cells)}): {state}",
                          highlight=False, markup=False)
    except WhittedError as exc:
        raise fail(str(exc)) from None
    finally:
        signal.signal(signal.SIGINT, previous)
    if len(paths) < len(cells):
        err.print(f"interrupted: {len(paths)} of {len(cells)} images finished in {folder}; "
                  "run the same command again to continue")
        raise typer.Exit(EXIT_INTERRUPTED)

    import numpy as np
    from PIL import Image as PILImage

    images = [np.asarray(PILImage.open(p).convert("RGB")) for p in paths]
    if len(axes) == 2:
        ncols = len(axes[0][1])
    else:
        ncols = columns or (len(cells) if len(cells) <= 6 else math.ceil(math.sqrt(len(cells))))
    heading = title if title is not None else " / ".join(path for path, _ in axes)
    sheet = contact_sheet(images, [c.label for c in cells], ncols, heading)
    atomic_write(output, lambda tmp: PILImage.fromarray(sheet).save(tmp, format="PNG"))
    if not quiet:
        out.print(f"{len(cells)} images ({rendered} rendered) -> {folder}; sheet "
                  f"{sheet.shape[1]}x{sheet.shape[0]} -> {output}; "
                  f"{time.perf_counter() - started:.1f} s", highlight=False)
