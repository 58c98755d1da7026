"""Readable paths to scene values, and reading or replacing the value a path names.

A path is how a track or a ``--set`` names one value of a scene::

    camera.position                      render.max_depth        background
    lights[0].intensity                  lights[key].color
    objects[glass sphere].material.kt    objects[2].transform.rotate
    materials.glass.kt                   materials[glass].ior

``[...]`` picks a list item by index or by its ``name`` (quotes are optional:
``objects["glass sphere"]``), or a named material. Setting a value returns a new scene: only
the models along the path are copied, the rest is shared, and the new value is validated by
the model that holds it (so ``kt = 2`` fails as it would in a scene file). Setting a value
below an object's material that names a shared material (``material = "glass"``) gives that
object its own copy of the material; the other objects keep the shared one.
"""

from __future__ import annotations

import difflib
import re
import typing
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, TypeAdapter, ValidationError

from ..errors import PathError, shorten

__all__ = ["PathError", "Step", "format_path", "get_value", "parse_path", "resolve_path",
           "set_value"]


@dataclass(frozen=True)
class Step:
    """One step of a path: a field or dict key (``.name``) or a list item (``[3]``/``[name]``)."""

    key: str | int
    item: bool = False  # written in brackets

    def __str__(self) -> str:
        if not self.item:
            return f".{self.key}"
        key = self.key
        if isinstance(key, str) and (re.fullmatch(r"\d+", key) or key != key.strip()
                                     or any(c in key for c in "[]\"'")):
            # quoted, so that the path reads back the same (a name "3" is not index 3)
            return f"['{key}']" if '"' in key else f'["{key}"]'
        return f"[{key}]"


_TOKEN = re.compile(
    r"""(?P<field>[A-Za-z_][\w-]*)|\[\s*(?P<item>"[^"]*"|'[^']*'|[^\]]*?)\s*\]|(?P<dot>\.)"""
)


def parse_path(text: str) -> tuple[Step, ...]:
    """``"objects[glass sphere].material.kt"`` -> its steps. PathError when malformed."""
    if not isinstance(text, str):
        raise PathError(f"a path is text such as 'camera.position', got {_kind(text)}")
    text = text.strip()
    if not text:
        raise PathError("empty path")
    steps: list[Step] = []
    pos = 0
    after_dot = True  # a field name is expected (the start counts as after a dot)
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            raise PathError(f"cannot read path {shorten(text)!r} at {shorten(text[pos:])!r}")
        if m.group("dot"):
            if after_dot:
                raise PathError(f"cannot read path {shorten(text)!r}: a name is missing before '.'")
            after_dot = True
        elif m.group("field") is not None:
            if not after_dot:
                raise PathError(f"cannot read path {shorten(text)!r}: '.' missing before "
                                f"{m.group('field')!r}")
            steps.append(Step(m.group("field")))
            after_dot = False
        else:
            if after_dot:
                raise PathError(f"cannot read path {shorten(text)!r}: '[' must follow a name")
            raw = m.group("item")
            if len(raw) >= 2 and raw[0] == raw[-1] and raw[0] in "\"'":
                key: str | int = raw[1:-1]
            elif re.fullmatch(r"\d+", raw):
                key = int(raw)
            else:
                key = raw
            if key == "":
                raise PathError(f"cannot read path {shorten(text)!r}: empty []")
            steps.append(Step(key, item=True))
        pos = m.end()
    if after_dot:
        raise PathError(f"cannot read path {shorten(text)!r}: it ends with '.'")
    return tuple(steps)


def _steps(steps: Any) -> tuple[Step, ...]:
    """A path given as text or as parsed steps; PathError for anything else."""
    if isinstance(steps, tuple) and all(isinstance(s, Step) for s in steps):
        return steps
    return parse_path(steps)


def format_path(steps: tuple[Step, ...]) -> str:
    out = ""
    for s in steps:
        out += str(s) if out or s.item else str(s.key)
    return out


# ------------------------------------------------------------------------------ walking


