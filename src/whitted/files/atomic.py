"""Writing a file atomically: a reader sees the old content or the complete new one, never
a part; the temporary files of a writer that was killed are recognised and removed."""

from __future__ import annotations

import contextlib
import os
import pathlib
import tempfile
from collections.abc import Callable

PathLike = str | os.PathLike



def _current_umask() -> int:
    """The process umask, read without changing it where the platform allows."""
    with contextlib.suppress(OSError, ValueError), open("/proc/self/status") as f:
        for line in f:
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(directory: pathlib.Path) -> None:
    if os.name == "nt":
        return
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _temp_prefix(target: pathlib.Path) -> str:
    """Start of the names of ``target``'s temporary files (the name cut so that a temporary
    name stays within the 255-byte limit of file names)."""
    name = target.name
    while len(os.fsencode(name)) > 160:
        name = name[: len(name) * 3 // 4]
    return f".{name}.tmp-"


def _process_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # someone else's live process
    return True


def remove_stale_temporaries(path: PathLike) -> list[pathlib.Path]:
    """Delete the temporary files that writes of ``path`` left behind when their process was
    killed (their names carry the writer's process id; a live writer's file is kept).
    Returns the files removed."""
    target = pathlib.Path(path)
    prefix = _temp_prefix(target)
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    for entry in entries:
        if not (entry.name.startswith(prefix) and entry.name.endswith(target.suffix)):
            continue
        pid_text = entry.name[len(prefix):].split(".", 1)[0]
        if not pid_text.isdigit() or _process_alive(int(pid_text)):
            continue
        with contextlib.suppress(OSError):
            os.unlink(entry.path)
            removed.append(pathlib.Path(entry.path))
    return removed


def atomic_write(path: PathLike, write_fn: Callable[[str], object]) -> pathlib.Path:
    """Write a file atomically: ``path`` either keeps its old content or gets the complete new one.

    ``write_fn(tmp_path)`` is called with the path (str) of a fresh temporary file created with
    :func:`tempfile.mkstemp` in the same directory as ``path`` and with the same suffix, so a
    writer that picks its format from the extension still works. The temporary file is then
    fsynced, given the permissions of the file it replaces (or the umask default for a new
    file) and moved onto ``path`` with :func:`os.replace`. If anything raises, the temporary
    file is removed and the exception propagates. The temporary file's name carries the process
    id, so that temporary files of a writer that was killed (``kill -9``) are recognised and
    removed by the next write of the same path. Returns ``path`` as a :class:`pathlib.Path`.
    """
    target = pathlib.Path(path)
    directory = target.parent
    prefix = _temp_prefix(target)
    remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(suffix=target.suffix, prefix=f"{prefix}{os.getpid()}.",
                               dir=directory)
    os.close(fd)
    try:
        write_fn(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        try:
            mode = os.stat(target).st_mode & 0o7777
        except OSError:
            mode = 0o666 & ~_current_umask()
        with contextlib.suppress(OSError):
            os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(directory)
    return target
