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
import tomllib
from typing import TYPE_CHECKING, Any

from ..errors import SceneError
from ..scene.paths import PathError, parse_path, resolve_path, set_value

if TYPE_CHECKING:
    from ..scene.scene import Scene

__all__ = ["apply_overrides", "parse_assignment", "parse_value", "parse_values"]


def parse_value(text: str) -> Any:
    """A TOML value (``0.5``, ``[1, 2, 3]``, ``"x"``, ``{a = 1}``), else the text itself."""
    text = text.strip()
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_assignment(text: str) -> tuple[str, str]:
    """``"PATH=VALUE"`` -> (PATH, VALUE text). SceneError when there is no ``=``."""
    depth = 0
    for i, ch in enumerate(text):
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        elif ch == "=" and depth == 0:
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


def parse_values(text: str) -> list[Any]:
    """The values of a sweep: ``START:STOP:STEP`` or ``a,b,c`` (each a TOML value)."""
    pieces = text.split(":")
    if len(pieces) in (2, 3) and not text.strip().startswith(("[", "{", '"', "'")):
        try:
            nums = [float(p) for p in pieces]
        except ValueError:
            nums = None
        if nums is not None:
            start, stop = nums[0], nums[1]
            step = nums[2] if len(nums) == 3 else (1.0 if stop >= start else -1.0)
            if step == 0 or not all(math.isfinite(v) for v in nums):
                raise SceneError(f"range {text!r}: the step must be a non-zero number",
                                 where="--set")
            if (stop - start) * step < 0:
                raise SceneError(f"range {text!r}: the step {step:g} goes away from {stop:g}",
                                 where="--set")
            count = math.floor((stop - start) / step + 1e-9) + 1
            if count > 10_000:
                raise SceneError(f"range {text!r} has {count} values (at most 10000)",
                                 where="--set")
            whole = all(float(p).is_integer() and "." not in p for p in pieces)
            values = [round(start + k * step, 10) for k in range(count)]
            return [int(v) for v in values] if whole else [v + 0.0 for v in values]
    return [parse_value(p) for p in _split_top_level(text)]


def apply_overrides(scene: Scene, assignments: list[tuple[str, Any]] | dict[str, Any]) -> Scene:
    """A copy of ``scene`` with each ``(path, value)`` set (values already parsed; text is
    parsed with :func:`parse_value`). Tracks on an overridden value are dropped. SceneError
    (one line, ``--set PATH: problem``) when a path names nothing or a value is rejected."""
    items = list(assignments.items()) if isinstance(assignments, dict) else list(assignments)
    for path, value in items:
        if isinstance(value, str):
            value = parse_value(value)
        try:
            written = parse_path(path)
            steps = resolve_path(scene, written)
            new = set_value(scene, written, value)  # errors name the path as written
        except PathError as exc:
            raise SceneError(str(exc), where="--set") from None
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
