"""Parameter sweeps: one image per value of one or two scene values, and a contact sheet.

A sweep is a list of ``(path, values)``: each value of the first path makes a column, each
value of the second (if any) a row; every combination is one *cell*, a plain scene rendered
like any other (with :func:`~whitted.animation.frames.render_frame`, so cells already on disk
from the same scene and settings are kept). :func:`contact_sheet` lays the images out in a
grid with a label under each and a title above.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import SceneError
from ..scene.paths import PathError, parse_path
from .overrides import apply_overrides

if TYPE_CHECKING:
    from ..scene.scene import Scene

__all__ = ["SweepCell", "contact_sheet", "format_value", "short_name", "sweep_cells"]

MAX_AXES = 2


@dataclass(frozen=True)
class SweepCell:
    """One combination of values: ``row``/``column`` in the grid and the scene to render."""

    index: int
    row: int
    column: int
    values: tuple[tuple[str, Any], ...]  # (path, value) of each swept path
    scene: Scene

    @property
    def label(self) -> str:
        return ", ".join(f"{short_name(p)} = {format_value(v)}" for p, v in self.values)


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


def sweep_cells(scene: Scene, axes: Sequence[tuple[str, Sequence[Any]]]) -> list[SweepCell]:
    """Every combination of the axes' values applied to ``scene`` (first axis: columns,
    second: rows). SceneError (one line) when a path or a value does not fit the scene."""
    if not axes:
        raise SceneError("nothing to sweep: give a --set with several values "
                         "(START:STOP:STEP or a,b,c)", where="--set")
    if len(axes) > MAX_AXES:
        raise SceneError(f"at most {MAX_AXES} values can be swept at once, got {len(axes)}",
                         where="--set")
    columns = axes[0][1]
    rows = axes[1][1] if len(axes) == 2 else [None]
    cells = []
    for index, (r, c) in enumerate(itertools.product(range(len(rows)), range(len(columns)))):
        values = [(axes[0][0], columns[c])]
        if len(axes) == 2:
            values.append((axes[1][0], rows[r]))
        cells.append(SweepCell(index, r, c, tuple(values), apply_overrides(scene, values)))
    return cells


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: the small bitmap font
        return ImageFont.load_default()


def contact_sheet(images: Sequence[np.ndarray], labels: Sequence[str], columns: int,
                  title: str | None = None, gap: int = 6) -> np.ndarray:
    """A grid of the (H, W, 3) uint8 ``images`` (all one size), ``columns`` wide, each with
    its label centred underneath and ``title`` above all: an (H', W', 3) uint8 image."""
    from PIL import Image as PILImage
    from PIL import ImageDraw

    if not images:
        raise ValueError("no images")
    h, w = images[0].shape[:2]
    columns = max(1, min(columns, len(images)))
    rows = math.ceil(len(images) / columns)
    size = max(11, min(24, w // 14))
    font = _font(size)
    label_h = size + 2 * gap
    title_h = size + 3 * gap if title else 0
    sheet_w = columns * w + (columns + 1) * gap
    sheet_h = title_h + rows * (h + label_h) + gap
    sheet = PILImage.new("RGB", (sheet_w, sheet_h), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((sheet_w / 2, gap + size / 2 + gap / 2), title, fill=(0, 0, 0), font=font,
                  anchor="mm")
    for k, (image, label) in enumerate(zip(images, labels, strict=True)):
        r, c = divmod(k, columns)
        x = gap + c * (w + gap)
        y = title_h + gap + r * (h + label_h)
        sheet.paste(PILImage.fromarray(image), (x, y))
        draw.text((x + w / 2, y + h + label_h / 2), label, fill=(0, 0, 0), font=font,
                  anchor="mm")
    return np.asarray(sheet)
