"""Reading and writing scene files (TOML or JSON, one schema) with one-line errors."""

from __future__ import annotations

import codecs
import difflib
import json
import math
import os
import re
import tomllib
import typing
from pathlib import Path
from typing import Any

import tomli_w
from pydantic import BaseModel, ValidationError

from ..errors import SceneError, shorten
from .materials import Material
from .scene import Scene

SCENE_SUFFIXES = (".toml", ".json")

# Names pydantic puts into an error location for union members; they are not scene keys.
_UNION_TAGS = {"str", "int", "float", "bool", "Material", "Transform", "Gradient", "AxisAngle"}
_SHAPE_AND_LIGHT_TAGS = {
    "sphere", "plane", "rectangle", "disk", "triangle", "box", "cylinder", "cone", "mesh",
    "image", "checker", "gradient",
    "ambient", "point", "directional",
}


#: The largest scene file read (scenes with inline meshes can be large, but not this).
MAX_SCENE_BYTES = 256 << 20
#: Deepest nesting of tables and lists a scene file may use (the schema needs about 8).
MAX_NESTING = 64
#: Largest magnitude of a number in a scene file: beyond it squares and products overflow.
MAX_MAGNITUDE = 1e15


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file. Raises :class:`SceneError` with file, key path and line."""
    from ..assets.files import path_problem, read_limited

    if not isinstance(path, str | os.PathLike):
        from ..errors import ArgumentError

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


def named_files(scene: Scene) -> list[tuple[list[str | int], str]]:
    """(key path, file name) of every model and texture file the scene names."""
    named: list[tuple[list[str | int], str]] = []
    for i, obj in enumerate(scene.objects):
        if getattr(obj, "file", None):
            named.append((["objects", i, "file"], obj.file))
        mat = obj.material
        if isinstance(mat, Material) and getattr(mat.texture, "file", None):
            named.append((["objects", i, "material", "texture", "file"], mat.texture.file))
    for key, mat in scene.materials.items():
        if mat.texture is not None and getattr(mat.texture, "file", None):
            named.append((["materials", key, "texture", "file"], mat.texture.file))
    from ..animation.timeline import is_sequence, sequence_file

    expanded: list[tuple[list[str | int], str]] = []
    for keys, pattern in named:
        if len(keys) == 3 and is_sequence(pattern):  # a mesh sequence: every frame's file
            expanded.extend((keys, sequence_file(pattern, k)) for k in range(scene.frame_count))
        else:
            expanded.append((keys, pattern))
    return expanded


def _check_files(scene: Scene, name: str | None, text: str | None, data: Any) -> None:
    """Every model and texture file the scene names exists (read later, when compiled)."""
    from ..assets.files import path_problem

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
                line = (_json_line(text, keys, data) if name and name.endswith(".json")
                        else _toml_line(text, keys))
            raise SceneError(f"{problem}: {shorten(file)!r} (looked in "
                             f"{shorten(str(target.parent))})", file=name,
                             where=_format_path(keys), line=line)


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
            line = _json_line(text, keys, root)
        elif keys:
            line = _toml_line(text, keys)
        return SceneError(message, file=name, where=_format_path(keys) or None, line=line)

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


def _json_key_line(text: str, key: str) -> int | None:
    pattern = re.compile(rf'"{re.escape(json.dumps(key)[1:-1])}"\s*:')
    hits = [i for i, raw in enumerate(text.splitlines()) if pattern.search(raw)]
    return hits[1] + 1 if len(hits) >= 2 else None


def scene_from_dict(data: dict[str, Any], *, file: str | None = None, text: str | None = None):
    try:
        return Scene.model_validate(data, strict=True)
    except ValidationError as exc:
        raise _scene_error(exc, file, text, data) from None


# pydantic's type-mismatch errors, in words a scene author uses (a table is a JSON object).
_EXPECTED = {
    "string_type": "a string",
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "a whole number",
    "float_type": "a number",
    "float_parsing": "a number",
    "bool_type": "true or false",
    "bool_parsing": "true or false",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "dict_type": "a table",
    "list_type": "a list",
    "tuple_type": "a list",
}


def _priority(error: Any) -> int:
    """Which of several errors at the same depth to report: a misspelt key explains a missing
    one, and a union member's own complaint beats another member's "wrong type"."""
    kind = error["type"]
    if kind == "extra_forbidden":
        return 3
    if kind == "missing":
        return 1
    if kind in _EXPECTED:
        return 0
    return 2


def validation_message(exc: ValidationError) -> str:
    """The most informative problem of a pydantic error, in the scene files' words and without
    its key path (what an editor shows at the field itself)."""
    # unions report one error per member: the deepest one is the informative one
    best = max(exc.errors(), key=lambda e: (len(_clean_loc(e["loc"])), _priority(e)))
    return _clean_message(best)


def describe_validation_error(exc: ValidationError,
                              root: type[BaseModel] | None = None) -> tuple[str, str]:
    """(key path, message) of the most informative problem of ``exc``, as in scene files."""
    e = _scene_error(exc, None, None, None, root=root)
    return e.where or "", e.message


def _scene_error(
    exc: ValidationError, file: str | None, text: str | None, data: Any = None,
    root: type[BaseModel] | None = None,
) -> SceneError:
    errors = exc.errors()
    # Unions report one error per member; the deepest location is the informative one.
    best = max(errors, key=lambda e: (len(_clean_loc(e["loc"])), _priority(e)))
    keys = _clean_loc(best["loc"])
    if best["type"] in _EXPECTED:
        # every member of a union rejected the value's type: name all the accepted kinds
        alternatives = [
            _EXPECTED[e["type"]] for e in errors
            if e["type"] in _EXPECTED and _clean_loc(e["loc"]) == keys
        ]
        message = "expected " + " or ".join(dict.fromkeys(alternatives))
        message += _got(best, message)
    elif best["type"] == "extra_forbidden":
        message = "unknown key" + _known_keys_hint(keys, data, root or Scene)
    else:
        message = _clean_message(best)
    where = _format_path(keys)
    m = re.match(r"^((?:objects|lights)\[\d+\](?:\.\w+)*"
                 r"|animation\.tracks\[\d+\](?:\.\w+)*(?:\[\d+\])?): (.*)$", message)
    if not keys and m:
        where, message = m.group(1), m.group(2)
        keys = _parse_path(where)
    # an unknown shape or light type is best shown on its `type = ...` line
    line_keys = [*keys, "type"] if best["type"] == "union_tag_invalid" else keys
    line = None
    if text is not None and file:
        if file.lower().endswith(".toml"):
            line = _toml_line(text, line_keys)
        elif file.lower().endswith(".json"):
            line = _json_line(text, line_keys, data)
    return SceneError(message, file=file, where=where or None, line=line)


def _clean_loc(loc: tuple[Any, ...]) -> list[str | int]:
    out: list[str | int] = []
    for i, item in enumerate(loc):
        if isinstance(item, str):
            dict_key = i == 1 and loc[0] == "materials"  # a material's own name: keep it
            if not dict_key and (item in _UNION_TAGS or "[" in item or "-" in item):
                continue
            # the discriminator tag pydantic inserts after objects[i] / lights[i]
            if item in _SHAPE_AND_LIGHT_TAGS and i >= 1 and (
                isinstance(loc[i - 1], int) or loc[i - 1] == "texture"
            ):
                continue
        out.append(item)
    return out


def _clean_message(error: dict[str, Any]) -> str:
    kind, msg = error["type"], error["msg"]
    if kind == "missing":
        in_list = bool(error["loc"]) and isinstance(error["loc"][-1], int)
        return "missing list item" if in_list else "missing required value"
    if kind == "union_tag_invalid":
        tag = error.get("input", {}).get("type") if isinstance(error.get("input"), dict) else None
        expected = error.get("ctx", {}).get("expected_tags", "")
        shown = shorten(repr(tag), 40)
        return f"unknown type {shown} (expected one of {expected})"
    if kind == "union_tag_not_found":
        return "missing 'type'"
    if kind in ("too_short", "too_long") and "ctx" in error:
        ctx = error["ctx"]
        bound = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        word = "at least" if kind == "too_short" else "at most"
        return f"expected {word} {bound} items, got {ctx.get('actual_length')}"
    msg = re.sub(r"^(Value error|Assertion failed), ", "", msg)
    msg = msg[0].lower() + msg[1:] if msg else msg
    if kind not in ("model_type", "dict_type"):
        msg += _got(error, msg)
    return msg


def _got(error: dict[str, Any], message: str) -> str:
    """`` (got VALUE)`` for a short offending value that the message does not already show."""
    if "input" not in error or not _short(error["input"]):
        return ""
    shown = repr(error["input"])
    return "" if shown in message else f" (got {shown})"


def _short(value: Any) -> bool:
    return isinstance(value, int | float | str | bool) and len(repr(value)) <= 40


def _known_keys_hint(keys: list[str | int], data: Any, root: type[BaseModel] = Scene) -> str:
    """`` (did you mean 'radius'?)`` for a misspelt key, else the keys that are allowed there."""
    if not keys or not isinstance(keys[-1], str):
        return ""
    known = _allowed_keys(keys[:-1], data, root)
    if not known:
        return ""
    close = (difflib.get_close_matches(keys[-1], known, n=1, cutoff=0.6)
             if len(keys[-1]) <= 100 else [])
    if close:
        return f" (did you mean {close[0]!r}?)"
    if len(known) <= 12:
        return f" (known: {', '.join(known)})"
    return ""


def _allowed_keys(parent: list[str | int], data: Any, root: type[BaseModel] = Scene) -> list[str]:
    """The keys the scene model accepts at ``parent`` (a cleaned location), or [] if unknown."""
    models: list[type[BaseModel]] = [root]
    node = data
    container = False  # the next key indexes a list or names a dict entry
    for key in parent:
        node = _child(node, key)
        if container:
            container = False
            continue
        if not isinstance(key, str):
            return []
        fields = [m.model_fields[key] for m in models if key in m.model_fields]
        if not fields:
            return []
        annotation = fields[0].annotation
        container = typing.get_origin(annotation) in (list, dict)
        models = _models_in(annotation)
    if len(models) > 1 and isinstance(node, dict):  # shapes and lights: pick by their type
        chosen = [m for m in models if "type" in m.model_fields
                  and m.model_fields["type"].default == node.get("type")]
        models = chosen or models
    if len(models) != 1:
        return []
    return list(models[0].model_fields)


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    found: list[type[BaseModel]] = []
    for arg in typing.get_args(annotation):
        found += [m for m in _models_in(arg) if m not in found]
    return found


def _child(node: Any, key: str | int) -> Any:
    if isinstance(node, dict) and isinstance(key, str):
        return node.get(key)
    if isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node):
        return node[key]
    return None


def _format_path(keys: list[str | int]) -> str:
    out = ""
    for k in keys:
        if isinstance(k, int):
            out += f"[{k}]"
            continue
        k = shorten(k)
        name = k if re.fullmatch(r"[A-Za-z_][\w-]*", k) else json.dumps(k)  # "my glass"
        out += f".{name}" if out else name
    return out


def _parse_path(where: str) -> list[str | int]:
    keys: list[str | int] = []
    for name, index in re.findall(r"(\w+)|\[(\d+)\]", where):
        keys.append(int(index) if index else name)
    return keys


_TOML_KEY = r"""(?:[A-Za-z_][\w-]*|"[^"\n]*"|'[^'\n]*')"""  # bare or quoted
_HEADER_RE = re.compile(
    rf"^\s*(\[\[?)\s*({_TOML_KEY}(?:\s*\.\s*{_TOML_KEY})*)\s*\]\]?\s*(?:#.*)?$"
)


