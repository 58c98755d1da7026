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

from ..errors import FrameError, SceneError, shorten
from .animation import Track
from .interpolate import interpolate_tree, scalar_leaves, spline_extremes, wrap_keys
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


#: The widest a sequence pattern's ``{frame:...}`` may make the number (width or precision):
#: ``{frame:>300000000}`` would be a name of 300 million characters.
MAX_FORMAT_WIDTH = 32

_SPEC_RE = re.compile(
    r"(?:.?[<>=^])?[-+ ]?z?#?0?(?P<width>\d+)?[,_]?(?:\.(?P<precision>\d+))?[bdoxXneEfFgG%]?")


def _check_spec(pattern: str, spec: str, conversion: str | None) -> None:
    shown = shorten(pattern)
    if conversion is not None:
        raise ValueError(f"file pattern {shown!r}: {{frame!{conversion}}} is not a number "
                         "format (use for example {frame:04d})")
    m = _SPEC_RE.fullmatch(spec)
    if m is None:
        raise ValueError(f"file pattern {shown!r}: {{frame:{shorten(spec, 20)}}} is not a "
                         "number format (use for example {frame:04d})")
    for part in ("width", "precision"):
        digits = m.group(part)
        if digits is not None and (len(digits) > 3 or int(digits) > MAX_FORMAT_WIDTH):
            raise ValueError(f"file pattern {shown!r}: the {part} "
                             f"{shorten(digits.lstrip('0') or '0', 20)} is more than "
                             f"{MAX_FORMAT_WIDTH} characters")


def sequence_file(pattern: str, frame: int) -> str:
    """The file of ``frame`` in a numbered sequence; ValueError for a malformed pattern
    (a field other than ``{frame}``, a format that is not a number's, or one wider than
    :data:`MAX_FORMAT_WIDTH`)."""
    try:
        parsed = list(string.Formatter().parse(pattern))
    except ValueError as exc:
        raise ValueError(f"file pattern {shorten(pattern)!r}: {exc}") from None
    for _, name, spec, conversion in parsed:
        if name is None:
            continue
        if name != "frame":
            raise ValueError(f"file pattern {shorten(pattern)!r}: only {{frame}} may be used "
                             "(for example ice_{frame:04d}.ply)")
        _check_spec(pattern, spec or "", conversion)
    try:
        return pattern.format(frame=int(frame))
    except (ValueError, IndexError) as exc:
        raise ValueError(f"file pattern {shorten(pattern)!r}: {exc}") from None


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


#: A track whose keys span at most this many frames is checked at every frame between its
#: keys; a longer one (a film may have a million frames) at its keys, the frames next to
#: them, the frames where a spline turns (where it can overshoot) and this many frames
#: spread evenly: a cost that grows with the keys, not with the frames.
CHECK_EVERY_FRAME_UP_TO = 512


def _frames_to_check(ready: _Ready, frames: int) -> list[int]:
    """The frames :func:`check_animation` tries for one track's in-between values."""
    first = max(0, math.ceil(ready.times[0]))
    last = min(frames - 1, math.floor(ready.times[-1]))
    if last < first:
        return []
    if last - first < CHECK_EVERY_FRAME_UP_TO:
        return list(range(first, last + 1))
    picked: set[int] = set()
    for t in ready.times:  # on both sides of every key
        picked.update((math.floor(t) - 1, math.floor(t), math.ceil(t), math.ceil(t) + 1))
    if ready.interpolation == "spline":
        for leaf in scalar_leaves(ready.values, ready.name):
            for t in spline_extremes(ready.times, leaf):
                picked.update((math.floor(t), math.ceil(t)))
    step = (last - first) / CHECK_EVERY_FRAME_UP_TO
    picked.update(first + round(k * step) for k in range(CHECK_EVERY_FRAME_UP_TO + 1))
    return sorted(f for f in picked if first <= f <= last)


def check_animation(scene: Scene) -> None:
    """ValueError (one line, starting with the place: ``animation.tracks[2].keys[1]: ...``)
    for a track whose path names nothing, a key outside the frames, a key value its target
    rejects, or an interpolation that leaves what the target accepts between keys (a spline
    overshooting ``kt = 1``); or a mesh sequence with a malformed file pattern.

    The keys are checked once each; in-between values at the frames
    :func:`_frames_to_check` picks (every frame of a track spanning up to
    :data:`CHECK_EVERY_FRAME_UP_TO` frames), so a million-frame film is checked as fast as
    its keys. A frame not tried here whose value is still rejected (a value rule that is
    not a range, such as a camera position on its look-at point) is reported, one line
    naming the frame and the track, when that frame is made (:func:`scene_at_frame`)."""
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
        for frame in _frames_to_check(ready, scene.animation.frames):
            value = _value_at(ready, frame)
            try:
                set_value(scene, ready.written, value)
            except PathError as exc:
                raise ValueError(
                    f"animation.tracks[{i}]: at frame {frame} the {ready.interpolation} "
                    f"between keys gives {exc}") from None


def frame_number(frame: Any, frames: int) -> int:
    """``frame`` as an int in 0 .. frames - 1 (a whole float such as ``3.0`` or a NumPy
    integer is accepted); FrameError (one line) for anything else: None, text, true/false,
    NaN, infinity, 2.5, a frame out of range."""
    import numbers

    span = f"0..{frames - 1}"
    if isinstance(frame, bool) or not isinstance(frame, numbers.Real):
        raise FrameError(f"frame {shorten(repr(frame))} is not a frame number (a whole number "
                         f"{span})")
    if not isinstance(frame, numbers.Integral) and (
            not math.isfinite(frame) or int(frame) != frame):
        raise FrameError(f"frame {frame!r} is not a whole number (the frames are {span})")
    frame = int(frame)
    if not 0 <= frame < frames:
        plural = "s" if frames != 1 else ""
        raise FrameError(f"frame {shorten(str(frame))} is outside {span} (the scene has "
                         f"{frames} frame{plural})")
    return frame


def scene_at_frame(scene: Scene, frame: int) -> Scene:
    """The plain still of frame ``frame`` (0 .. frame_count - 1); ``scene`` is unchanged."""
    n = frame_count(scene)
    frame = frame_number(frame, n)
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
