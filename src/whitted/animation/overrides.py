"""``--set PATH=VALUE``: replace any scene value from the command line (or from Python).

``VALUE`` is written as in a TOML file (``0.5``, ``[0, 2, 9]``, ``"glass"``, ``true``,
``{ top = "#336699", bottom = "#ffffff" }``); a bare word that is not TOML is taken as text
(``--set render.tonemap=aces``). The path is the same as a track's
(:mod:`whitted.scene.paths`). An override applies to the scene before its frames are
made; a track animating the same value is dropped (the command line wins).

For sweeps, :func:`parse_values` reads several values: a range ``START:STOP:STEP`` (STOP
included when the steps land on it: ``1:0:-0.2`` is 1, 0.8, 0.6, 0.4, 0.2, 0) or a list
``a,b,c`` of TOML values.
"""

from __future__ import annotations

import math
import sys
import tomllib
from typing import TYPE_CHECKING, Any

from ..errors import SceneError, shorten
from ..scene.io import check_value_numbers
from ..scene.paths import PathError, parse_path, resolve_path, set_value

if TYPE_CHECKING:
    from ..scene.scene import Scene

__all__ = ["MAX_VALUES", "apply_overrides", "is_range", "parse_assignment", "parse_value",
           "parse_values"]


def parse_value(text: str) -> Any:
    """A TOML value (``0.5``, ``[1, 2, 3]``, ``"x"``, ``{a = 1}``), else the text itself."""
    text = text.strip()
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_assignment(text: str) -> tuple[str, str]:
    """``"PATH=VALUE"`` -> (PATH, VALUE text). SceneError when there is no ``=``. The ``=``
    is the first one outside the path's brackets and the quotes in them
    (``objects["a=b]"].radius=0.2``), as the path reader (:func:`parse_path`) reads them."""
    depth, quote = 0, ""
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'" and depth > 0 and text[:i].rstrip().endswith("["):
            quote = ch  # a quoted name: brackets and '=' in it are part of the name
        elif ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        elif ch == "=" and depth <= 0:
            path, value = text[:i].strip(), text[i + 1:].strip()
            if not path:
                break
            if not value:
                raise SceneError(f"no value after '=' in {text!r}", where="--set")
            return path, value
    raise SceneError(f"expected PATH=VALUE, got {text!r}", where="--set")


def _split_top_level(text: str) -> list[str]:
    """Split at commas outside brackets, braces and quotes."""
    parts, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


#: The most values one range or list of a sweep may have.
MAX_VALUES = 10_000


def _range_pieces(text: str) -> list[str] | None:
    """The numbers of ``START:STOP`` or ``START:STOP:STEP`` as text, or None when ``text``
    is not written as a range."""
    pieces = [p.strip() for p in text.split(":")]
    if len(pieces) not in (2, 3) or text.strip().startswith(("[", "{", '"', "'")):
        return None
    try:
        for p in pieces:
            float(p)
    except ValueError:
        return None
    return pieces


def is_range(text: str) -> bool:
    """Whether ``text`` is written as a range of a sweep (``1:0:-0.2``, ``1:1:0.1``)."""
    return _range_pieces(text) is not None


def _whole(piece: str) -> int | None:
    try:
        return int(piece)  # exact, however large (no float rounding)
    except ValueError:
        return None