def _toml_line(text: str, keys: list[str | int]) -> int | None:
    """Best-effort line of a key path in TOML text written with ``[table]``/``[[array]]``
    headers (the usual style) or top-level keys. Returns None when the key cannot be placed."""
    if not keys:
        return None
    lines = text.splitlines()
    # Each header's place in the data: [[objects]] is objects[n] for its n-th occurrence and a
    # following [objects.transform] belongs to that same element.
    headers: list[tuple[int, list[str | int]]] = []
    counters: dict[tuple[str | int, ...], int] = {}
    for i, raw in enumerate(lines):
        m = _HEADER_RE.match(raw)
        if not m:
            continue
        parts = [p.strip("\"'") for p in re.findall(_TOML_KEY, m.group(2))]
        path: list[str | int] = []
        for j, part in enumerate(parts):
            path.append(part)
            prefix = tuple(path)
            if j == len(parts) - 1 and m.group(1) == "[[":
                counters[prefix] = counters.get(prefix, -1) + 1
                path.append(counters[prefix])
            elif prefix in counters:
                path.append(counters[prefix])
        headers.append((i, path))
    # The deepest header whose path starts the key path; without one, the top-level keys.
    start, rest, best_len = -1, keys, 0
    end = headers[0][0] if headers else len(lines)
    for n, (i, path) in enumerate(headers):
        if len(path) > best_len and keys[: len(path)] == path:
            best_len = len(path)
            start, rest = i, keys[len(path):]
            end = headers[n + 1][0] if n + 1 < len(headers) else len(lines)
    if rest and isinstance(rest[0], str):
        key_re = re.compile(rf"""^\s*["']?{re.escape(rest[0])}["']?\s*[=.]""")
        for i in range(start + 1, end):
            if key_re.match(lines[i]):
                return i + 1
    return start + 1 if start >= 0 else None


