"""Validated value types shared by the scene model: vectors, colours, transforms."""

from __future__ import annotations

import contextlib
import functools
import math
import types
import typing
from contextvars import ContextVar
from typing import Annotated, Any

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from ..errors import SceneValidationError
from .messages import describe_validation_error

_strict: ContextVar[bool] = ContextVar("whitted_strict_validation", default=False)
_depth: ContextVar[int] = ContextVar("whitted_validation_depth", default=0)



@contextlib.contextmanager
def file_strictness():
    """Validation inside the block is as strict as a scene file's, nested models too
    (``--set`` and sweep values: ``photons = true`` or ``width = "32"`` is refused as the
    file refuses it), and its errors are pydantic's own, their locations whole."""
    strictness = _strict.set(True)
    depth = _depth.set(_depth.get() + 1)
    try:
        yield
    finally:
        _depth.reset(depth)
        _strict.reset(strictness)


def _wrap(exc: ValidationError, model: type) -> Exception:
    """``exc`` as a :class:`SceneValidationError` whose line names ``model`` and the key."""
    where, message = describe_validation_error(exc, model)
    where = ".".join(p for p in (getattr(model, "__name__", None), where) if p)
    return SceneValidationError.wrap(exc, where, message)


class Strict(BaseModel):
    """Base of every scene model: unknown keys are errors, values are re-validated on assignment.

    Scene files are validated strictly (``model_validate(data, strict=True)``: numbers are
    numbers, booleans booleans, no text for either); a list is taken wherever the model holds a
    tuple. Errors are :class:`~whitted.errors.SceneValidationError` (a WhittedError that is also
    pydantic's ValidationError)."""

    model_config = ConfigDict(
        extra="forbid", validate_assignment=True, frozen=False, allow_inf_nan=False
    )

    def __init__(self, /, **data: Any) -> None:
        # pydantic calls a custom __init__ for nested models too: the strictness of the
        # outermost call travels in a context variable, and only the outermost call turns
        # pydantic's error into the library's own
        depth = _depth.set(_depth.get() + 1)
        try:
            self.__pydantic_validator__.validate_python(
                data, self_instance=self, strict=_strict.get() or None)
        except ValidationError as exc:
            if _depth.get() > 1 or isinstance(exc, SceneValidationError):
                raise
            raise _wrap(exc, type(self)) from None
        finally:
            _depth.reset(depth)

    def __setattr__(self, name: str, value: Any) -> None:
        try:
            super().__setattr__(name, value)
        except SceneValidationError:
            raise
        except ValidationError as exc:
            raise _wrap(exc, type(self)) from None

    @classmethod
    def model_validate(cls, obj: Any, *, strict: bool | None = None, **kwargs: Any) -> Any:
        strictness = _strict.set(bool(strict))
        depth = _depth.set(_depth.get() + 1)
        try:
            return super().model_validate(obj, strict=strict, **kwargs)
        except ValidationError as exc:
            if _depth.get() > 1 or isinstance(exc, SceneValidationError):
                raise
            raise _wrap(exc, cls) from None
        finally:
            _depth.reset(depth)
            _strict.reset(strictness)

    @model_validator(mode="before")
    @classmethod
    def _lists_as_tuples(cls, data: Any) -> Any:
        """Files hold lists where the model holds tuples (vectors, triangles): take them.
        Numbers beyond :data:`MAX_MAGNITUDE` are refused here, for every model (their squares
        and products would overflow in the compiler)."""
        if not isinstance(data, dict):
            return data
        for key, value in data.items():
            big = _too_large(value)
            if big is not None:
                raise ValueError(f"{key}: number {big!r} is too large (scene values are limited "
                                 f"to {MAX_MAGNITUDE:.0e} in magnitude)")
        names = _tuple_fields(cls)
        if not names or not any(isinstance(data.get(n), list) for n in names):
            return data
        return {k: (_as_tuple(v) if k in names else v) for k, v in data.items()}


#: Largest magnitude of a number in a scene: beyond it squares and products overflow.
MAX_MAGNITUDE = 1e15