def _range_values(text: str, pieces: list[str]) -> list[Any]:
    where = f"range {shorten(text)!r}"
    whole = [_whole(p) for p in pieces]
    if all(w is not None for w in whole):  # whole numbers: exact integer steps
        start, stop = whole[0], whole[1]
        step = whole[2] if len(whole) == 3 else (1 if stop >= start else -1)
        if step == 0:
            raise SceneError(f"{where}: the step must not be 0", where="--set")
        if (stop - start) * step < 0:
            raise SceneError(f"{where}: the step {step} goes away from {shorten(str(stop))}",
                             where="--set")
        count = (stop - start) // step + 1
        _check_count(where, count)
        return [start + k * step for k in range(count)]
    nums = [float(p) for p in pieces]
    if not all(math.isfinite(v) for v in nums):
        raise SceneError(f"{where}: START, STOP and STEP must be finite numbers", where="--set")
    start, stop = nums[0], nums[1]
    step = nums[2] if len(nums) == 3 else (1.0 if stop >= start else -1.0)
    if step == 0:
        raise SceneError(f"{where}: the step must not be 0", where="--set")
    span = (stop - start) / step  # may overflow to infinity: then far too many values
    if span < 0:
        raise SceneError(f"{where}: the step {step:g} goes away from {stop:g}", where="--set")
    if not math.isfinite(span) or span >= MAX_VALUES:
        _check_count(where, math.inf if not math.isfinite(span) else math.floor(span) + 1)
    count = math.floor(span + 1e-9) + 1
    _check_count(where, count)
    values = [start]
    for k in range(1, count):
        v = start + k * step
        # 0.1 * 3 is 0.30000000000000004 and 1 - 5 * 0.2 may be 5e-17: within the rounding
        # of the sum, take the shortest number (0.3, 0) instead
        noise = 4 * sys.float_info.epsilon * (abs(start) + abs(k * step))
        short = float(f"{v:.12g}")
        values.append(0.0 if abs(v) <= noise else short if abs(short - v) <= noise else v)
    return values


def _check_count(where: str, count: float) -> None:
    if count > MAX_VALUES:
        shown = f"{count:.3g}" if count >= 1e6 else f"{count}"
        raise SceneError(f"{where} has {shown} values (at most {MAX_VALUES})", where="--set")


def parse_values(text: str) -> list[Any]:
    """The values of a sweep: ``START:STOP:STEP`` (STOP included when a step lands on it,
    as near as 1e-9 of a step; whole numbers stay whole and exact) or ``a,b,c`` (each a TOML
    value). SceneError (one line) for a range with a zero or wrong-way step, numbers that
    are not finite, or more than :data:`MAX_VALUES` values."""
    pieces = _range_pieces(text)
    if pieces is not None:
        return _range_values(text, pieces)
    values = [parse_value(p) for p in _split_top_level(text)]
    if len(values) > MAX_VALUES:
        raise SceneError(f"the list {shorten(text)!r} has {len(values)} values (at most "
                         f"{MAX_VALUES})", where="--set")
    return values


def apply_overrides(scene: Scene, assignments: list[tuple[str, Any]] | dict[str, Any]) -> Scene:
    """A copy of ``scene`` with each ``(path, value)`` set (values already parsed; text is
    parsed with :func:`parse_value`). Tracks on an overridden value are dropped. SceneError
    (one line, ``--set PATH: problem``) when a path names nothing or a value is rejected."""
    items = list(assignments.items()) if isinstance(assignments, dict) else list(assignments)
    for path, value in items:
        text = value if isinstance(value, str) else None
        if text is not None:
            value = parse_value(text)
        try:
            written = parse_path(path)
            steps = resolve_path(scene, written)
            check_value_numbers(value, [step.key for step in steps])
            new = set_value(scene, written, value, strict=True)  # as a file's value
        except SceneError as exc:  # a number too large, as in a file
            if not isinstance(exc, PathError):
                raise SceneError(str(exc), where="--set") from None
            hint = ("; a range START:STOP:STEP is for whitted sweep, here give one value"
                    if text is not None and is_range(text) else "")
            raise SceneError(f"{exc}{hint}", where="--set") from None
        if scene.animation is not None:
            kept = []
            for track in scene.animation.tracks:
                try:
                    same = resolve_path(scene, parse_path(track.path)) == steps
                except PathError:
                    same = False
                if not same:
                    kept.append(track)
            if len(kept) != len(scene.animation.tracks):
                animation = scene.animation.model_copy(update={"tracks": kept})
                new = new.model_copy(update={"animation": animation})
        scene = new
    if scene.animation is not None:
        from ..scene.timeline import check_animation

        try:
            check_animation(scene)
        except ValueError as exc:
            raise SceneError(f"after --set: {exc}") from None
    return scene
