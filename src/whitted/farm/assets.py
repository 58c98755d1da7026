"""The files a scene names, shipped to workers that cannot see them.

On the client, :func:`collect_assets` finds every file the scenes name (any ``file`` field:
mesh models, image textures, and the per-frame files of a mesh sequence once a film's frames
are plain scenes) and the files those name in turn (an OBJ's MTL libraries and their
``map_Kd`` images, a glTF's buffers and images). Each file is addressed by the SHA-256 of its
bytes. Their common folder becomes the *tree*: every file keeps its path relative to it, so
the relative names inside scenes and model files keep working.

On a worker, :func:`materialise` writes each blob once into the worker's cache folder
(``<cache>/blobs/<sha256>``, atomically) and links it into ``<cache>/trees/<tree key>/<path>``
(a hard link, or a copy where links are not possible); :func:`worker_scene` re-points the scene
at that tree (its base folder, and its absolute file names). A file already cached is never
written again, whichever scene or run asked for it.

With ``assets="shared"`` (or ``"auto"`` when every worker already sees every file at the same
path with the same size and modification time: a shared file system, or a LocalCluster) the
scene is used as is and nothing is shipped.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import unquote

from pydantic import BaseModel

from ..errors import SceneError
from ..scene.scene import Scene

ASSET_KEY_PREFIX = "whitted-asset-"
CACHE_ENV = "WHITTED_FARM_CACHE"  # a worker's asset cache folder (default: its local_directory)
_MTLLIB = re.compile(rb"^[ \t]*mtllib[ \t]+([^\r\n]*)", re.MULTILINE)
_MAP = re.compile(r"^[ \t]*map_\w+[ \t]+(.*)$", re.MULTILINE | re.IGNORECASE)


# ------------------------------------------------------------------ the files a scene names

def map_file_names(value: Any, rename: Callable[[str], str]) -> Any:
    """``value`` (a scene or any part of one) with every ``file`` field passed through
    ``rename``; parts with nothing renamed are shared, not copied."""
    if isinstance(value, BaseModel):
        update = {}
        for name in type(value).model_fields:
            item = getattr(value, name)
            if name == "file" and isinstance(item, str):
                new = rename(item)
            else:
                new = map_file_names(item, rename)
            if new is not item:
                update[name] = new
        return value.model_copy(update=update) if update else value
    if isinstance(value, (list, tuple)):
        items = [map_file_names(v, rename) for v in value]
        changed = any(a is not b for a, b in zip(items, value, strict=True))
        return type(value)(items) if changed else value
    if isinstance(value, dict):
        mapped = {k: map_file_names(v, rename) for k, v in value.items()}
        changed = any(mapped[k] is not value[k] for k in value)
        return mapped if changed else value
    return value


def scene_file_names(scene: Scene) -> list[str]:
    """Every file name the scene holds (``file`` fields), as written, in scene order."""
    names: list[str] = []

    def note(name: str) -> str:
        if name not in names:
            names.append(name)
        return name

    map_file_names(scene, note)
    return names


def _absolute(path: Path) -> Path:
    """Absolute and normalised, symbolic links kept (a model's own references are relative to
    the folder it is named in, link or not)."""
    return Path(os.path.abspath(os.path.expanduser(path)))


def _existing(folder: Path, name: str) -> Path | None:
    """The file ``name`` names relative to ``folder``, tried as the loaders try it (as written,
    with Windows separators turned, then the bare file name)."""
    for candidate in (name, name.replace("\\", "/"), Path(name.replace("\\", "/")).name):
        if candidate and (folder / candidate).is_file():
            return _absolute(folder / candidate)
    return None


def _split_names(argument: str) -> list[str]:
    from ..assets.mtl import split_escaped

    whole = argument.strip()
    return [whole] + split_escaped(whole) if whole else []


def model_dependencies(path: Path) -> list[Path]:
    """The files a model file names in turn: an OBJ's MTL libraries and their texture maps,
    a glTF's buffers and images. Missing ones are left out (the loader warns about them)."""
    suffix = path.suffix.lower()
    found: list[Path] = []
    if suffix == ".obj":
        data = path.read_bytes()
        for match in _MTLLIB.finditer(data):
            for name in _split_names(match.group(1).decode("utf-8", "replace")):
                library = _existing(path.parent, name)
                if library is None or library in found:
                    continue
                found.append(library)
                text = library.read_bytes().decode("utf-8", "replace")
                for map_line in _MAP.finditer(text):
                    tokens = _split_names(map_line.group(1))
                    # the file name is the whole argument or its last word (after the options)
                    for name_ in (tokens[:1] + tokens[-1:]) if tokens else []:
                        image = _existing(library.parent, name_)
                        if image is not None and image not in found:
                            found.append(image)
    elif suffix == ".gltf":
        with contextlib.suppress(OSError, ValueError, AttributeError, TypeError):
            document = json.loads(path.read_text(encoding="utf-8"))
            for item in document.get("buffers", []) + document.get("images", []):
                uri = item.get("uri", "")
                if uri and not uri.startswith("data:"):
                    file = path.parent / unquote(uri)
                    if file.is_file() and _absolute(file) not in found:
                        found.append(_absolute(file))
    return found


def file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


