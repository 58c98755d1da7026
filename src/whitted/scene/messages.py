"""pydantic's validation errors in the words of a scene file: the key path, the line in the
TOML or JSON text, the one most informative problem, and the keys allowed where a key is
unknown. Used by the scene model, the scene reader, animation paths and Stefan case files."""

from __future__ import annotations

import difflib
import json
import re
import typing
from typing import Any

from pydantic import BaseModel, ValidationError

from ..errors import SceneError, shorten

# Names pydantic puts into an error location for union members; they are not scene keys.
_UNION_TAGS = {"str", "int", "float", "bool", "Material", "Transform", "Gradient", "AxisAngle"}
_SHAPE_AND_LIGHT_TAGS = {
    "sphere", "plane", "rectangle", "disk", "triangle", "box", "cylinder", "cone", "mesh",
    "torus", "csg", "image", "checker", "gradient",
    "ambient", "point", "directional",
}



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
    best = max(exc.errors(), key=lambda e: (len(clean_loc(e["loc"])), _priority(e)))
    return clean_message(best)


def describe_validation_error(exc: ValidationError,
                              root: type[BaseModel] | None = None) -> tuple[str, str]:
    """(key path, message) of the most informative problem of ``exc``, as in scene files."""
    e = scene_error(exc, None, None, None, root=root)
    return e.where or "", e.message


def scene_error(
    exc: ValidationError, file: str | None, text: str | None, data: Any = None,
    root: Any = None,
) -> SceneError:
    errors = exc.errors()
    # Unions report one error per member; the deepest location is the informative one.
    best = max(errors, key=lambda e: (len(clean_loc(e["loc"])), _priority(e)))
    keys = clean_loc(best["loc"])
    if best["type"] in _EXPECTED:
        # every member of a union rejected the value's type: name all the accepted kinds
        alternatives = [
            _EXPECTED[e["type"]] for e in errors
            if e["type"] in _EXPECTED and clean_loc(e["loc"]) == keys
        ]
        message = "expected " + " or ".join(dict.fromkeys(alternatives))
        message += _got(best, message)
    elif best["type"] == "extra_forbidden":
        message = "unknown key" + (known_keys_hint(keys, data, root) if root else "")
    else:
        message = clean_message(best)
    where = format_path(keys)
    m = re.match(r"^((?:objects|lights)\[\d+\](?:\.\w+)*"
                 r"|animation\.tracks\[\d+\](?:\.\w+)*(?:\[\d+\])?): (.*)$", message)
    if not keys and m:
        where, message = m.group(1), m.group(2)
        keys = parse_path(where)
    # an unknown shape or light type is best shown on its `type = ...` line
    line_keys = [*keys, "type"] if best["type"] == "union_tag_invalid" else keys
    line = None
    if text is not None and file:
        if file.lower().endswith(".toml"):
            line = toml_line(text, line_keys)
        elif file.lower().endswith(".json"):
            line = json_line(text, line_keys, data)
    return SceneError(message, file=file, where=where or None, line=line)


def clean_loc(loc: tuple[Any, ...]) -> list[str | int]:
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


def clean_message(error: dict[str, Any]) -> str:
    kind, msg = error["type"], error["msg"]
    if kind == "missing":
        in_list = bool(error["loc"]) and isinstance(error["loc"][-1], int)
        return "missing list item" if in_list else "missing required value"
    if kind == "union_tag_invalid":
        given = error.get("input")
        expected = error.get("ctx", {}).get("expected_tags", "")
        if isinstance(given, BaseModel):  # a whole object of the wrong kind (Python)
            name = shorten(type(given).__name__, 40)
            if name.endswith("Light"):
                return (f"a {name} is a light, not a shape (lights go in the scene's "
                        f"lights; expected one of {expected})")
            return f"a {name} cannot go here (expected one of {expected})"
        tag = given.get("type") if isinstance(given, dict) else None
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


def known_keys_hint(keys: list[str | int], data: Any, root: Any) -> str:
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


def _allowed_keys(parent: list[str | int], data: Any, root: Any) -> list[str]:
    """The keys the scene model accepts at ``parent`` (a cleaned location), or [] if unknown.
    ``root``: a model class, or an annotation naming models (the shapes' union)."""
    models: list[type[BaseModel]] = _models_in(root)
    node = data
    # the next key indexes a list or names a dict entry
    container = typing.get_origin(root) in (list, dict)
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


def format_path(keys: list[str | int]) -> str:
    out = ""
    for k in keys:
        if isinstance(k, int):
            out += f"[{k}]"
            continue
        k = shorten(k)
        name = k if re.fullmatch(r"[A-Za-z_][\w-]*", k) else json.dumps(k)  # "my glass"
        out += f".{name}" if out else name
    return out


def parse_path(where: str) -> list[str | int]:
    keys: list[str | int] = []
    for name, index in re.findall(r"(\w+)|\[(\d+)\]", where):
        keys.append(int(index) if index else name)
    return keys


_TOML_KEY = r"""(?:[A-Za-z_][\w-]*|"[^"\n]*"|'[^'\n]*')"""  # bare or quoted
_HEADER_RE = re.compile(
    rf"^\s*(\[\[?)\s*({_TOML_KEY}(?:\s*\.\s*{_TOML_KEY})*)\s*\]\]?\s*(?:#.*)?$"
)


def toml_line(text: str, keys: list[str | int]) -> int | None:
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


def json_line(text: str, keys: list[str | int], data: Any) -> int | None:
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
