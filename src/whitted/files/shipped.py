"""The scenes that come with whitted: the examples (with their models and textures) and the
benchmark scenes. In a checkout they are its ``examples/`` and ``benchmarks/`` folders; an
installed wheel carries them as package data, ``whitted/examples/`` and
``whitted/benchmarks/`` (setup.py). Examples render by short name (``glass_cube``) and
``whitted examples DIR`` copies them out, never over a file that is there."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from ..errors import ArgumentError

#: folder -> a file that marks it as whitted's
MARKERS = {"examples": "glass_cube.toml", "benchmarks": "seed000.toml"}


def shipped_dir(name: str) -> Path | None:
    """Whitted's ``examples`` or ``benchmarks`` folder: the installed package's, or the
    checkout's this source runs from; None when neither is there."""
    for parent in Path(__file__).resolve().parents:
        candidate = parent / name
        if (candidate / MARKERS[name]).is_file():
            return candidate
    return None


def example_names() -> dict[str, Path]:
    """Short name -> scene file of every example scene (``glass_cube``); the Stefan cases in
    ``stefan/`` are not scenes and go by their path."""
    folder = shipped_dir("examples")
    if folder is None:
        return {}
    return {p.stem: p for p in sorted(folder.glob("*.toml"))}


def example_path(name: str) -> Path | None:
    """The example scene a short name (no folder, no suffix) names, or None."""
    if not name or os.sep in name or "." in name:
        return None
    return example_names().get(name)


def example_files() -> list[Path]:
    """Every file of the examples, relative to their folder (scenes, models, textures)."""
    folder = shipped_dir("examples")
    if folder is None:
        return []
    return sorted(p.relative_to(folder) for p in folder.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


def copy_examples(target: str | os.PathLike[str]) -> tuple[list[Path], list[Path]]:
    """Copy the examples into the folder ``target`` (made if missing): each file whose place
    is free, atomically; a file already there is kept as it is, whatever it holds. Returns
    (copied, kept), relative paths. ArgumentError for a target that cannot be a folder."""
    folder = shipped_dir("examples")
    if folder is None:
        raise ArgumentError("whitted's examples are not installed with this copy of whitted")
    dest = Path(target)
    if dest.exists() and not dest.is_dir():
        raise ArgumentError(f"{dest}: is a file, not a folder")
    copied: list[Path] = []
    kept: list[Path] = []
    for rel in example_files():
        out = dest / rel
        if out.exists() or out.is_symlink():
            kept.append(rel)
            continue
        out.parent.mkdir(parents=True, exist_ok=True)
        if _copy_new(folder / rel, out):
            copied.append(rel)
        else:
            kept.append(rel)
    return copied, kept


def _copy_new(source: Path, out: Path) -> bool:
    """Copy ``source`` to ``out`` if nothing is at ``out``: written to a temporary file beside
    it, then linked into place, which fails rather than replace a file that appeared
    meanwhile (another process). False when ``out`` was taken."""
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent)
    os.close(fd)
    try:
        shutil.copyfile(source, tmp)
        try:
            os.link(tmp, out)
        except FileExistsError:
            return False
        except OSError:  # a file system without hard links: create exclusively
            try:
                with open(out, "xb") as f, open(tmp, "rb") as src:
                    shutil.copyfileobj(src, f)
            except FileExistsError:
                return False
        return True
    finally:
        Path(tmp).unlink(missing_ok=True)
