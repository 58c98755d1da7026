"""Reading and writing scene files (TOML or JSON, one schema) with one-line errors."""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path
from typing import Any

import tomli_w
from pydantic import ValidationError

from ..errors import SceneError
from .scene import Scene

SCENE_SUFFIXES = (".toml", ".json")

# Names pydantic puts into an error location for union members; they are not scene keys.
_UNION_TAGS = {"str", "int", "float", "bool", "Material", "Transform", "Gradient", "AxisAngle"}
_SHAPE_AND_LIGHT_TAGS = {
    "sphere", "plane", "rectangle", "disk", "triangle", "box", "cylinder", "cone",
    "ambient", "point", "directional",
}


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file. Raises :class:`SceneError` with file, key path and line."""
    path = Path(path)
    name = str(path)
    if path.suffix.lower() not in SCENE_SUFFIXES:
        raise SceneError(f"unknown scene format {path.suffix!r} (use .toml or .json)", file=name)
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise SceneError("no such file", file=name) from None
    except IsADirectoryError:
        raise SceneError("is a directory, not a scene file", file=name) from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"not UTF-8 text (byte {exc.start})", file=name) from None
    except OSError as exc:
        raise SceneError(f"cannot read: {exc.strerror}", file=name) from None
    data = parse_scene_text(text, path.suffix.lower(), name)
    return scene_from_dict(data, file=name, text=text)


def parse_scene_text(text: str, suffix: str, name: str | None = None) -> dict[str, Any]:
    if suffix == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SceneError(f"malformed JSON: {exc.msg}", file=name, line=exc.lineno) from None
        if not isinstance(data, dict):
            raise SceneError("the top level must be an object", file=name)
        return data
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = re.search(r"\(at line (\d+), column \d+\)", msg)
        line = int(m.group(1)) if m else None
        msg = re.sub(r"\s*\(at line \d+, column \d+\)", "", msg)
        raise SceneError(f"malformed TOML: {msg}", file=name, line=line) from None


def scene_from_dict(data: dict[str, Any], *, file: str | None = None, text: str | None = None):
    try:
        return Scene.model_validate(data)
    except ValidationError as exc:
        raise _scene_error(exc, file, text) from None


def _scene_error(exc: ValidationError, file: str | None, text: str | None) -> SceneError:
    errors = exc.errors()
    # Unions report one error per member; the deepest location is the informative one.
    best = max(errors, key=lambda e: len(e["loc"]))
    keys = _clean_loc(best["loc"])
    message = _clean_message(best)
    where = _format_path(keys)
    m = re.match(r"^((?:objects|lights)\[\d+\](?:\.\w+)*): (.*)$", message)
    if not keys and m:
        where, message = m.group(1), m.group(2)
        keys = _parse_path(where)
    line = _toml_line(text, keys) if text is not None and file and file.endswith(".toml") else None
    return SceneError(message, file=file, where=where or None, line=line)


def _clean_loc(loc: tuple[Any, ...]) -> list[str | int]:
    out: list[str | int] = []
    for i, item in enumerate(loc):
        if isinstance(item, str):
            if item in _UNION_TAGS or "[" in item or "-" in item:
                continue
            # the discriminator tag pydantic inserts after objects[i] / lights[i]
            if item in _SHAPE_AND_LIGHT_TAGS and i >= 1 and isinstance(loc[i - 1], int):
                continue
        out.append(item)
    return out


def _clean_message(error: dict[str, Any]) -> str:
    kind, msg = error["type"], error["msg"]
    if kind == "extra_forbidden":
        return "unknown key"
    if kind == "missing":
        return "missing required value"
    if kind == "union_tag_invalid":
        tag = error.get("input", {}).get("type") if isinstance(error.get("input"), dict) else None
        expected = error.get("ctx", {}).get("expected_tags", "")
        return f"unknown type {tag!r} (expected one of {expected})"
    if kind == "union_tag_not_found":
        return "missing 'type'"
    msg = re.sub(r"^(Value error|Assertion failed), ", "", msg)
    msg = msg[0].lower() + msg[1:] if msg else msg
    if "input" in error and kind not in ("model_type", "dict_type") and _short(error["input"]):
        msg += f" (got {error['input']!r})"
    return msg


def _short(value: Any) -> bool:
    return isinstance(value, int | float | str | bool) and len(repr(value)) <= 40


def _format_path(keys: list[str | int]) -> str:
    out = ""
    for k in keys:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out


def _parse_path(where: str) -> list[str | int]:
    keys: list[str | int] = []
    for name, index in re.findall(r"(\w+)|\[(\d+)\]", where):
        keys.append(int(index) if index else name)
    return keys


def _toml_line(text: str, keys: list[str | int]) -> int | None:
    """Best-effort line of a key path in TOML text written with ``[table]``/``[[array]]``
    headers (the usual style). Returns None when the key cannot be placed."""
    if not keys:
        return None
    lines = text.splitlines()
    header_re = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
    # Locate the section: `[[objects]]` n-th occurrence, or `[render]`, `[materials.x]`, ...
    section_start, rest = None, keys
    if len(keys) >= 2 and isinstance(keys[1], int):
        count = -1
        for i, raw in enumerate(lines):
            m = header_re.match(raw)
            if m and m.group(1) == "[[" and m.group(2) == keys[0]:
                count += 1
                if count == keys[1]:
                    section_start, rest = i, keys[2:]
                    break
    else:
        for depth in range(len(keys), 0, -1):
            dotted = ".".join(str(k) for k in keys[:depth])
            for i, raw in enumerate(lines):
                m = header_re.match(raw)
                if m and m.group(1) == "[" and m.group(2) == dotted:
                    section_start, rest = i, keys[depth:]
                    break
            if section_start is not None:
                break
    if section_start is None:
        return None
    if not rest or not isinstance(rest[0], str):
        return section_start + 1
    key_re = re.compile(rf"^\s*{re.escape(rest[0])}\s*=")
    for i in range(section_start + 1, len(lines)):
        if header_re.match(lines[i]):
            break
        if key_re.match(lines[i]):
            return i + 1
    return section_start + 1


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    return scene.model_dump(mode="json", exclude_none=True)


def save_scene(scene: Scene, path: str | Path) -> Path:
    from ..output.encode import atomic_write

    path = Path(path)
    suffix = path.suffix.lower()
    data = scene_to_dict(scene)
    if suffix == ".toml":
        payload = tomli_w.dumps(data).encode()
    elif suffix == ".json":
        payload = (json.dumps(data, indent=2) + "\n").encode()
    else:
        raise SceneError(
            f"unknown scene format {path.suffix!r} (use .toml or .json)", file=str(path)
        )

    def write(tmp: str) -> None:
        Path(tmp).write_bytes(payload)

    atomic_write(path, write)
    return path
