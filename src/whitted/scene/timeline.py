"""An animated scene -> the plain still of one frame.

``scene_at_frame(scene, k)`` applies every track at frame ``k`` (in the order they are
listed: a later track on the same value wins), names each mesh sequence's file for frame
``k``, derives the frame's random seed and drops the animation. The result is a plain
:class:`~whitted.Scene` that renders exactly like frame ``k`` of the film, wherever it is
rendered. The scene it came from is not changed.
"""

from __future__ import annotations

import hashlib
import math
import re
import string
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel

from ..errors import SceneError
from .animation import Track
from .interpolate import interpolate_tree, wrap_keys
from .paths import PathError, Step, format_path, get_value, parse_path, resolve_path, set_value

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["check_animation", "frame_count", "frame_seed", "is_sequence", "scene_at_frame",
           "sequence_file", "track_value"]

SEED_LIMIT = 2**31  # RenderSettings.seed is below this


def frame_seed(seed: int, frame: int) -> int:
    """The render seed of frame ``frame`` of a film rendered with ``seed``: frame 0 keeps
    ``seed`` (a still renders as it always did); other frames get a stable hash of
    (seed, frame), so the noise of area-light and pixel samples changes from frame to frame
    and is the same in every process, on every machine."""
    if frame == 0:
        return int(seed)
    digest = hashlib.blake2b(f"whitted-frame:{int(seed)}:{int(frame)}".encode(),
                             digest_size=8).digest()
    return int.from_bytes(digest, "little") % SEED_LIMIT


# ------------------------------------------------------------------------------ sequences

_FIELD_RE = re.compile(r"\{[^{}]*\}")


def is_sequence(name: str | None) -> bool:
    """Whether a model file name is a numbered sequence (``melt/ice_{frame:04d}.ply``)."""
    return bool(name) and "{" in name  # type: ignore[operator]


def sequence_file(pattern: str, frame: int) -> str:
    """The file of ``frame`` in a numbered sequence; ValueError for a malformed pattern."""
    try:
        fields = [f for _, f, _, _ in string.Formatter().parse(pattern) if f is not None]
    except ValueError as exc:
        raise ValueError(f"file pattern {pattern!r}: {exc}") from None
    if any(f != "frame" for f in fields):
        raise ValueError(f"file pattern {pattern!r}: only {{frame}} may be used "
                         "(for example ice_{frame:04d}.ply)")
    try:
        return pattern.format(frame=int(frame))
    except (ValueError, IndexError) as exc:
        raise ValueError(f"file pattern {pattern!r}: {exc}") from None


def _sequences(scene: Scene) -> list[int]:
    return [i for i, obj in enumerate(scene.objects) if is_sequence(getattr(obj, "file", None))]


# ------------------------------------------------------------------------------ tracks


def frame_count(scene: Scene) -> int:
    """How many frames the scene has: its animation's ``frames``, else 1 (a still)."""
    return scene.animation.frames if scene.animation is not None else 1


@dataclass(frozen=True)
class _Ready:
    """A track checked against its scene: concrete path, keys as plain trees."""

    steps: tuple[Step, ...]
    written: tuple[Step, ...]  # as the track names it (names, not indices): for messages
    times: list[float]
    values: list[Any]
    interpolation: str
    name: str | None


def _tree(value: Any) -> Any:
    """A validated value as numbers, lists and dicts (what interpolation works on)."""
    if isinstance(value, BaseModel):
        return {k: _tree(getattr(value, k)) for k in type(value).model_fields}
    if isinstance(value, tuple | list):
        return [_tree(v) for v in value]
    return value


def _prepare(scene: Scene, index: int, track: Track) -> _Ready:
    head = f"animation.tracks[{index}]"
    try:
        written = parse_path(track.path)
        steps = resolve_path(scene, written)
    except PathError as exc:
        raise ValueError(f"{head}.path: {exc}") from None
    frames = frame_count(scene)
    keys = sorted(enumerate(track.keys), key=lambda k: k[1][0])
    times: list[float] = []
    values: list[Any] = []
    for j, (frame, value) in keys:
        if not 0 <= frame <= frames - 1:
            raise ValueError(f"{head}.keys[{j}]: frame {frame:g} is outside 0..{frames - 1} "
                             f"(frames = {frames})")
        try:
            keyed = set_value(scene, written, value)  # errors name the path as written
        except PathError as exc:
            raise ValueError(f"{head}.keys[{j}]: {exc}") from None
        times.append(float(frame))
        values.append(_tree(get_value(keyed, steps)))
    name = steps[-1].key if isinstance(steps[-1].key, str) else None
    if scene.animation is not None and scene.animation.cyclic:
        times, values = wrap_keys(times, values, float(frames))
    return _Ready(steps, written, times, values, track.interpolation, name)


