"""A run folder is whitted's only when whitted made it: the marker file, and the files it may
touch there.

``prepare(out, fresh=...)``:

* a missing folder is created with its marker (``MARKER``) first;
* an existing folder without the marker is taken only when none of the run's names is in it
  (``TOP_NAMES``; the user's other files there are left alone); else one line names the file;
* in a marked folder, whitted's files are the names it writes (``owned``); ``fresh`` removes
  those and nothing else; any other file or folder in the way of a name it writes is an error.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

from .case import CaseError

MARKER = ".whitted-stefan-run"
SUBFOLDERS = ("fields", "surfaces", "scenes")
TOP_FILES = ("case.toml", "series.csv", "series.png", "summary.json")
#: every name a run (and its film) writes at the top of the folder
TOP_NAMES = (*TOP_FILES, *SUBFOLDERS, "film.toml", "frames")
_OWNED = {
    "fields": re.compile(r"state_\d{4,}\.npz(\.part)?"),
    "surfaces": re.compile(r"(outer|inner)_\d{4,}\.ply(\.part)?"),
    "scenes": re.compile(r"frame_\d{4,}\.toml(\.part)?"),
}
_TOP_OWNED = re.compile(r"(case\.toml|series\.csv|series\.png|summary\.json)(\.part)?")


def is_marked(out: Path) -> bool:
    return (Path(out) / MARKER).is_file()


def owned(out: Path) -> list[Path]:
    """The files whitted wrote in a marked run folder (by name; temporaries included)."""
    out = Path(out)
    files = [p for p in out.iterdir() if _TOP_OWNED.fullmatch(p.name) and p.is_file()
             and not p.is_symlink()]
    for sub, pattern in _OWNED.items():
        folder = out / sub
        if folder.is_dir() and not folder.is_symlink():
            files += [p for p in folder.iterdir() if pattern.fullmatch(p.name)
                      and p.is_file() and not p.is_symlink()]
    return sorted(files)


def _in_the_way(out: Path) -> Path | None:
    """In a marked folder: a path whitted would write that is not a regular file of its own
    (a folder, a link), or a subfolder that is a file."""
    for name in TOP_FILES:
        p = out / name
        if p.is_symlink() or (p.exists() and not p.is_file()):
            return p
    for sub, pattern in _OWNED.items():
        folder = out / sub
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            return folder
        if folder.is_dir():
            for p in folder.iterdir():
                if pattern.fullmatch(p.name) and (p.is_symlink() or not p.is_file()):
                    return p
    return None


def prepare(out: Path, *, fresh: bool, digest: str) -> None:
    """Make ``out`` a run folder whitted may write (see the module docstring); CaseError (one
    line naming the path) when it is not one."""
    out = Path(out)
    if out.is_symlink() and not out.is_dir() or (out.exists() and not out.is_dir()):
        raise CaseError("exists and is not a folder", file=str(out))
    try:
        if not out.exists():
            out.mkdir(parents=True)
            _mark(out, digest)
        elif not is_marked(out):
            taken = sorted(p.name for p in out.iterdir() if p.name in TOP_NAMES)
            if taken:
                raise CaseError(f"holds {taken[0]!r}, which whitted did not write (no "
                                f"{MARKER} marker): use a new or empty folder",
                                file=str(out))
            _mark(out, digest)
        blocked = _in_the_way(out)
        if blocked is not None:
            raise CaseError("is in the way of a file the run writes (not a file whitted "
                            "wrote): move it or use another folder", file=str(blocked))
        if fresh:
            for p in owned(out):
                p.unlink()
        for sub in SUBFOLDERS:
            (out / sub).mkdir(exist_ok=True)
    except PermissionError as exc:
        raise CaseError(f"cannot write there: {exc.strerror}",
                        file=str(exc.filename or out)) from None
    except OSError as exc:
        raise CaseError(f"cannot prepare the run folder: {exc.strerror or exc}",
                        file=str(exc.filename or out)) from None


def _mark(out: Path, digest: str) -> None:
    data = json.dumps({"whitted": "stefan run", "case_digest": digest}).encode()
    tmp = out / (MARKER + ".part")
    tmp.write_bytes(data)
    os.replace(tmp, out / MARKER)


__all__ = ["MARKER", "is_marked", "owned", "prepare"]
