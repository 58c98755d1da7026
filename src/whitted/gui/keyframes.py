"""Keys and poses for the editor's timeline (pure functions on scenes, no Qt).

- :func:`key_targets`: which values "Insert key" keys for a selection: an object's
  ``transform`` (and its ``center`` when the shape has one), a light's position/direction,
  the camera's ``position`` and ``look_at``
- :func:`insert_keys`: the scene with those values keyed at a frame (the ``[animation]``
  table and its tracks are created as needed, a key already at that frame is replaced)
- :func:`posed`: the scene with the values its tracks drive set to their values at a frame,
  as Blender poses a scene when the frame changes: the properties panel then shows the
  frame's values, and an edit the user has not keyed yet is still seen in the preview
- :func:`frame_still`: what the editor previews and renders at a frame: ``scene.at_frame(k)``
  for a scene posed at ``k`` (equal to it when nothing unkeyed was edited)
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel

from ..scene import Scene
from ..scene.animation import Animation, Interpolation, Track
from ..scene.paths import (
    PathError,
    format_path,
    get_value,
    parse_path,
    resolve_path,
    set_value,
)
from ..scene.timeline import scene_at_frame, track_value
from ..scene.types import Transform

#: a new animation (made by the first key of a still scene): two seconds at 24 fps
NEW_FRAMES = 48
NEW_FPS = 24.0
NEW_INTERPOLATION: Interpolation = "linear"
OBJECT_PLACEMENT = ("center", "transform")
LIGHT_PLACEMENT = ("position", "center", "direction", "normal")
CAMERA_PLACEMENT = ("position", "look_at")


def _plain(value: Any) -> Any:
    """A value as TOML-ready numbers, lists and dicts (models without their unset fields)."""
    if isinstance(value, BaseModel):
        return {k: _plain(v) for k, v in value if v is not None}
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if v is not None}
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def _item_ref(items: list, index: int) -> str:
    """``[name]`` when the item's name is unique and readable in a path, else ``[index]``."""
    name = getattr(items[index], "name", None)
    if (name and name.strip() == name and not any(c in name for c in "[]\"'")
            and not name.isdigit()
            and sum(getattr(it, "name", None) == name for it in items) == 1):
        return f"[{name}]"
    return f"[{index}]"


def key_targets(scene: Scene, selection: tuple | None) -> list[tuple[str, Any]]:
    """(path, current value) of every value "Insert key" keys for ``selection``; empty when
    the selection has nothing to key (the render settings, the background, nothing)."""
    if selection is None:
        return []
    if selection == ("camera",):
        return [(f"camera.{f}", _plain(getattr(scene.camera, f))) for f in CAMERA_PLACEMENT]
    if len(selection) != 2 or selection[0] not in ("objects", "lights"):
        return []
    kind, index = selection
    items = getattr(scene, kind)
    if not 0 <= index < len(items):
        return []
    item = items[index]
    head = kind + _item_ref(items, index)
    fields = OBJECT_PLACEMENT if kind == "objects" else LIGHT_PLACEMENT
    out = []
    for name in fields:
        if name not in type(item).model_fields:
            continue
        value = getattr(item, name)
        if value is None and name == "transform":
            value = Transform()
        out.append((f"{head}.{name}", _plain(value)))
    return out


def _same_target(scene: Scene, a: str, b: str) -> bool:
    try:
        return resolve_path(scene, a) == resolve_path(scene, b)
    except PathError:
        return False


def _with_key(keys: list, frame: int, value: Any) -> list:
    kept = [[f, v] for f, v in keys if float(f) != float(frame)]
    return sorted([*kept, [frame, value]], key=lambda k: k[0])