@dataclass(frozen=True)
class AssetManifest:
    """What a worker needs to rebuild the scenes' files: ``files`` maps each file's path
    relative to the tree (POSIX) to its SHA-256; ``base`` is the scenes' base folder relative
    to the tree; ``client_root`` the tree's folder on the client (for absolute names)."""

    files: dict[str, str]
    base: str
    client_root: str
    #: each file's absolute path on the client with (size, mtime_ns): the shared-FS check
    stamps: dict[str, tuple[int, int]] = field(default_factory=dict, compare=False)

    @property
    def key(self) -> str:
        h = hashlib.sha256(json.dumps([sorted(self.files.items()), self.base]).encode())
        return h.hexdigest()[:24]

    @property
    def total_bytes(self) -> int:
        return sum(size for size, _ in self.stamps.values())

    def subset(self, relpaths: Iterable[str]) -> AssetManifest:
        """The same tree, with only some of its files (what one task needs)."""
        wanted = set(relpaths)
        return AssetManifest({p: s for p, s in self.files.items() if p in wanted}, self.base,
                             self.client_root, {})


def scene_assets(scene: Scene) -> list[Path]:
    """Every file ``scene`` needs, absolute: the files it names, then theirs."""
    files: list[Path] = []
    for name in scene_file_names(scene):
        path = _absolute(scene.resolve_path(name))
        if not path.is_file():
            raise SceneError(f"'{name}': no such file ({path})")
        if path not in files:
            files.append(path)
        for dependency in model_dependencies(path):
            if dependency not in files:
                files.append(dependency)
    return files


def file_stamps(scenes: Iterable[Scene]) -> tuple[dict[str, tuple[int, int]],
                                                  list[list[Path]]]:
    """(size, mtime_ns) of every file the scenes need, by absolute path, and each scene's
    files: cheap (no file is read), enough to tell whether workers see the same files."""
    per_scene = [scene_assets(s) for s in scenes]
    stamps = {}
    for p in sorted({p for files in per_scene for p in files}):
        st = p.stat()
        stamps[str(p)] = (st.st_size, st.st_mtime_ns)
    return stamps, per_scene


def collect_assets(scenes: Iterable[Scene], stamped: tuple | None = None
                   ) -> tuple[AssetManifest, dict[str, Path], list[list[str]]]:
    """The manifest of every file the scenes need (they share one base folder), each blob's
    client path by digest, and, per scene, the tree paths that scene needs. ``stamped``:
    :func:`file_stamps` of the same scenes, when already made."""
    scenes = list(scenes)
    base = _absolute(scenes[0].base_dir)
    stamps, per_scene = stamped if stamped is not None else file_stamps(scenes)
    every = [Path(name) for name in stamps]
    root = Path(os.path.commonpath([base, *every])) if every else base
    digests: dict[Path, str] = {p: file_digest(p) for p in every}
    files = {p.relative_to(root).as_posix(): digests[p] for p in every}
    manifest = AssetManifest(files, base.relative_to(root).as_posix(), str(root), stamps)
    blobs = {digests[p]: p for p in every}
    needs = [[p.relative_to(root).as_posix() for p in files_] for files_ in per_scene]
    return manifest, blobs, needs


def files_visible(stamps: dict[str, tuple[int, int]]) -> bool:
    """True when this machine sees every file at the same path with the same size and
    modification time (run on each worker: a shared file system needs no shipping)."""
    for name, (size, mtime) in stamps.items():
        try:
            st = os.stat(name)
        except OSError:
            return False
        if (st.st_size, st.st_mtime_ns) != (size, mtime):
            return False
    return True


# ------------------------------------------------------------------ on the worker

_lock = threading.Lock()


def asset_cache_dir() -> Path:
    """This worker's asset cache: ``$WHITTED_FARM_CACHE``, else ``whitted-assets`` in the
    Dask worker's local directory, else in the system's temporary folder."""
    chosen = os.environ.get(CACHE_ENV)
    if chosen:
        return Path(chosen)
    try:
        from distributed import get_worker

        return Path(get_worker().local_directory) / "whitted-assets"
    except (ImportError, ValueError):
        import tempfile

        return Path(tempfile.gettempdir()) / "whitted-assets"


def _write_once(target: Path, write: Callable[[Path], None]) -> None:
    """Make ``target`` with ``write(tmp)`` then a rename, unless it exists: readers never see
    a half-written file, and two writers of the same content both succeed."""
    if target.exists():
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def materialise(manifest: AssetManifest, blobs: dict[str, bytes],
                cache: Path | None = None) -> Path:
    """Write the manifest's files into this worker's cache (each blob once, checked against
    its digest) and return the tree's folder."""
    cache = cache or asset_cache_dir()
    tree = cache / "trees" / manifest.key
    with _lock:
        for relpath, digest in manifest.files.items():
            blob = cache / "blobs" / digest
            if not blob.exists():
                data = blobs[digest]
                if hashlib.sha256(data).hexdigest() != digest:
                    raise OSError(f"{relpath}: the bytes received do not match their digest")
                _write_once(blob, lambda tmp, data=data: tmp.write_bytes(data))
            target = tree.joinpath(*relpath.split("/"))

            def link(tmp: Path, blob: Path = blob) -> None:
                try:
                    os.link(blob, tmp)
                except OSError:  # another file system, or links not allowed
                    import shutil

                    shutil.copyfile(blob, tmp)

            _write_once(target, link)
    return tree


def worker_scene(scene: Scene, manifest: AssetManifest, tree: Path) -> Scene:
    """``scene`` re-pointed at the worker's copy of its files: relative names resolve in the
    tree's copy of the base folder, absolute names are moved into the tree."""
    root = Path(manifest.client_root)

    def rename(name: str) -> str:
        path = Path(name).expanduser()
        if not path.is_absolute():
            return name
        return str(tree / _absolute(path).relative_to(root))

    moved = map_file_names(scene, rename)
    return moved.with_base_dir(tree.joinpath(*manifest.base.split("/")) if manifest.base != "."
                               else tree)
