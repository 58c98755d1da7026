"""A sweep rendered in memory: one image per combination of values, and the labelled contact
sheet of them (:class:`ContactSheet`, which shows itself in a notebook).

``whitted sweep`` writes its cells and sheet to files (and resumes); :func:`render_sweep` is
the same sweep for the Python API: the same cells (:func:`~whitted.animation.sweep.sweep_cells`:
counted and checked value by value before anything renders), the same sheet
(:func:`~whitted.animation.sweep.contact_sheet`), nothing written unless asked.
"""

from __future__ import annotations

import io
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import RenderCancelled, SceneError

if TYPE_CHECKING:
    from ..output.image import Image
    from ..render.api import CancelToken, Progress
    from ..scene.scene import Scene
    from .sweep import SweepCell

__all__ = ["ContactSheet", "SweepProgress", "render_sweep", "sheet_columns"]


def sheet_columns(cells, columns: int | None) -> int:
    """Cells per row: the first axis's values for a grid of two axes, else ``columns``, else
    one row up to 6 cells and a square-ish grid beyond (as ``whitted sweep``)."""
    if len(cells.axes) == 2:
        return cells.columns
    n = len(cells)
    return max(1, min(n, columns or (n if n <= 6 else math.ceil(math.sqrt(n)))))


@dataclass
class SweepProgress:
    """What :func:`render_sweep`'s ``progress`` receives: cell ``cell`` (``done`` of
    ``total`` finished) starts (``tiles`` None) or has ``tiles`` done."""

    cell: SweepCell
    done: int
    total: int
    tiles: Progress | None = None


@dataclass
class ContactSheet:
    """The sheet (``pixels``: (H, W, 3) uint8 sRGB), the cells' images and labels, and
    whether every cell was rendered (``complete``: a cancelled sweep shows those that were)."""

    pixels: np.ndarray
    images: list[Image] = field(repr=False)
    labels: list[str]
    axes: list[tuple[str, list[Any]]]
    complete: bool = True
    seconds: float = 0.0

    @property
    def width(self) -> int:
        return int(self.pixels.shape[1])

    @property
    def height(self) -> int:
        return int(self.pixels.shape[0])

    def _repr_png_(self) -> bytes:
        from PIL import Image as PILImage

        buf = io.BytesIO()
        PILImage.fromarray(self.pixels).save(buf, format="PNG")
        return buf.getvalue()

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the sheet as a PNG, atomically."""
        from PIL import Image as PILImage

        from ..errors import OutputError
        from ..files import atomic_write
        from ..output.png import software_text

        path = Path(path)
        if path.suffix.lower() != ".png":
            raise OutputError(f"{path}: the sheet is a PNG (use a .png name)")
        try:
            return atomic_write(path, lambda tmp: PILImage.fromarray(self.pixels).save(
                tmp, format="PNG", pnginfo=software_text()))
        except OSError as exc:
            raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None

    def __repr__(self) -> str:
        swept = " x ".join(f"{path} ({len(values)})" for path, values in self.axes)
        state = "" if self.complete else f", {len(self.images)} cells rendered (stopped)"
        return f"<ContactSheet {self.width}x{self.height}: {swept}{state}>"


def _axes(axes: Mapping[str, Sequence[Any]] | Sequence[tuple[str, Sequence[Any]]]):
    items = list(axes.items()) if isinstance(axes, Mapping) else list(axes)
    out = []
    for item in items:
        try:
            path, values = item
        except (TypeError, ValueError):
            raise SceneError(f"a swept value is (path, values), got {item!r}") from None
        if isinstance(values, str):
            from .overrides import parse_values

            values = parse_values(values)  # "0:1:0.25" or "a,b,c" as on the command line
        out.append((str(path), list(values)))
    return out


def render_sweep(
    scene: Scene,
    axes: Mapping[str, Sequence[Any]] | Sequence[tuple[str, Sequence[Any]]],
    *,
    columns: int | None = None,
    title: str | None = None,
    threads: int | None = None,
    progress: Callable[[SweepProgress], None] | None = None,
    cancel: CancelToken | None = None,
) -> ContactSheet:
    """Render ``scene`` once per combination of the swept values (``{"camera.aperture":
    [0, 0.1, 0.2]}``: the first path's values make the columns, a second path's the rows;
    values may be given as text, ``"0:0.2:0.1"`` or ``"a,b,c"``) and lay the images out in a
    labelled sheet. ``cancel`` stops after the tiles in flight: the sheet then holds the
    cells rendered (``complete`` False). One-line :class:`~whitted.SceneError` for a path or
    value that does not fit the scene, too many cells or a sheet too large, before any
    rendering."""
    from ..render.api import RenderJob
    from .sweep import cell_size_bounds, check_sheet_size, contact_sheet, sweep_cells

    started = time.perf_counter()
    swept = _axes(axes)
    cells = sweep_cells(scene, swept)
    ncols = sheet_columns(cells, columns)
    widths, heights = cell_size_bounds(cells)
    if ncols != cells.columns:
        widths = [max(widths)] * ncols
        heights = [heights[0]] * math.ceil(len(cells) / ncols)
    check_sheet_size(widths, heights, title != "")
    images: list[Image] = []
    labels: list[str] = []
    complete = True
    for cell in cells:
        if cancel is not None and cancel.cancelled:
            complete = False
            break
        still = cell.scene
        if still.is_animated:
            still = still.at_frame(0)
        if progress is not None:
            progress(SweepProgress(cell, len(images), len(cells)))
        tiles = None if progress is None else (
            lambda p, c=cell: progress(SweepProgress(c, len(images), len(cells), p)))
        job = RenderJob(still, progress=tiles, cancel=cancel, threads=threads)
        image = job.run()
        if job.cancelled:
            complete = False
            break
        images.append(image)
        labels.append(cell.label)
    if not images:
        raise RenderCancelled("the sweep was stopped before its first image was finished")
    heading = title if title is not None else " / ".join(path for path, _ in swept)
    sheet = contact_sheet([im.to_srgb8() for im in images], labels, ncols, heading or None)
    return ContactSheet(sheet, images, labels, cells.axes, complete,
                        time.perf_counter() - started)
