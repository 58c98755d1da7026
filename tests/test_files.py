"""files/: reading only regular files within a size limit (every kind of path that is not one
gets its own phrase), memory-mapping large files, and atomic writes that leave no temporary
file behind and keep the replaced file's permissions."""

from __future__ import annotations

import errno
import mmap
import os
import socket
import stat
from pathlib import Path

import pytest

from whitted.errors import SceneError
from whitted.files import atomic as atomic_mod
from whitted.files import reading
from whitted.files.atomic import atomic_write, remove_stale_temporaries
from whitted.files.reading import (
    GiB,
    MiB,
    head_bytes,
    kind_of,
    map_limited,
    open_regular,
    path_problem,
    read_limited,
    same_file,
)


@pytest.mark.parametrize(("mode", "words"), [
    (stat.S_IFREG, None),
    (stat.S_IFDIR, "a directory"),
    (stat.S_IFCHR, "a character device"),
    (stat.S_IFBLK, "a block device"),
    (stat.S_IFIFO, "a named pipe (FIFO)"),
    (stat.S_IFSOCK, "a socket"),
    (stat.S_IFLNK, "not a regular file"),
])
def test_every_kind_of_file_is_named(mode, words):
    assert kind_of(mode | 0o644) == words


def test_paths_that_are_not_regular_files(tmp_path):
    assert path_problem(tmp_path / "none") == "no such file"
    (tmp_path / "broken").symlink_to(tmp_path / "gone")
    assert path_problem(tmp_path / "broken") == \
        "a broken symbolic link (its target does not exist)"
    (tmp_path / "loop_a").symlink_to(tmp_path / "loop_b")
    (tmp_path / "loop_b").symlink_to(tmp_path / "loop_a")
    assert path_problem(tmp_path / "loop_a") == "a symbolic link loop"
    assert path_problem(tmp_path / ("x" * 300)) == "file name too long"
    (tmp_path / "plain").write_text("x")
    assert path_problem(tmp_path / "plain" / "under") == "a part of the path is not a folder"
    assert path_problem("bad\0name") == "not a valid file name"
    assert path_problem(tmp_path) == "is a directory, not a regular file"
    assert path_problem("/dev/null") == "is a character device, not a regular file"
    os.mkfifo(tmp_path / "fifo")
    assert path_problem(tmp_path / "fifo") == "is a named pipe (FIFO), not a regular file"
    sock = socket.socket(socket.AF_UNIX)
    try:
        sock.bind(str(tmp_path / "sock"))
        assert path_problem(tmp_path / "sock") == "is a socket, not a regular file"
    finally:
        sock.close()
    assert path_problem(tmp_path / "plain") is None


def test_os_errors_in_words(monkeypatch, tmp_path):
    def raising(err):
        def fake_stat(path, *args, **kwargs):
            raise OSError(err, os.strerror(err))
        return fake_stat

    monkeypatch.setattr(reading.os, "stat", raising(errno.EACCES))
    assert path_problem(tmp_path / "f") == "permission denied"
    monkeypatch.setattr(reading.os, "stat", raising(errno.EIO))
    assert path_problem(tmp_path / "f") == "cannot read: Input/output error"


