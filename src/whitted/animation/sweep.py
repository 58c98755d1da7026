"""Parameter sweeps: one image per value of one or two scene values, and a contact sheet.

A sweep is a list of ``(path, values)``: each value of the first path makes a column, each
value of the second (if any) a row; every combination is one *cell*, a plain scene rendered
like any other (with :func:`~whitted.animation.frames.render_frame`, so cells already on disk
from the same scene and settings are kept). :func:`contact_sheet` lays the images out in a
grid with a label under each and a title above.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from ..errors import SceneError, shorten
from ..scene.paths import PathError, parse_path
from .overrides import apply_overrides

if TYPE_CHECKING:
    from ..scene.scene import Scene

__all__ = ["MAX_CELLS", "MAX_SHEET_PIXELS", "SweepCell", "SweepCells", "cell_size_bounds",
           "check_sheet_size", "contact_sheet", "format_value", "sheet_layout", "short_name",
           "sweep_cells"]

MAX_AXES = 2
#: The most cells (images) one sweep may have: the product of its axes' value counts. It is
#: checked before any cell is made (each axis may have up to 10,000 values: two such axes
#: would be 10^8 scenes).
MAX_CELLS = 10_000
#: The most pixels a contact sheet may have: the limit of any image (``render.width x
#: render.height``), 100 megapixels.
MAX_SHEET_PIXELS = 100_000_000
#: The longest label (and title) a sheet shows; longer ones are cut in the middle.
LABEL_LIMIT = 60


@dataclass
class SweepCell:
    """One combination of values: ``row``/``column`` in the grid and the scene to render
    (made when first asked for: a sweep builds one cell's scene at a time)."""

    index: int
    row: int
    column: int
    values: tuple[tuple[str, Any], ...]  # (path, value) of each swept path
    base: Scene = field(repr=False)

    @cached_property
    def scene(self) -> Scene:
        """The scene with this cell's values set (SceneError, one line, when they do not
        fit it together)."""
        return apply_overrides(self.base, list(self.values))

    @property
    def label(self) -> str:
        return ", ".join(f"{short_name(p)} = {format_value(v)}" for p, v in self.values)


class SweepCells(Sequence[SweepCell]):
    """The cells of a sweep, made one at a time when asked for (``cells[k]``, iteration):
    counting them costs nothing, holding them holds only the axes."""

    def __init__(self, scene: Scene, axes: Sequence[tuple[str, Sequence[Any]]]) -> None:
        self.scene = scene
        self.axes = [(path, list(values)) for path, values in axes]
        self.columns = len(self.axes[0][1])
        self.rows = len(self.axes[1][1]) if len(self.axes) == 2 else 1
        #: per axis, per value: (width, height) of the scene with that value alone set
        self.value_sizes: list[list[tuple[int, int]]] = []

    def __len__(self) -> int:
        return self.columns * self.rows

    def axis_scenes(self) -> Iterator[Scene]:
        """The scene with each value of each axis set alone, one at a time (the files a
        swept value names are among theirs)."""
        for path, values in self.axes:
            for value in values:
                yield apply_overrides(self.scene, [(path, value)])

    @overload
    def __getitem__(self, index: int) -> SweepCell: ...

    @overload
    def __getitem__(self, index: slice) -> list[SweepCell]: ...

    def __getitem__(self, index: int | slice) -> SweepCell | list[SweepCell]:
        if isinstance(index, slice):
            return [self[k] for k in range(*index.indices(len(self)))]
        n = len(self)
        if index < 0:
            index += n
        if not 0 <= index < n:
            raise IndexError(f"cell {index} of {n}")
        r, c = divmod(index, self.columns)
        values = [(self.axes[0][0], self.axes[0][1][c])]
        if len(self.axes) == 2:
            values.append((self.axes[1][0], self.axes[1][1][r]))
        return SweepCell(index, r, c, tuple(values), self.scene)


def format_value(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    return str(value)


def short_name(path: str) -> str:
    """The last name of a path: ``kt`` for ``objects[glass sphere].material.kt``."""
    try:
        steps = parse_path(path)
    except PathError:
        return path
    named = [s.key for s in steps if isinstance(s.key, str) and not s.item]
    return str(named[-1]) if named else path


def sweep_cells(scene: Scene, axes: Sequence[tuple[str, Sequence[Any]]]) -> SweepCells:
    """Every combination of the axes' values applied to ``scene`` (first axis: columns,
    second: rows), as a sequence that makes each cell's scene when it is asked for.

    Before anything is made, the cells are counted (SceneError over :data:`MAX_CELLS`), and
    each value of each axis is set alone on ``scene`` (SceneError, one line, for a path or a
    value that does not fit it): one check per value, not one per combination."""
    if not axes:
        raise SceneError("nothing to sweep: give a --set with several values "
                         "(START:STOP:STEP or a,b,c)", where="--set")
    if len(axes) > MAX_AXES:
        raise SceneError(f"at most {MAX_AXES} values can be swept at once, got {len(axes)}",
                         where="--set")
    counts = [len(values) for _, values in axes]
    if any(n == 0 for n in counts):
        raise SceneError("an axis of the sweep has no values", where="--set")
    total = math.prod(counts)
    if total > MAX_CELLS:
        shape = " x ".join(str(n) for n in counts)
        raise SceneError(f"the sweep has {shape} = {total} cells (at most {MAX_CELLS})",
                         where="--set")
    cells = SweepCells(scene, axes)
    base = (scene.render.width, scene.render.height)
    for path, values in cells.axes:
        sizes = []
        for value in values:
            render = apply_overrides(scene, [(path, value)]).render
            sizes.append((max(base[0], render.width), max(base[1], render.height)))
        cells.value_sizes.append(sizes)
    return cells


def cell_size_bounds(cells: SweepCells) -> tuple[list[int], list[int]]:
    """An upper bound of each column's width and each row's height in pixels, from the
    scenes of each axis value alone (a cell's size is its scene's ``render`` size)."""
    base = (cells.scene.render.width, cells.scene.render.height)
    columns = cells.value_sizes[0]
    rows = cells.value_sizes[1] if len(cells.value_sizes) == 2 else [base]
    widest_row = max(w for w, _ in rows)
    tallest_column = max(h for _, h in columns)
    return [max(w, widest_row) for w, _ in columns], [max(h, tallest_column) for _, h in rows]


@dataclass(frozen=True)
class SheetLayout:
    """Where each cell of a contact sheet goes: column ``c`` starts at ``x[c]`` and is
    ``widths[c]`` wide (its widest image), row ``r`` starts at ``y[r]`` and is ``heights[r]``
    high (its tallest image) with a label band of ``label_h`` under it."""

    x: list[int]
    y: list[int]
    widths: list[int]
    heights: list[int]
    width: int
    height: int
    font_size: int
    label_h: int
    title_h: int


def font_size(widths: Sequence[int]) -> int:
    """The labels' font size for cells of these widths (11 to 24 pixels)."""
    return max(11, min(24, min(widths) // 14))


def sheet_layout(widths: Sequence[int], heights: Sequence[int], title: bool = False,
                 gap: int = 6, size: int | None = None) -> SheetLayout:
    """The layout of a grid of columns ``widths`` wide and rows ``heights`` high, labels in
    a font of ``size`` pixels (default :func:`font_size` of the widths)."""
    size = font_size(widths) if size is None else size
    label_h = size + 2 * gap
    title_h = size + 3 * gap if title else 0
    x, at = [], gap
    for w in widths:
        x.append(at)
        at += w + gap
    sheet_w = at
    y, at = [], title_h + gap
    for h in heights:
        y.append(at)
        at += h + label_h
    return SheetLayout(x, y, list(widths), list(heights), sheet_w, at, size,
                       label_h, title_h)


def check_sheet_size(widths: Sequence[int], heights: Sequence[int], title: bool = False,
                     gap: int = 6) -> None:
    """SceneError (one line) when the sheet of this grid would be over
    :data:`MAX_SHEET_PIXELS`; call it with :func:`cell_size_bounds` before rendering."""
    layout = sheet_layout(widths, heights, title, gap)
    if layout.width * layout.height > MAX_SHEET_PIXELS:
        raise SceneError(f"the contact sheet would be about {layout.width}x{layout.height} "
                         f"pixels, over {MAX_SHEET_PIXELS // 1_000_000} megapixels: sweep "
                         "fewer values or make the cells smaller (--width, --height)",
                         where="--set")


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: the small bitmap font
        return ImageFont.load_default()


def contact_sheet(images: Sequence[np.ndarray], labels: Sequence[str], columns: int,
                  title: str | None = None, gap: int = 6) -> np.ndarray:
    """A grid of the (H, W, 3) uint8 ``images``, ``columns`` wide, each with its label
    centred underneath and ``title`` above all: an (H', W', 3) uint8 image. Images may
    differ in size (a sweep of ``render.width``): each column is as wide as its widest image,
    each row as high as its tallest, and each image sits centred at the top of its place."""
    from PIL import Image as PILImage
    from PIL import ImageDraw

    if not images:
        raise ValueError("no images")
    columns = max(1, min(columns, len(images)))
    rows = math.ceil(len(images) / columns)
    widths, heights = [0] * columns, [0] * rows
    for k, image in enumerate(images):
        r, c = divmod(k, columns)
        widths[c] = max(widths[c], image.shape[1])
        heights[r] = max(heights[r], image.shape[0])
    size = font_size(widths)
    font = _font(size)
    labels = [shorten(label, LABEL_LIMIT) for label in labels]
    for k, label in enumerate(labels):  # a column is as wide as its longest label too
        c = k % columns
        widths[c] = max(widths[c], math.ceil(draw_length(font, label)) + gap)
    layout = sheet_layout(widths, heights, bool(title), gap, size)
    sheet_w = layout.width
    if title:
        title = shorten(title, LABEL_LIMIT)
        sheet_w = max(sheet_w, math.ceil(draw_length(font, title)) + 2 * gap)
    left = (sheet_w - layout.width) // 2  # the grid centred under a wider title
    sheet = PILImage.new("RGB", (sheet_w, layout.height), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((sheet_w / 2, gap + size / 2 + gap / 2), title, fill=(0, 0, 0), font=font,
                  anchor="mm")
    for k, (image, label) in enumerate(zip(images, labels, strict=True)):
        r, c = divmod(k, columns)
        h, w = image.shape[:2]
        x = left + layout.x[c] + (widths[c] - w) // 2
        sheet.paste(PILImage.fromarray(image), (x, layout.y[r]))
        draw.text((left + layout.x[c] + widths[c] / 2,
                   layout.y[r] + heights[r] + layout.label_h / 2),
                  label, fill=(0, 0, 0), font=font, anchor="mm")
    return np.asarray(sheet)


def draw_length(font, text: str) -> float:
    """The width in pixels of ``text`` in ``font``."""
    try:
        return float(font.getlength(text))
    except AttributeError:  # Pillow's old bitmap font
        return float(font.getsize(text)[0])