def _model_types(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    found: list[type[BaseModel]] = []
    for arg in typing.get_args(annotation):
        found += [m for m in _model_types(arg) if m not in found]
    return found


def _unknown(key: object, known: list[str], where: str, what: str = "key") -> PathError:
    close = difflib.get_close_matches(str(key), known, n=1, cutoff=0.6)
    hint = (f" (did you mean {close[0]!r}?)" if close
            else f" (known: {', '.join(known)})" if known and len(known) <= 16 else "")
    return PathError(f"{shorten(where)}: unknown {what} {shorten(str(key))!r}{hint}")


def _item_index(items: list, key: str | int, where: str) -> int:
    if isinstance(key, int):
        if not 0 <= key < len(items):
            raise PathError(f"{where}: index {key} is out of range (there are {len(items)})")
        return key
    hits = [i for i, item in enumerate(items) if getattr(item, "name", None) == key]
    if len(hits) > 1:
        raise PathError(f"{where}: {len(hits)} items are named {key!r}; use an index")
    if not hits:
        names = [n for n in (getattr(it, "name", None) for it in items) if n]
        raise _unknown(key, names, where, "name")
    return hits[0]


def resolve_path(scene: Any, steps: tuple[Step, ...] | str) -> tuple[Step, ...]:
    """The same path with names of list items replaced by their index, checked against
    ``scene``: PathError (one line) when it names nothing."""
    steps = _steps(steps)
    out: list[Step] = []
    _walk(scene, steps, out)
    return tuple(out)


def _walk(scene: Any, steps: tuple[Step, ...], resolved: list[Step] | None = None) -> Any:
    """The value at ``steps`` (None fields below which the path goes read as their defaults)."""
    node: Any = scene
    for n, step in enumerate(steps):
        where = format_path(steps[: n + 1])
        node, concrete = _child(scene, node, step, where, steps[:n], more=n + 1 < len(steps))
        if resolved is not None:
            resolved.append(concrete)
    return node


def _child(scene: Any, node: Any, step: Step, where: str, parent: tuple[Step, ...],
           more: bool) -> tuple[Any, Step]:
    if isinstance(node, list):
        if not step.item:
            raise PathError(f"{format_path(parent)} is a list: pick an item with [index] or "
                            f"[name], not .{step.key}")
        i = _item_index(node, step.key, where)
        return node[i], Step(i, item=True)
    if isinstance(node, dict):
        if step.key not in node:
            raise _unknown(step.key, sorted(node), where, "name")
        return node[step.key], Step(step.key, item=step.item)
    if isinstance(node, BaseModel):
        fields = type(node).model_fields
        if step.item or step.key not in fields:
            if step.item:
                raise PathError(f"{where}: {format_path(parent) or 'the scene'} is not a list")
            raise _unknown(step.key, list(fields), where)
        value = getattr(node, step.key)
        if more:
            value = _expand(scene, node, step.key, value, parent, where)
        return value, Step(step.key)
    place = format_path(parent)
    raise PathError(f"{where}: {place} is a value ({_kind(node)}), it has no parts")


def _kind(value: Any) -> str:
    if value is None:
        return "nothing (None)"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "text"
    if isinstance(value, tuple | list):
        return f"a list of {len(value)}"
    return type(value).__name__


def _expand(scene: Any, owner: BaseModel, key: str, value: Any, parent: tuple[Step, ...],
            where: str) -> Any:
    """What a path below ``owner.key`` walks into when the field holds no model itself: an
    object's material given by name resolves to that material; an unset transform (or
    material) to its default."""
    if key == "material" and hasattr(owner, "transform"):  # a shape's material
        if isinstance(value, str) or value is None:
            if value is None and getattr(owner, "file", None):
                raise PathError(f"{where}: this mesh takes its materials from its file; "
                                "give it a material first")
            index = parent[-1].key if parent and isinstance(parent[-1].key, int) else None
            if index is None:
                index = scene.objects.index(owner)
            return scene.material_of(index)
        return value
    if value is None:
        for model in _model_types(type(owner).model_fields[key].annotation):
            try:
                return model()
            except ValidationError:
                continue
        raise PathError(f"{where}: is not set; set it whole first (e.g. {where} = {{...}})")
    return value


def get_value(scene: Any, steps: tuple[Step, ...] | str) -> Any:
    """The value a path names (a model, a tuple, a number, ...)."""
    steps = _steps(steps)
    return _walk(scene, steps)


# ------------------------------------------------------------------------------ setting

_ADAPTERS: dict[Any, TypeAdapter] = {}


def _adapter(annotation: Any) -> TypeAdapter:
    adapter = _ADAPTERS.get(annotation)
    if adapter is None:
        adapter = _ADAPTERS[annotation] = TypeAdapter(annotation)
    return adapter


def _rejected(exc: ValidationError, parent: tuple[Step, ...], root: Any, data: Any) -> PathError:
    """The one line of a value the model rejects, worded as a scene file's error (the whole
    key path, ``expected an integer (got True)``, ``unknown key (known: ...)``): ``parent``
    is where the validated ``data`` hangs, ``root`` the model (or annotation) it met."""
    from .messages import scene_error

    e = scene_error(exc, None, None, data, root=root)
    where = format_path(parent)
    inner = e.where or ""
    if inner:
        where = f"{where}{inner}" if inner.startswith("[") or not where else f"{where}.{inner}"
    return PathError(f"{where}: {e.message}" if where else e.message)


def set_value(scene: Any, steps: tuple[Step, ...] | str, value: Any, *,
              strict: bool = False) -> Any:
    """A copy of ``scene`` with the value at ``steps`` replaced by ``value`` (validated where
    it lands). The original is unchanged. PathError (one line) when the path names nothing
    or the value is rejected. ``strict``: the value follows a scene file's rules (numbers
    are numbers, booleans booleans, no text for either), as ``--set`` and sweeps need;
    otherwise pydantic's lax conversions apply (values made by whitted itself: tracks)."""
    steps = _steps(steps)
    if not steps:
        raise PathError("empty path")
    if not strict:
        return _set(scene, scene, steps, 0, value, False)
    from .types import file_strictness

    with file_strictness():
        return _set(scene, scene, steps, 0, value, True)


def _set(scene: Any, node: Any, steps: tuple[Step, ...], n: int, value: Any,
         strict: bool) -> Any:
    """``node`` with the value at ``steps[n:]`` replaced. A model validates the field it
    holds (a list item or dict entry is validated with its list or dict, by the model that
    holds them: the error's location is then the whole path)."""
    step = steps[n]
    last = n + 1 == len(steps)
    where = format_path(steps[: n + 1])
    child, concrete = _child(scene, node, step, where, steps[:n], more=not last)
    new_child = value if last else _set(scene, child, steps, n + 1, value, strict)
    if isinstance(node, BaseModel):
        if node is scene:  # the top level: validate the field only, then the cross-checks
            annotation = type(node).model_fields[step.key].annotation
            try:
                new_child = _adapter(annotation).validate_python(new_child,
                                                                 strict=strict or None)
            except ValidationError as exc:
                raise _rejected(exc, steps[: n + 1], annotation, new_child) from None
            copy = node.model_copy(update={step.key: new_child})
            check = getattr(type(node), "_material_names_resolve", None)
            if check is not None:
                try:
                    check(copy)
                except ValueError as exc:
                    raise PathError(str(exc)) from None
            return copy
        copy = node.model_copy()
        try:  # what assigning the attribute does, at the strictness asked for
            type(copy).__pydantic_validator__.validate_assignment(
                copy, step.key, new_child, strict=strict or None)
        except ValidationError as exc:
            raise _rejected(exc, steps[:n], type(node), {step.key: new_child}) from None
        return copy
    if isinstance(node, list):
        out = list(node)
        out[concrete.key] = new_child
        return out
    out_dict = dict(node)
    out_dict[concrete.key] = new_child
    return out_dict
