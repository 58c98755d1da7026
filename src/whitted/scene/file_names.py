"""The model and texture files a scene names, and those names re-pointed when the scene is
saved in another folder."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

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