_PREPARED: OrderedDict[tuple, tuple[Scene, list[_Ready]]] = OrderedDict()
_PREPARED_LOCK = threading.Lock()
_KEEP = 4


def _prepared(scene: Scene) -> list[_Ready]:
    """Every track of ``scene`` checked and its keys normalised, remembered for the last few
    scenes (a film asks for the same scene's tracks at every frame; normalising a key
    validates it in the scene, so a track keyed at every frame would otherwise cost the
    square of its length)."""
    assert scene.animation is not None
    key = (id(scene), id(scene.animation), id(scene.objects), id(scene.lights),
           id(scene.materials), len(scene.objects), len(scene.lights),
           tuple((id(t), id(t.keys), len(t.keys), t.path, t.interpolation)
                 for t in scene.animation.tracks))
    with _PREPARED_LOCK:
        hit = _PREPARED.get(key)
        if hit is not None and hit[0] is scene:
            _PREPARED.move_to_end(key)
            return hit[1]
    ready = [_prepare(scene, i, t) for i, t in enumerate(scene.animation.tracks)]
    with _PREPARED_LOCK:
        _PREPARED[key] = (scene, ready)  # holding the scene keeps its id from being reused
        while len(_PREPARED) > _KEEP:
            _PREPARED.popitem(last=False)
    return ready


def _value_at(ready: _Ready, frame: float) -> Any:
    return interpolate_tree(ready.times, ready.values, frame, ready.interpolation, ready.name)


def track_value(scene: Scene, track: Track | int, frame: float) -> Any:
    """The value a track gives at ``frame`` (numbers, lists, dicts for whole tables)."""
    assert scene.animation is not None
    index = track if isinstance(track, int) else scene.animation.tracks.index(track)
    ready = _prepare(scene, index, scene.animation.tracks[index])
    return _value_at(ready, frame)


def check_animation(scene: Scene) -> None:
    """ValueError (one line, starting with the place: ``animation.tracks[2].keys[1]: ...``)
    for a track whose path names nothing, a key outside the frames, a key value its target
    rejects, or an interpolation that leaves what the target accepts between keys (a spline
    overshooting ``kt = 1``); or a mesh sequence with a malformed file pattern."""
    for i in _sequences(scene):
        try:
            sequence_file(scene.objects[i].file, 0)
        except ValueError as exc:
            raise ValueError(f"objects[{i}].file: {exc}") from None
    if scene.animation is None:
        return
    for i, track in enumerate(scene.animation.tracks):
        ready = _prepare(scene, i, track)
        if ready.interpolation == "step" or len(ready.times) < 2:
            continue
        first = max(0, math.ceil(ready.times[0]))
        last = min(scene.animation.frames - 1, math.floor(ready.times[-1]))
        for frame in range(first, last + 1):
            value = _value_at(ready, frame)
            try:
                set_value(scene, ready.written, value)
            except PathError as exc:
                raise ValueError(
                    f"animation.tracks[{i}]: at frame {frame} the {ready.interpolation} "
                    f"between keys gives {exc}") from None


def scene_at_frame(scene: Scene, frame: int) -> Scene:
    """The plain still of frame ``frame`` (0 .. frame_count - 1); ``scene`` is unchanged."""
    n = frame_count(scene)
    if isinstance(frame, bool) or int(frame) != frame:
        raise SceneError(f"frame {frame!r} is not a whole number")
    frame = int(frame)
    if not 0 <= frame < n:
        raise SceneError(f"frame {frame} is outside 0..{n - 1} (the scene has {n} "
                         f"frame{'s' if n != 1 else ''})")
    still = scene
    if scene.animation is not None:
        try:
            prepared = _prepared(scene)
        except ValueError as exc:
            raise SceneError(f"frame {frame}: {exc}") from None
        for i, ready in enumerate(prepared):
            try:
                value = _value_at(ready, frame)
                still = set_value(still, ready.steps, value)
            except (PathError, ValueError) as exc:
                raise SceneError(f"frame {frame}: {exc}",
                                 where=f"animation.tracks[{i}]") from None
    sequences = _sequences(scene)
    if sequences:
        objects = list(still.objects)
        for i in sequences:
            name = sequence_file(objects[i].file, frame)
            if not still.resolve_path(name).is_file():
                raise SceneError(f"frame {frame}: no such file: {name!r} "
                                 f"(looked in {still.resolve_path(name).parent})",
                                 where=f"objects[{i}].file")
            objects[i] = objects[i].model_copy(update={"file": name})
        still = still.model_copy(update={"objects": objects})
    render = still.render.model_copy(update={"seed": frame_seed(still.render.seed, frame)})
    return still.model_copy(update={"render": render, "animation": None})


def path_text(steps: tuple[Step, ...]) -> str:
    return format_path(steps)