def insert_keys(scene: Scene, targets: list[tuple[str, Any]], frame: int,
                interpolation: Interpolation = NEW_INTERPOLATION) -> Scene:
    """``scene`` with each (path, value) of ``targets`` keyed at ``frame``: into the track
    that already drives that value (same target, whatever its spelling), else a new track.
    A still scene gets an animation of at least :data:`NEW_FRAMES` frames. The result is
    validated (ValueError/ValidationError when a track would give an invalid value)."""
    anim = scene.animation or Animation(frames=max(NEW_FRAMES, frame + 1), fps=NEW_FPS)
    tracks = list(anim.tracks)
    for path, value in targets:
        for i, track in enumerate(tracks):
            if _same_target(scene, track.path, path):
                tracks[i] = Track(track.path, _with_key(track.keys, frame, value),
                                  interpolation=track.interpolation)
                break
        else:
            tracks.append(Track(path, [[frame, value]], interpolation=interpolation))
    fields = {name: getattr(scene, name) for name in Scene.model_fields}
    # every other setting of the animation (cyclic, fps, frames...) stays as it is
    fields["animation"] = anim.model_copy(update={"tracks": tracks})
    return Scene(**fields).with_base_dir(getattr(scene, "_base_dir", None))


def delete_keys(scene: Scene, targets: list[tuple[str, Any]], frame: int) -> Scene:
    """``scene`` without the keys at ``frame`` of the tracks that drive ``targets``' values;
    a track left without keys goes (the value keeps what the frame showed). The same scene
    when there is no such key."""
    if scene.animation is None:
        return scene
    tracks = []
    for track in scene.animation.tracks:
        if any(_same_target(scene, track.path, path) for path, _ in targets):
            keys = [[f, v] for f, v in track.keys if float(f) != float(frame)]
            if len(keys) == len(track.keys):
                tracks.append(track)
            elif keys:
                tracks.append(Track(track.path, keys, interpolation=track.interpolation))
        else:
            tracks.append(track)
    if tracks == scene.animation.tracks:
        return scene
    fields = {name: getattr(scene, name) for name in Scene.model_fields}
    fields["animation"] = scene.animation.model_copy(update={"tracks": tracks})
    return Scene(**fields).with_base_dir(getattr(scene, "_base_dir", None))


def tracks_following_items(scene: Scene, update: dict[str, Any]) -> Animation | None:
    """The animation of ``scene`` for the scene that ``update`` (new ``objects`` or
    ``lights`` lists) makes of it: a track keeps driving the same item when items are
    renamed, duplicated, added or moved (its path says the item's new name or index), and
    goes with an item that is deleted. None when nothing changes."""
    anim = scene.animation
    if anim is None or not any(kind in update for kind in ("objects", "lights")):
        return None
    tracks, changed = [], False
    for track in anim.tracks:
        steps = _item_steps(track.path)
        if steps is None or steps[0].key not in update:
            tracks.append(track)
            continue
        kind = str(steps[0].key)
        old_items, new_items = getattr(scene, kind), list(update[kind])
        try:
            index = resolve_path(scene, steps[:2])[1].key
        except PathError:
            tracks.append(track)
            continue
        item = old_items[index]
        moved = next((j for j, it in enumerate(new_items) if it is item), None)
        if moved is None and len(new_items) == len(old_items):
            moved = index  # edited in place (a rename, a new value)
        if moved is None:
            changed = True  # the item was deleted: its tracks go with it
            continue
        ref = _item_ref(new_items, moved) if isinstance(steps[1].key, str) else f"[{moved}]"
        path = str(steps[0].key) + ref + "".join(str(step) for step in steps[2:])
        changed = changed or path != track.path
        tracks.append(track if path == track.path else track.model_copy(update={"path": path}))
    if not changed:
        return None
    return anim.model_copy(update={"tracks": tracks})


def _item_steps(path: str) -> tuple | None:
    try:
        steps = parse_path(path)
    except PathError:
        return None
    if len(steps) < 2 or steps[0].key not in ("objects", "lights") or not steps[1].item:
        return None
    return steps


def _posable(scene: Scene, track: Track) -> tuple | None:
    """The resolved path of a track that posing may write into the scene's own values, or
    None: a path through an object's ``material`` is left to ``at_frame`` (setting it would
    give the object its own copy of a shared material)."""
    try:
        steps = resolve_path(scene, track.path)
    except PathError:
        return None
    if any(step.key == "material" for step in steps):
        return None
    return steps