def _json_line(text: str, keys: list[str | int], data: Any) -> int | None:
    """Line of the last key of ``keys`` in JSON text, when that key is present in the data at
    that place and appears exactly once in the text (json keeps no positions)."""
    node = data
    for key in keys:
        node = _child(node, key)
        if node is None:
            return None
    names = [k for k in keys if isinstance(k, str)]
    if not names:
        return None
    pattern = re.compile(rf'"{re.escape(names[-1])}"\s*:')
    hits = [i for i, raw in enumerate(text.splitlines()) if pattern.search(raw)]
    return hits[0] + 1 if len(hits) == 1 else None


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    return scene.model_dump(mode="json", exclude_none=True)


def _moved_name(name: str, old: Path, new: Path) -> str:
    """File name ``name`` (relative to folder ``old``) as seen from folder ``new``: relative
    while that stays close (at most two levels up), else absolute."""
    p = Path(name).expanduser()
    if p.is_absolute():
        return name
    target = (old / p).resolve()
    try:
        rel = Path(os.path.relpath(target, new))
    except ValueError:  # another drive
        return str(target)
    if rel.parts[:3] == ("..", "..", ".."):
        return str(target)
    return rel.as_posix()


def rebase_files(scene: Scene, folder: str | Path) -> Scene:
    """A copy of ``scene`` whose relative model and texture file names point at the same
    files from ``folder`` (and whose base folder is ``folder``): what saving elsewhere needs."""
    old = scene.base_dir
    folder = Path(folder).resolve()
    if old.resolve() == folder:
        return scene.with_base_dir(folder)

    def moved(name: str) -> str:
        return _moved_name(name, old, folder)

    objects = []
    for obj in scene.objects:
        update: dict[str, Any] = {}
        if getattr(obj, "file", None):
            update["file"] = moved(obj.file)
        mat = obj.material
        if isinstance(mat, Material) and getattr(mat.texture, "file", None):
            tex = mat.texture.model_copy(update={"file": moved(mat.texture.file)})
            update["material"] = mat.model_copy(update={"texture": tex})
        objects.append(obj.model_copy(update=update) if update else obj)
    materials = {}
    for key, mat in scene.materials.items():
        if getattr(mat.texture, "file", None):
            tex = mat.texture.model_copy(update={"file": moved(mat.texture.file)})
            mat = mat.model_copy(update={"texture": tex})
        materials[key] = mat
    return scene.model_copy(update={"objects": objects, "materials": materials}).with_base_dir(
        folder)


def save_scene(scene: Scene, path: str | Path) -> Path:
    """Write ``scene`` as TOML or JSON (by extension), atomically. Relative model and texture
    file names are rewritten to stay valid from the new file's folder."""
    from ..output.encode import atomic_write

    path = Path(path)
    if path.parent.resolve() != scene.base_dir.resolve():
        scene = rebase_files(scene, path.parent)
    suffix = path.suffix.lower()
    data = scene_to_dict(scene)
    if suffix == ".toml":
        animation = data.pop("animation", None)
        text = tomli_w.dumps(data)
        if animation is not None:  # one key per line, not one number per line
            from ..animation.model import animation_toml

            text += "\n" + animation_toml(animation)
        payload = text.encode()
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