def test_a_file_that_cannot_be_opened_is_one_line(monkeypatch, tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text("x")

    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(reading.os, "open", denied)
    with pytest.raises(SceneError) as info:
        open_regular(path, 10, name="scene.toml")
    assert str(info.value) == "scene.toml: permission denied"


def test_a_path_swapped_for_a_fifo_after_the_check_is_refused_through_its_handle(
        monkeypatch, tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    monkeypatch.setattr(reading, "path_problem", lambda path: None)  # the check passed
    with pytest.raises(SceneError) as info:
        open_regular(fifo, 10)  # non-blocking: no writer, yet it does not hang
    assert str(info.value) == f"{fifo}: is a named pipe (FIFO), not a regular file"


def test_size_limits_in_words(tmp_path):
    path = tmp_path / "big.bin"
    path.write_bytes(b"x" * 2000)
    with pytest.raises(SceneError) as info:
        read_limited(path, 1000, what="model", name="big.bin")
    assert str(info.value) == "big.bin: model too large: 2000 bytes (the limit is 1000 bytes)"
    with open(path, "r+b") as f:
        f.truncate(3 * MiB + MiB // 2)
    with pytest.raises(SceneError) as info:
        read_limited(path, 2 * MiB, name="big.bin")
    assert str(info.value) == "big.bin: file too large: 3.5 MiB (the limit is 2.0 MiB)"
    with pytest.raises(SceneError) as info:
        read_limited(tmp_path, GiB + GiB // 2)
    assert str(info.value) == f"{tmp_path}: is a directory, not a regular file"
    assert reading._size_text(3 * GiB) == "3.0 GiB"


class _GrowingFile:
    """A file object whose file grows by ``extra`` bytes after its size was read."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0

    def read(self, n: int) -> bytes:
        piece = self.data[self.pos:self.pos + n]
        self.pos += len(piece)
        return piece


def test_a_file_that_grows_while_read_is_read_up_to_the_limit_plus_one():
    # size 4 at the check, 10 bytes by the time it is read: pieces up to limit + 1
    assert reading._read_at_most(_GrowingFile(b"0123456789"), 4, 100) == b"0123456789"
    assert reading._read_at_most(_GrowingFile(b"0123456789"), 4, 7) == b"01234567"
    assert reading._read_at_most(_GrowingFile(b"0123456789"), 4, 4) == b"01234"


def test_read_limited_refuses_a_file_that_grew_past_the_limit(monkeypatch, tmp_path):
    path = tmp_path / "log.txt"
    path.write_bytes(b"abc")
    monkeypatch.setattr(reading, "_read_at_most", lambda f, size, limit: b"x" * (limit + 1))
    with pytest.raises(SceneError) as info:
        read_limited(path, 3, what="log")
    assert str(info.value) == f"{path}: log too large (the limit is 3 bytes)"


def test_errors_while_reading_are_one_line(monkeypatch, tmp_path):
    path = tmp_path / "m.obj"
    path.write_bytes(b"v 0 0 0\n")

    def fail(err):
        def read(f, size, limit):
            if err is MemoryError:
                raise MemoryError
            raise OSError(err, os.strerror(err))
        return read

    monkeypatch.setattr(reading, "_read_at_most", fail(errno.EIO))
    with pytest.raises(SceneError) as info:
        read_limited(path, 100, name="m.obj")
    assert str(info.value) == "m.obj: cannot read: Input/output error"
    monkeypatch.setattr(reading, "_read_at_most", fail(MemoryError))
    with pytest.raises(SceneError) as info:
        read_limited(path, 100, what="model", name="m.obj")
    assert str(info.value) == (
        "m.obj: model too large for the memory this process may use: 8 bytes could not be "
        "read (a memory or address-space limit such as ulimit -v)")
    with pytest.raises(SceneError) as info:
        map_limited(path, 100, what="model", name="m.obj")
    assert "model too large for the memory this process may use: 8 bytes" in str(info.value)
    monkeypatch.setattr(reading, "_read_at_most", fail(errno.ENOMEM))
    with pytest.raises(SceneError) as info:
        map_limited(path, 100, what="model", name="m.obj")
    assert "could not be read (a memory or address-space limit" in str(info.value)
    monkeypatch.setattr(reading, "_read_at_most", fail(errno.EIO))
    with pytest.raises(SceneError) as info:
        map_limited(path, 100, name="m.obj")
    assert str(info.value) == "m.obj: cannot read: Input/output error"


def test_small_files_are_read_and_large_ones_mapped(tmp_path):
    small = tmp_path / "small.bin"
    small.write_bytes(b"hello")
    data = map_limited(small, 100)
    assert isinstance(data, bytes) and data == b"hello"
    large = tmp_path / "large.bin"
    with open(large, "wb") as f:
        f.write(b"START")
        f.truncate(17 * MiB)  # sparse: no 17 MiB written
    mapped = map_limited(large, 32 * MiB)
    try:
        assert isinstance(mapped, mmap.mmap)
        assert len(mapped) == 17 * MiB and mapped[:5] == b"START" and mapped[-1] == 0
    finally:
        mapped.close()
    assert head_bytes(large, 5, 32 * MiB) == b"START"
    with pytest.raises(SceneError, match=r"file too large: 17.0 MiB \(the limit is 16.0 MiB\)"):
        head_bytes(large, 5, 16 * MiB)


def test_same_file(tmp_path):
    a = tmp_path / "a.png"
    a.write_bytes(b"x")
    (tmp_path / "link.png").symlink_to(a)
    os.link(a, tmp_path / "hard.png")
    assert same_file(a, tmp_path / "sub" / ".." / "a.png")
    assert same_file(a, tmp_path / "link.png")
    assert same_file(a, tmp_path / "hard.png")  # another name of the same inode
    assert not same_file(a, tmp_path / "missing.png")
    assert not same_file(a, "bad\0name")


# ---------------------------------------------------------------------- atomic writes


def test_a_replaced_file_keeps_its_mode_and_a_new_one_follows_the_umask(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    target.chmod(0o640)
    atomic_write(target, lambda tmp: Path(tmp).write_text("new"))
    assert target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    old = os.umask(0o027)
    try:
        fresh = atomic_write(tmp_path / "fresh.txt", lambda tmp: Path(tmp).write_text("x"))
    finally:
        os.umask(old)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fresh.txt", "out.txt"]


def test_the_umask_without_proc(monkeypatch):
    def no_proc(*args, **kwargs):
        raise OSError(errno.ENOENT, "no /proc")

    monkeypatch.setattr("builtins.open", no_proc)
    old = os.umask(0o037)
    try:
        assert atomic_mod._current_umask() == 0o037
        assert os.umask(0o037) == 0o037  # read without being changed
    finally:
        os.umask(old)


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "image.png"
    target.write_bytes(b"old")

    def half_then_fail(tmp):
        Path(tmp).write_bytes(b"ne")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atomic_write(target, half_then_fail)
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["image.png"]


def test_temporaries_of_dead_writers_are_removed_and_live_ones_kept(tmp_path):
    target = tmp_path / ("long" * 60 + ".png")  # a name cut to stay within 255 bytes
    prefix = atomic_mod._temp_prefix(target)
    assert prefix.startswith(".long") and len(os.fsencode(prefix)) <= 170
    dead_pid = 2 ** 22 + 12345  # above pid_max's default: no such process
    dead = tmp_path / f"{prefix}{dead_pid}.abc.png"
    live = tmp_path / f"{prefix}{os.getpid()}.abc.png"
    init = tmp_path / f"{prefix}1.abc.png"  # a live process (init)
    odd = tmp_path / f"{prefix}notapid.png"
    other = tmp_path / f"{prefix}{dead_pid}.abc.jpg"  # another target's suffix
    for p in (dead, live, init, odd, other):
        p.write_bytes(b"")
    assert remove_stale_temporaries(target) == [dead]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        p.name for p in (live, init, odd, other))
    assert remove_stale_temporaries(tmp_path / "missing_dir" / "f.png") == []


def test_process_alive(monkeypatch):
    assert atomic_mod._process_alive(os.getpid())

    def kill(pid, sig):
        raise PermissionError(errno.EPERM, "not yours")

    monkeypatch.setattr(atomic_mod.os, "kill", kill)
    assert atomic_mod._process_alive(1)  # someone else's live process
