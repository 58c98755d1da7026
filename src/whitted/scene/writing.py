"""Writing scene files (TOML or JSON, one schema): the one writer of scene files, used by
``whitted.save_scene``, ``Scene.save`` and the editor. A TOML file whose text is known is
edited in place (:mod:`.toml_document`: only the changed values, comments kept); without it
a compact, readable file is written. Relative model and texture file names are re-pointed
once when the file goes to another folder (:mod:`.file_names`)."""

from __future__ import annotations

import errno
import json
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import OutputError, SceneError
from ..files import atomic_write
from .file_names import named_files, rebase_files

if TYPE_CHECKING:
    from .scene import Scene


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    return scene.model_dump(mode="json", exclude_none=True)


def _suffix(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".json"):
        raise SceneError(f"unknown scene format {path.suffix!r} (use .toml or .json)",
                         file=str(path))
    return suffix


def for_folder(scene: Scene, path: str | Path) -> Scene:
    """``scene`` as saved at ``path``: relative file names re-pointed from its folder."""
    folder = Path(path).parent
    if folder.resolve() != scene.base_dir.resolve():
        return rebase_files(scene, folder)
    return scene


def scene_text(scene: Scene, path: str | Path, *, text: str | None = None,
               loaded: Scene | None = None,
               history: Iterable[tuple[str, Scene]] = ()) -> str:
    """What the file ``path`` holds once ``scene`` (already :func:`for_folder`) is saved
    there: TOML (``text``, which loaded as ``loaded``, with only the edits written into it;
    else compact) or JSON, by the file's extension."""
    if _suffix(Path(path)) == ".json":
        return json.dumps(scene_to_dict(scene), indent=2) + "\n"
    from .toml_document import scene_toml

    return scene_toml(scene, text=text, loaded=loaded, history=history)


def write_scene_text(path: str | Path, payload: str) -> Path:
    """Write ``payload`` to ``path`` atomically; OutputError with one line when the folder
    cannot take it ("cannot write PATH: permission denied")."""
    path = Path(path)
    try:
        atomic_write(path, lambda tmp: Path(tmp).write_text(payload, encoding="utf-8"))
    except OSError as exc:
        reason = (exc.strerror or errno.errorcode.get(exc.errno or 0, str(exc))).lower()
        raise OutputError(f"cannot write {path}: {reason}") from None
    return path


def save_scene(scene: Scene, path: str | Path, *, text: str | None = None,
               loaded: Scene | None = None) -> Path:
    """Write ``scene`` as TOML or JSON (by extension), atomically. Relative model and texture
    file names are rewritten to stay valid from the new file's folder. ``text`` (a TOML
    file's text in the same folder, which loaded as ``loaded``) is edited in place."""
    path = Path(path)
    _suffix(path)
    if path.parent.resolve() != scene.base_dir.resolve():
        text = loaded = None  # another folder: its file names change, written afresh
    moved = for_folder(scene, path)
    write_scene_text(path, scene_text(moved, path, text=text, loaded=loaded))
    return path


__all__ = ["for_folder", "named_files", "rebase_files", "save_scene", "scene_text",
           "scene_to_dict", "write_scene_text"]
