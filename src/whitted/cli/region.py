"""``--region X0:X1,Y0:Y1``: the part of the picture ``whitted render`` renders (POV-Ray's
``+SC +EC +SR +ER``), into a full-size image whose other pixels stay black (and transparent
with ``--alpha``). Whole numbers are pixels, 0-based, the end excluded (``0:320,0:240`` is
the top-left 320x240); numbers with a point are fractions of the width and height
(``0.25:0.75,0.25:0.75`` is the middle quarter); an empty end is the image's edge
(``:,0:0.5`` is the top half)."""

from __future__ import annotations

import math

from ..errors import shorten

__all__ = ["parse_region"]


def _ends(text: str, size: int, axis: str, whole: str) -> tuple[int, int]:
    pieces = text.split(":")
    if len(pieces) != 2:
        raise ValueError(f"expected {axis}0:{axis}1 (got {shorten(text)!r})")
    fractions = any(("." in p or "e" in p.lower()) for p in pieces)
    ends = []
    for k, piece in enumerate(p.strip() for p in pieces):
        if not piece:
            ends.append(0 if k == 0 else size)
            continue
        try:
            value = float(piece) if fractions else int(piece)
        except ValueError:
            raise ValueError(f"{piece!r} is not a number") from None
        if not math.isfinite(value):
            raise ValueError(f"{piece!r} is not a finite number")
        if fractions:
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"the fraction {piece} is not between 0 and 1")
            value = round(value * size)
        elif not 0 <= value <= size:
            raise ValueError(f"{axis} = {piece} is outside the image (0 to {size} {whole})")
        ends.append(int(value))
    if ends[0] >= ends[1]:
        raise ValueError(f"{axis}0:{axis}1 = {ends[0]}:{ends[1]} holds no pixels (the end is "
                         "excluded)")
    return ends[0], ends[1]


def parse_region(text: str, width: int, height: int) -> tuple[int, int, int, int]:
    """``"X0:X1,Y0:Y1"`` -> the pixels (x0, y0, x1, y1), ends excluded; ValueError (a
    sentence without the option's name) when it is malformed or outside the image."""
    parts = text.split(",")
    if len(parts) != 2:
        raise ValueError(f"expected X0:X1,Y0:Y1 such as 0:320,0:240 or 0.25:0.75,0:1 "
                         f"(got {shorten(text)!r})")
    x0, x1 = _ends(parts[0], width, "x", "columns")
    y0, y1 = _ends(parts[1], height, "y", "rows")
    return x0, y0, x1, y1
