"""Which files whitted wrote: the only files a command replaces at a name the user did not
give (a default output such as render.png, film.mp4 or sheet.png; the AOVs written beside
a picture, ``NAME.depth.npy``). Anything else there is someone else's, and is kept.

A file proves itself whitted's by what it carries: a PNG its ``Software: whitted`` text
(:mod:`.png`). A film's ``whitted`` comment (:mod:`.video`) survives a user's remux or
re-encode, so a film must also be recorded; a format that holds no mark at all (NPY: its
header is exactly three keys, and NumPy refuses any other) is recorded only. Recorded
(:func:`record_written`) when whitted writes it: its path, size and SHA-256 in the
per-user cache (``$WHITTED_CACHE_DIR/written/``, default ``~/.cache/whitted/written/``). Such
a file is whitted's while its bytes are those recorded; one copied in from elsewhere, changed
since, or written when the record could not be kept is treated as someone else's (the safe
side: the command ends in one line and nothing is written).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from pathlib import Path

from ..errors import OutputError

__all__ = ["check_replaceable", "record_written", "recorded_by_whitted", "written_by_whitted"]

#: The records' folder under the cache root.
RECORDS = "written"
#: A record's version (its first key).
RECORD_KIND = "whitted written file 1"
#: Records kept before those of files gone or changed since are swept away.
RECORDS_KEPT = 2000


def _records() -> Path:
    from ..jit.cache import cache_root

    return cache_root() / RECORDS


def _key(path: Path) -> str:
    return hashlib.sha256(os.fsencode(os.path.abspath(path))).hexdigest()[:40]


def _digest(path: Path) -> tuple[int, str]:
    h = hashlib.sha256()
    size = 0
    with open(path, "rb") as f:
        while block := f.read(1 << 20):
            h.update(block)
            size += len(block)
    return size, h.hexdigest()


def record_written(path: str | os.PathLike[str]) -> None:
    """Note that whitted has just written ``path`` (a film, or a file whose format holds no
    mark). A
    record that cannot be kept (no cache folder) is skipped: the file then counts as
    someone else's."""
    path = Path(path)
    from ..files import atomic_write

    with contextlib.suppress(OSError):
        size, digest = _digest(path)
        folder = _records()
        folder.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"kind": RECORD_KIND, "path": os.path.abspath(path), "size": size,
                           "sha256": digest})
        atomic_write(folder / f"{_key(path)}.json",
                     lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
        _sweep(folder)


def _sweep(folder: Path) -> None:
    """Past :data:`RECORDS_KEPT` records, remove those whose file is gone or has another
    size now (it is no longer what whitted wrote)."""
    entries = list(os.scandir(folder))
    if len(entries) <= RECORDS_KEPT:
        return
    for entry in entries:
        with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
            record = json.loads(Path(entry.path).read_bytes()[:4096])
            if os.stat(record["path"]).st_size == record["size"]:
                continue
        with contextlib.suppress(OSError):
            os.unlink(entry.path)


def recorded_by_whitted(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` holds the very bytes whitted recorded when it wrote it."""
    path = Path(path)
    try:
        if not path.is_file():
            return False
        raw = (_records() / f"{_key(path)}.json").read_bytes()[:4096]
        record = json.loads(raw)
        if not isinstance(record, dict) or record.get("kind") != RECORD_KIND \
                or record.get("path") != os.path.abspath(path):
            return False
        if record.get("size") != path.stat().st_size:
            return False
        return _digest(path) == (record["size"], record.get("sha256"))
    except (OSError, ValueError, KeyError, TypeError):
        return False


def written_by_whitted(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a file whitted wrote: it carries whitted's mark (PNG, MP4, GIF) or
    is one whitted recorded (:func:`recorded_by_whitted`). False for anything else, a file
    that cannot be read included."""
    from .png import written_by_whitted as png_is_whitteds
    from .video import film_written_by_whitted

    return (png_is_whitteds(path) or film_written_by_whitted(path)
            or recorded_by_whitted(path))


def exists(path: Path) -> bool:
    """Whether something is at ``path`` (a dangling link counts). False for a place that
    cannot be looked at: :func:`~.safety.check_outputs` says what is wrong with it."""
    try:
        return path.exists() or path.is_symlink()
    except (OSError, ValueError):
        return False


def check_replaceable(path: str | os.PathLike[str], hint: str) -> None:
    """:class:`OutputError` (one line) when something not whitted's is at ``path``, a name
    the user did not give; ``hint`` says what the user can do instead."""
    path = Path(path)
    if exists(path) and not written_by_whitted(path):
        raise OutputError(f"{path}: a file not marked as whitted's is there (someone else's, "
                          f"or an older whitted's); it is kept ({hint})")
