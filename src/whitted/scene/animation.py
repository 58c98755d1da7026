"""The ``[animation]`` table of a scene: frames, frames per second and tracks (pure data).

A track names one value of the scene by a path (:mod:`whitted.scene.paths`) and gives
keys, pairs ``[frame, value]``, with an interpolation. Frames are numbered from 0 to
``frames - 1``; a key may sit between frames (``12.5``).

>>> Track("camera.position", {0: [0, 2, 9], 47: [9, 2, 0]}, interpolation="smooth")
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import Field, field_validator

from .types import Strict

Interpolation = Literal["step", "linear", "smooth", "spline"]
MAX_FRAMES = 1_000_000


class Track(Strict):
    """Keys of one scene value over time. ``keys`` is a list of ``[frame, value]`` pairs (a
    dict ``{frame: value}`` is accepted from Python); the value has the shape of the value
    the path names (a number, ``[x, y, z]``, a colour, a whole table)."""

    path: str = Field(min_length=1)
    keys: list[tuple[int | float, Any]] = Field(min_length=1)
    interpolation: Interpolation = "linear"

    def __init__(self, path: str | None = None, keys: Any = None, **data: Any) -> None:
        if path is not None:
            data["path"] = path
        if keys is not None:
            data["keys"] = keys
        super().__init__(**data)

    @field_validator("keys", mode="before")
    @classmethod
    def _keys_from_dict(cls, value: Any) -> Any:
        if isinstance(value, dict):
            value = [[float(k) if isinstance(k, str) else k, v] for k, v in value.items()]
        if isinstance(value, list):  # scene files are validated strictly: a pair is a tuple
            return [tuple(k) if isinstance(k, list) else k for k in value]
        return value

    @field_validator("keys")
    @classmethod
    def _frames_distinct(cls, keys: list[tuple[int | float, Any]]) -> list:
        seen: set[float] = set()
        for frame, _ in keys:
            if isinstance(frame, bool) or not math.isfinite(frame):
                raise ValueError(f"key frame {frame!r} is not a number")
            if frame in seen:
                raise ValueError(f"two keys at frame {frame:g}")
            seen.add(frame)
        return keys

    def sorted_keys(self) -> list[tuple[float, Any]]:
        return sorted(self.keys, key=lambda k: k[0])


class Animation(Strict):
    """``frames`` frames (numbered 0 .. frames-1) shown at ``fps`` per second; ``tracks``
    change scene values over them."""

    frames: int = Field(ge=1, le=MAX_FRAMES)
    fps: float = Field(default=24.0, gt=0.0, le=1000.0)
    #: the film loops: frame ``frames`` would be frame 0 again, so every track runs from its
    #: last key back to its first (a camera orbit that plays seamlessly in a loop)
    cyclic: bool = False
    tracks: list[Track] = Field(default_factory=list)

    def track(self, path: str, keys: Any, interpolation: Interpolation = "linear") -> Animation:
        """A copy with one more track (``keys``: ``{frame: value}`` or ``[(frame, value)]``)."""
        new = Track(path, keys, interpolation=interpolation)
        return Animation(frames=self.frames, fps=self.fps, cyclic=self.cyclic,
                         tracks=[*self.tracks, new])
