"""What the editor says when a value is refused: one short sentence in the user's words,
naming the field as the panel labels it ("radius must be greater than 0"), not the
validator's text."""

from __future__ import annotations

from typing import Any

from pydantic import ValidationError


def _number(value: Any) -> str:
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


def _name_of(loc: tuple, label: str | None, field: str | None) -> str:
    names = [p for p in loc if isinstance(p, str)]
    if label and (not names or field is None or names[-1] == field):
        return label
    return names[-1].replace("_", " ") if names else (label or "the value")


def describe_error(error: dict[str, Any], label: str | None = None,
                   field: str | None = None) -> str:
    """One pydantic error as a sentence; ``label`` names the field being edited (``field``:
    its key in the model) when the error is about it."""
    name = _name_of(tuple(error.get("loc", ())), label, field)
    kind = error.get("type", "")
    ctx = error.get("ctx") or {}
    bounds = {"greater_than": ("gt", "greater than"), "greater_than_equal": ("ge", "at least"),
              "less_than": ("lt", "less than"), "less_than_equal": ("le", "at most")}
    if kind in bounds:
        key, words = bounds[kind]
        return f"{name} must be {words} {_number(ctx.get(key))}"
    if kind in ("float_parsing", "int_parsing", "float_type", "int_type", "finite_number"):
        return f"{name} must be a {'whole ' if kind.startswith('int') else ''}number"
    if kind == "literal_error":
        return f"{name} must be {ctx.get('expected', 'one of the choices')}"
    if kind == "missing":
        return f"{name} is needed"
    if kind == "value_error":
        inner = str(ctx.get("error", error.get("msg", "")))
        return inner if name in inner or not error.get("loc") else f"{name}: {inner}"
    msg = str(error.get("msg", "not a valid value"))
    return f"{name}: {msg[:1].lower()}{msg[1:]}"


def friendly_message(exc: ValidationError, label: str | None = None,
                     field: str | None = None) -> str:
    """The first (most telling) error of ``exc`` as one sentence."""
    errors = exc.errors()
    # an error about the field being edited first, then bounds before the rest
    errors.sort(key=lambda e: (field is not None and field not in e.get("loc", ()),
                               e.get("type") == "missing"))
    return describe_error(errors[0], label, field) if errors else str(exc)