def _too_large(value: Any, depth: int = 0) -> float | int | None:
    """The first number in ``value`` (a number or a short list of them, nested twice at most)
    whose magnitude exceeds :data:`MAX_MAGNITUDE`; None if there is none. Non-finite numbers
    are left to the fields' own checks."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float | np.integer | np.floating):
        magnitude = abs(float(value)) if not isinstance(value, int) else abs(value)
        return value if math.isfinite(magnitude) and magnitude > MAX_MAGNITUDE else None
    if isinstance(value, list | tuple) and depth < 2 and len(value) <= 64:
        for item in value:
            big = _too_large(item, depth + 1)
            if big is not None:
                return big
    return None


def _as_tuple(value: Any) -> Any:
    if isinstance(value, list) and len(value) <= 64:
        return tuple(_as_tuple(v) for v in value)
    return value


def _holds_tuple(annotation: Any, depth: int = 0) -> bool:
    if depth > 8:
        return False
    origin = typing.get_origin(annotation)
    if origin is tuple:
        return True
    if origin is Annotated:
        return _holds_tuple(typing.get_args(annotation)[0], depth + 1)
    if origin in (typing.Union, types.UnionType):
        return any(_holds_tuple(a, depth + 1) for a in typing.get_args(annotation))
    return False


@functools.cache
def _tuple_fields(cls: type[BaseModel]) -> frozenset[str]:
    return frozenset(n for n, f in cls.model_fields.items() if _holds_tuple(f.annotation))


def _finite_vector(value: object) -> tuple[float, float, float]:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ValueError("expected a list of 3 numbers")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ValueError(f"expected a number, got {v!r}")
        if not math.isfinite(v):
            raise ValueError(f"expected a finite number, got {v!r}")
        out.append(float(v))
    return (out[0], out[1], out[2])


def _nonzero_vector(value: object) -> tuple[float, float, float]:
    v = _finite_vector(value)
    if math.hypot(*v) < 1e-12:  # hypot: no overflow for components above 1e154
        raise ValueError("must not be the zero vector")
    return v


def srgb_channel_to_linear(c: float) -> float:
    """The sRGB transfer curve (IEC 61966-2-1) inverted: 8-bit style colour to linear."""
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def _colour(value: object) -> tuple[float, float, float]:
    """Colours are ``"#rrggbb"`` (sRGB-encoded, as colour pickers give them) or linear [r, g, b]."""
    if isinstance(value, str):
        text = value.strip()
        if len(text) != 7 or text[0] != "#":
            raise ValueError(f"colour {value!r} is not '#rrggbb' or [r, g, b]")
        try:
            channels = [int(text[i : i + 2], 16) / 255.0 for i in (1, 3, 5)]
        except ValueError:
            raise ValueError(f"colour {value!r} has non-hex digits") from None
        r, g, b = (srgb_channel_to_linear(c) for c in channels)
        return (r, g, b)
    v = _finite_vector(value)
    for c in v:
        if c < 0.0 or c > 1.0:
            raise ValueError(f"colour channel {c} is outside 0..1")
    return v


Vec3 = Annotated[tuple[float, float, float], BeforeValidator(_finite_vector)]
Direction = Annotated[tuple[float, float, float], BeforeValidator(_nonzero_vector)]
Colour = Annotated[tuple[float, float, float], BeforeValidator(_colour)]


def _finite(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {value!r}")
    return value


Finite = Annotated[float, BeforeValidator(_finite)]
Positive = Annotated[float, BeforeValidator(_finite), Field(gt=0)]
Unit = Annotated[float, BeforeValidator(_finite), Field(ge=0, le=1)]


class AxisAngle(Strict):
    """A rotation by ``angle`` degrees about ``axis`` (right-hand rule)."""

    axis: Direction
    angle: Finite


class Transform(Strict):
    """An object's placement: scale, then rotate about x, y, z (in that order), then about an
    arbitrary axis, then translate. Angles in degrees; rotations are about the world origin."""

    scale: Finite | Vec3 = 1.0
    rotate: Vec3 = (0.0, 0.0, 0.0)
    axis_angle: AxisAngle | None = None
    translate: Vec3 = (0.0, 0.0, 0.0)

    @field_validator("scale")
    @classmethod
    def _scale_nonzero(cls, v: float | tuple[float, float, float]) -> object:
        values = v if isinstance(v, tuple) else (v,)
        if any(abs(s) < 1e-12 for s in values):
            raise ValueError("scale must not be zero")
        return v

    def is_identity(self) -> bool:
        return bool(np.allclose(self.matrix(), np.eye(4), rtol=0, atol=0))

    def matrix(self) -> np.ndarray:
        """The 4x4 object-to-world matrix."""
        s = self.scale
        sx, sy, sz = (s, s, s) if isinstance(s, int | float) else s
        m = np.diag([sx, sy, sz, 1.0])
        rx, ry, rz = (math.radians(a) for a in self.rotate)
        m = _rotation(np.array([1.0, 0, 0]), rx) @ m
        m = _rotation(np.array([0, 1.0, 0]), ry) @ m
        m = _rotation(np.array([0, 0, 1.0]), rz) @ m
        if self.axis_angle is not None:
            m = _rotation(np.array(self.axis_angle.axis), math.radians(self.axis_angle.angle)) @ m
        t = np.eye(4)
        t[:3, 3] = self.translate
        return t @ m


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation matrix (4x4) for a right-handed rotation of ``angle`` radians."""
    a = axis / np.linalg.norm(axis)
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = a
    r = np.array(
        [
            [c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
            [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
            [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)],
        ]
    )
    # snap the tiny residues of cos(90 deg) etc. so axis-aligned rotations stay exact
    r[np.abs(r) < 1e-15] = 0.0
    m = np.eye(4)
    m[:3, :3] = r
    return m


class Gradient(Strict):
    """A vertical background gradient: ``bottom`` at the horizon-down direction, ``top`` up."""

    top: Colour
    bottom: Colour


class Background(Strict):
    color: Colour = (0.0, 0.0, 0.0)
    gradient: Gradient | None = None

    @model_validator(mode="before")
    @classmethod
    def _accept_plain_colour(cls, data: object) -> object:
        if isinstance(data, str | list | tuple):
            return {"color": data}
        return data
