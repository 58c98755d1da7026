"""Writing scene files (TOML or JSON, one schema), and the model and texture files a scene
names, re-pointed when the scene is saved in another folder."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import tomli_w

from ..errors import SceneError
from ..files import atomic_write
from .animation import animation_toml
from .materials import Material
from .timeline import is_sequence, sequence_file

if TYPE_CHECKING:
    from .scene import Scene


def named_files(scene: Scene) -> list[tuple[list[str | int], str]]:
    """(key path, file name) of every model and texture file the scene names."""
    named: list[tuple[list[str | int], str]] = []

    def walk(objects, keys: list[str | int]) -> None:  # CSG objects' children too
        for i, obj in enumerate(objects):
            if getattr(obj, "file", None):
                named.append(([*keys, i, "file"], obj.file))
            mat = obj.material
            if isinstance(mat, Material) and getattr(mat.texture, "file", None):
                named.append(([*keys, i, "material", "texture", "file"], mat.texture.file))
            children = getattr(obj, "objects", None)
            if obj.type == "csg" and children:
                walk(children, [*keys, i, "objects"])

    walk(scene.objects, ["objects"])
    for key, mat in scene.materials.items():
        if mat.texture is not None and getattr(mat.texture, "file", None):
            named.append((["materials", key, "texture", "file"], mat.texture.file))

    expanded: list[tuple[list[str | int], str]] = []
    for keys, pattern in named:
        if len(keys) == 3 and is_sequence(pattern):  # a mesh sequence: every frame's file
            expanded.extend((keys, sequence_file(pattern, k)) for k in range(scene.frame_count))
        else:
            expanded.append((keys, pattern))
    return expanded


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

    def rebased(objects: list) -> list:  # CSG objects' children too
        out = []
        for obj in objects:
            update: dict[str, Any] = {}
            if getattr(obj, "file", None):
                update["file"] = moved(obj.file)
            mat = obj.material
            if isinstance(mat, Material) and getattr(mat.texture, "file", None):
                tex = mat.texture.model_copy(update={"file": moved(mat.texture.file)})
                update["material"] = mat.model_copy(update={"texture": tex})
            if obj.type == "csg":
                update["objects"] = rebased(obj.objects)
            out.append(obj.model_copy(update=update) if update else obj)
        return out

    objects = rebased(scene.objects)
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
    path = Path(path)
    if path.parent.resolve() != scene.base_dir.resolve():
        scene = rebase_files(scene, path.parent)
    suffix = path.suffix.lower()
    data = scene_to_dict(scene)
    if suffix == ".toml":
        animation = data.pop("animation", None)
        text = tomli_w.dumps(data)
        if animation is not None:  # one key per line, not one number per line

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
