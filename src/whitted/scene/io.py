"""Reading scene files (TOML or JSON, one schema) with one-line errors; writing them is
:mod:`.writing`."""

from __future__ import annotations

import codecs
import json
import math
import os
import re
import tomllib
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ..errors import ArgumentError, SceneError, shorten
from ..files import path_problem, read_limited
from .file_names import named_files
from .messages import format_path, json_line, scene_error, toml_line
from .scene import Scene
from .types import MAX_MAGNITUDE

SCENE_SUFFIXES = (".toml", ".json")


#: The largest scene file read (scenes with inline meshes can be large, but not this).
MAX_SCENE_BYTES = 256 << 20
#: Deepest nesting of tables and lists a scene file may use (the schema needs about 8).
MAX_NESTING = 64


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file. Raises :class:`SceneError` with file, key path and line."""
    if not isinstance(path, str | os.PathLike):
        raise ArgumentError(f"load_scene needs the path of a scene file, got "
                            f"{type(path).__name__}")
    path = Path(path)
    name = str(path)
    # Existence first: "no such file" is more useful than "unknown format" for a typo'd path.
    problem = path_problem(path)
    if problem is not None:
        raise SceneError(problem, file=name)
    if path.suffix.lower() not in SCENE_SUFFIXES:
        raise SceneError(f"unknown scene format {shorten(path.suffix)!r} (use .toml or .json)",
                         file=name)
    raw = read_limited(path, MAX_SCENE_BYTES, "scene file")
    if raw.startswith(codecs.BOM_UTF8):  # some editors write one; TOML and JSON do not want it
        raw = raw[len(codecs.BOM_UTF8):]
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise SceneError(f"not UTF-8 text (byte {exc.start})", file=name, line=line) from None
    data = parse_scene_text(text, path.suffix.lower(), name)
    scene = scene_from_dict(data, file=name, text=text).with_base_dir(path.parent)
    _check_files(scene, name, text, data)
    return scene


def _check_files(scene: Scene, name: str | None, text: str | None, data: Any) -> None:
    """Every model and texture file the scene names exists (read later, when compiled)."""
    named = named_files(scene)
    for keys, file in named:
        try:
            target = scene.resolve_path(file)
            problem = path_problem(target)
        except (OSError, RuntimeError, ValueError) as exc:
            target, problem = Path(file), f"unusable file name ({exc})"
        if problem is not None:
            line = None
            if text is not None:
                line = (json_line(text, keys, data) if name and name.endswith(".json")
                        else toml_line(text, keys))
            raise SceneError(f"{problem}: {shorten(file)!r} (looked in "
                             f"{shorten(str(target.parent))})", file=name,
                             where=format_path(keys), line=line)


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """JSON object hook: a key given twice is an error (TOML rejects it too)."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


class _DuplicateKey(ValueError):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _json_big_int(text: str) -> int:
    if len(text.lstrip("-")) > 30:  # far beyond any value a scene holds
        raise ValueError(f"number {shorten(text, 24)} is too large")
    return int(text)


def _line_of_offset(text: str, offset: int) -> int:
    return text.count("\n", 0, max(0, offset)) + 1


def parse_scene_text(text: str, suffix: str, name: str | None = None) -> dict[str, Any]:
    if text.startswith("\ufeff"):
        text = text[1:]
    _check_nesting(text, name)
    if suffix == ".json":
        try:
            data = json.loads(text, object_pairs_hook=_unique_keys, parse_int=_json_big_int)
        except json.JSONDecodeError as exc:
            raise SceneError(f"malformed JSON: {exc.msg}", file=name, line=exc.lineno) from None
        except _DuplicateKey as exc:
            line = _json_key_line(text, exc.key)
            raise SceneError(f"duplicate key {shorten(exc.key)!r}", file=name,
                             line=line) from None
        except (ValueError, RecursionError) as exc:
            raise SceneError(f"malformed JSON: {shorten(str(exc), 120)}", file=name) from None
        if not isinstance(data, dict):
            raise SceneError("the top level must be an object", file=name)
    else:
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            msg = str(exc)
            m = re.search(r"\(at line (\d+), column \d+\)", msg)
            line = int(m.group(1)) if m else None
            if line is None and "end of document" in msg:
                line = max(1, text.count("\n") + (0 if text.endswith("\n") else 1))
                msg = re.sub(r"\s*\(at end of document\)", "", msg)
                msg += " (the file ends early: is it cut off?)"
            msg = re.sub(r"\s*\(at line \d+, column \d+\)", "", msg)
            raise SceneError(f"malformed TOML: {msg}", file=name, line=line) from None
        except (ValueError, RecursionError) as exc:
            raise SceneError(f"malformed TOML: {shorten(str(exc), 120)}", file=name) from None
    _check_values(data, [], name, text, suffix)
    return data


