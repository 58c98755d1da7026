"""Reading the files a user names, safely: only regular files, never more than a size limit.

A path that is a device (``/dev/zero``), a named pipe, a socket, a folder, a broken link or a
link loop is refused with one line that says what it is, before anything is read; a regular
file larger than the limit is refused before it is read. The file is opened non-blocking (a
pipe swapped in after the check cannot hang the reader) and checked again through its open
handle.
"""

from __future__ import annotations

import errno
import mmap
import os
import stat
from pathlib import Path

from ..errors import SceneError

MiB = 1 << 20
GiB = 1 << 30


def kind_of(mode: int) -> str | None:
    """What a non-regular file is, in words (None for a regular file)."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def path_problem(path: str | os.PathLike[str]) -> str | None:
    """Why ``path`` cannot be read as a regular file (one phrase), or None when it can."""
    try:
        status = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            return "a broken symbolic link (its target does not exist)"
        return "no such file"
    except OSError as exc:
        return _os_problem(exc)
    except ValueError:  # an embedded NUL byte
        return "not a valid file name"
    kind = kind_of(status.st_mode)
    if kind is None:
        return None
    return f"is {kind}, not a regular file"


def _os_problem(exc: OSError) -> str:
    if exc.errno == errno.ELOOP:
        return "a symbolic link loop"
    if exc.errno == errno.ENAMETOOLONG:
        return "file name too long"
    if exc.errno == errno.ENOTDIR:
        return "a part of the path is not a folder"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    return f"cannot read: {exc.strerror or exc}"


def _size_text(n: int) -> str:
    if n >= GiB:
        return f"{n / GiB:.1f} GiB"
    if n >= MiB:
        return f"{n / MiB:.1f} MiB"
    return f"{n} bytes"


def open_regular(path: str | os.PathLike[str], limit: int, what: str = "file",
                 name: str | None = None) -> int:
    """An open read-only descriptor of the regular file ``path`` of at most ``limit`` bytes;
    :class:`SceneError` naming ``name`` (default: the path) for anything else."""
    name = os.fspath(path) if name is None else name
    problem = path_problem(path)
    if problem is not None:
        raise SceneError(problem, file=name)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise SceneError(_os_problem(exc), file=name) from None
    try:
        status = os.fstat(fd)
        kind = kind_of(status.st_mode)
        if kind is not None:
            raise SceneError(f"is {kind}, not a regular file", file=name)
        if status.st_size > limit:
            raise SceneError(f"{what} too large: {_size_text(status.st_size)} (the limit is "
                             f"{_size_text(limit)})", file=name)
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_limited(path: str | os.PathLike[str], limit: int, what: str = "file",
                 name: str | None = None) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit`` bytes, else SceneError)."""
    fd = open_regular(path, limit, what, name)
    try:
        with os.fdopen(fd, "rb", closefd=True) as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise SceneError(_os_problem(exc), file=os.fspath(path) if name is None else name) from None
    if len(data) > limit:  # grew while we read it
        raise SceneError(f"{what} too large (the limit is {_size_text(limit)})",
                         file=os.fspath(path) if name is None else name)
    return data


def map_limited(path: str | os.PathLike[str], limit: int, what: str = "file",
                name: str | None = None) -> bytes | mmap.mmap:
    """Like :func:`read_limited`, but a large file is memory-mapped (read on demand by the
    pages touched) instead of read whole: a reader that stops at the first bad byte of a huge
    file touches only the start of it."""
    fd = open_regular(path, limit, what, name)
    try:
        size = os.fstat(fd).st_size
        if size < 16 * MiB:
            with os.fdopen(fd, "rb", closefd=False) as f:
                return f.read(limit + 1)
        return mmap.mmap(fd, size, access=mmap.ACCESS_READ)
    except OSError as exc:
        raise SceneError(_os_problem(exc), file=os.fspath(path) if name is None else name) from None
    finally:
        os.close(fd)


def head_bytes(path: str | os.PathLike[str], count: int, limit: int, what: str = "file",
               name: str | None = None) -> bytes:
    """The first ``count`` bytes of a regular file of at most ``limit`` bytes."""
    fd = open_regular(path, limit, what, name)
    with os.fdopen(fd, "rb") as f:
        return f.read(count)


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether two paths name one file (the same resolved path, or the same inode)."""
    try:
        if Path(a).resolve() == Path(b).resolve():
            return True
    except (OSError, RuntimeError, ValueError):
        pass
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False