def posed(scene: Scene, frame: int) -> Scene:
    """``scene`` with every value its tracks drive set to the track's value at ``frame``
    (the animation is kept). Values already equal are left alone, so a scene posed twice at
    the same frame is the same scene."""
    if scene.animation is None:
        return scene
    out = scene
    for i, track in enumerate(scene.animation.tracks):
        steps = _posable(scene, track)
        if steps is None:
            continue
        value = track_value(scene, i, frame)
        current = get_value(out, steps)
        if _plain(current) == _plain(value) or (current is None and _is_default(out, steps, value)):
            continue
        out = set_value(out, steps, value)
    if out is not scene:
        out = out.with_base_dir(getattr(scene, "_base_dir", None))
    return out


def unposed(scene: Scene, source: Scene | None) -> Scene:
    """``scene`` (posed at some frame) with the still values its tracks drive put back as
    ``source`` (the file as read) has them: what a save writes. The tracks give those
    values at every frame, so the file's own still values stay as written (a key inserted
    at a frame does not rewrite the still ``[camera] position``)."""
    if scene.animation is None or source is None:
        return scene
    out = scene
    for track in scene.animation.tracks:
        steps = _posable(scene, track)
        if steps is None:
            continue
        try:
            src_steps = resolve_path(source, track.path)
            if format_path(src_steps) != format_path(steps):
                continue  # items moved since the file was read: not the same value
            before = get_value(source, src_steps)
            if _plain(get_value(out, steps)) != _plain(before):
                out = set_value(out, steps, before)
        except (PathError, ValueError, TypeError, AttributeError):
            continue
    if out is not scene:
        out = out.with_base_dir(getattr(scene, "_base_dir", None))
    return out


def unkeyed_edits(scene: Scene, frame: int) -> list[str]:
    """The tracks (their paths) whose value in ``scene``, posed at ``frame``, was edited
    since and not keyed: the frame's pose would replace those edits."""
    if scene.animation is None:
        return []
    out = []
    for i, track in enumerate(scene.animation.tracks):
        steps = _posable(scene, track)
        if steps is None:
            continue
        current = get_value(scene, steps)
        value = track_value(scene, i, frame)
        if _plain(current) != _plain(value) and not (
                current is None and _is_default(scene, steps, value)):
            out.append(track.path)
    return out


def _is_default(scene: Scene, steps: tuple, value: Any) -> bool:
    """Whether ``value`` is what an unset field (None) at ``steps`` reads as."""
    try:
        filled = set_value(scene, steps, {})
    except (PathError, TypeError):
        return False
    return _plain(get_value(filled, steps)) == value


def frame_still(scene: Scene, frame: int) -> Scene:
    """The plain still the editor shows at ``frame`` of ``scene``, which was posed at
    ``frame``: the tracks that posing wrote are not applied again (so an unkeyed edit of a
    keyed value shows), the others are, with the frame's seed and mesh files."""
    if scene.animation is None:
        return scene_at_frame(scene, 0) if scene.is_animated else scene
    rest = [t for t in scene.animation.tracks if _posable(scene, t) is None]
    anim = scene.animation.model_copy(update={"tracks": rest})
    return scene_at_frame(scene.model_copy(update={"animation": anim}), frame)


def track_paths(scene: Scene) -> list[str]:
    """The concrete paths of the scene's tracks (for the timeline's key marks)."""
    out = []
    for track in scene.animation.tracks if scene.animation else []:
        try:
            out.append(format_path(resolve_path(scene, track.path)))
        except PathError:
            out.append(track.path)
    return out


def key_frames(scene: Scene) -> list[float]:
    """Every frame that holds a key, once each, in order."""
    if scene.animation is None:
        return []
    return sorted({float(f) for t in scene.animation.tracks for f, _ in t.keys})


__all__ = ["NEW_FPS", "NEW_FRAMES", "delete_keys", "frame_still", "insert_keys", "key_frames",
           "key_targets", "posed", "track_paths", "tracks_following_items", "unkeyed_edits",
           "unposed"]