def _check_nesting(text: str, name: str | None) -> None:
    """Refuse brackets nested deeper than any scene needs before a parser recurses into them
    (an upper bound: brackets inside strings count too, which only errs on the safe side for
    texts far deeper than :data:`MAX_NESTING`)."""
    depth = 0
    deepest = 0
    for m in re.finditer(r"[\[\]{}]", text):
        depth += 1 if m.group() in "[{" else -1
        if depth > deepest:
            deepest = depth
            if deepest > 4 * MAX_NESTING:
                line = _line_of_offset(text, m.start())
                raise SceneError(f"nested more than {MAX_NESTING} levels deep", file=name,
                                 line=line)


def _check_values(data: Any, keys: list[str | int], name: str | None, text: str,
                  suffix: str, depth: int = 0) -> None:
    """Nesting depth and number sizes: what would overflow later is an error now, at its key."""
    def error(message: str) -> SceneError:
        line = None
        if suffix == ".json":
            line = json_line(text, keys, root)
        elif keys:
            line = toml_line(text, keys)
        return SceneError(message, file=name, where=format_path(keys) or None, line=line)

    root = data
    stack: list[tuple[Any, list[str | int], int]] = [(data, keys, depth)]
    while stack:
        node, keys, depth = stack.pop()
        if depth > MAX_NESTING:
            raise error(f"nested more than {MAX_NESTING} levels deep")
        if isinstance(node, dict):
            stack.extend((v, [*keys, k], depth + 1) for k, v in node.items())
        elif isinstance(node, list):
            if node and all(type(v) in (int, float) for v in node):
                big = [v for v in node if not abs(v) <= MAX_MAGNITUDE]
                if big:
                    k = next(i for i, v in enumerate(node) if not abs(v) <= MAX_MAGNITUDE)
                    keys = [*keys, k]
                    node = node[k]
                else:
                    continue
            else:
                stack.extend((v, [*keys, i], depth + 1) for i, v in enumerate(node))
                continue
        if isinstance(node, float | int) and not isinstance(node, bool):
            if isinstance(node, float) and not math.isfinite(node):
                continue  # the model says "expected a finite number" where it matters
            if abs(node) > MAX_MAGNITUDE:
                shown = shorten(repr(node), 24)
                raise error(f"number {shown} is too large (scene values are limited to "
                            f"{MAX_MAGNITUDE:.0e} in magnitude)")


def check_value_numbers(value: Any, keys: list[str | int]) -> None:
    """What a scene file's reader checks of every number, for one value that lands at
    ``keys`` (a ``--set`` or sweep value): SceneError naming the key (``camera.position[1]:
    number 1e+20 is too large ...``), so that the message is the file's."""
    _check_values(value, list(keys), None, "", ".toml")


def _json_key_line(text: str, key: str) -> int | None:
    pattern = re.compile(rf'"{re.escape(json.dumps(key)[1:-1])}"\s*:')
    hits = [i for i, raw in enumerate(text.splitlines()) if pattern.search(raw)]
    return hits[1] + 1 if len(hits) >= 2 else None


def scene_from_dict(data: dict[str, Any], *, file: str | None = None, text: str | None = None):
    try:
        return Scene.model_validate(data, strict=True)
    except ValidationError as exc:
        raise scene_error(exc, file, text, data, root=Scene) from None


