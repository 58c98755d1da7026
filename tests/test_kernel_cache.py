"""The kernel cache heals itself (jit/cache.py): damaged files are dropped and compiled
again with one warning line, an unusable folder falls back with one warning line, two cold
renders share one folder; never a crash, a wrong image or an internal error."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import whitted
from whitted.jit import cache as _cache
from whitted.render.warm_up import warm_up_kernels

REPO_ROOT = Path(__file__).resolve().parents[1]
SIZE = (12, 9)


# ------------------------------------------------------------------ the list of sums alone

def _fake_cache(tmp_path: Path, own: bool = True) -> _cache.KernelCache:
    folder = tmp_path / "numba-x"
    for sub, names in (("kernels_1", ("a-1.py311.nbi", "a-1.py311.0.nbc")),
                       ("compile_2", ("b-2.py311.nbi", "b-2.py311.0.nbc", "b-2.py311.1.nbc"))):
        (folder / sub).mkdir(parents=True)
        for k, name in enumerate(names):
            (folder / sub / name).write_bytes(bytes(range(256)) * (k + 3))
    state = _cache.KernelCache(str(folder), own=own, helper=False)
    state.seal()
    return state


def _names(state) -> set[str]:
    return set(state._files())


def _flip(path: Path, bit: int) -> None:
    with open(path, "r+b") as f:
        f.seek(bit // 8)
        byte = f.read(1)[0]
        f.seek(bit // 8)
        f.write(bytes([byte ^ (1 << bit % 8)]))


def test_a_sealed_folder_checks_clean(tmp_path, capsys):
    state = _fake_cache(tmp_path)
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify() == 0
    assert len(_names(again)) == 5 and capsys.readouterr().err == ""


@pytest.mark.parametrize("bit", [0, 7, 800, 8 * 767 + 3])
def test_a_flipped_bit_in_any_file_drops_that_file_with_one_warning(tmp_path, capsys, bit):
    state = _fake_cache(tmp_path)
    names = sorted(_names(state))
    for name in names:  # every file, one at a time
        _flip(Path(state.folder, name), bit)
        again = _cache.KernelCache(state.folder, own=True, helper=False)
        assert again.verify() == 1, name
        assert name not in _names(again)
        err = capsys.readouterr().err.splitlines()
        assert len(err) == 1 and err[0].startswith("warning: 1 damaged kernel cache file")
        again.seal()  # the others are still sealed and check clean
        assert _cache.KernelCache(state.folder, own=True, helper=False).verify() == 0


def test_truncated_files_are_dropped_with_one_warning_for_all(tmp_path, capsys):
    state = _fake_cache(tmp_path)
    for name in ("kernels_1/a-1.py311.nbi", "compile_2/b-2.py311.1.nbc"):
        os.truncate(Path(state.folder, name), 10)
    Path(state.folder, "compile_2/b-2.py311.0.nbc").write_bytes(b"")
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify() == 3
    assert _names(again) == {"kernels_1/a-1.py311.0.nbc", "compile_2/b-2.py311.nbi"}
    err = capsys.readouterr().err.splitlines()
    assert err == [f"warning: 3 damaged kernel cache files in {state.folder} deleted; "
                   "compiling them again"]


def test_files_nobody_sealed_are_not_trusted_in_whitteds_folder(tmp_path, capsys):
    """A file written by a process that stopped before sealing, or put there by hand, is
    deleted (compiled again) without a warning; a file replaced by other content, with no
    process compiling, is damaged."""
    state = _fake_cache(tmp_path)
    Path(state.folder, "kernels_1/c-9.py311.nbi").write_bytes(b"\x80\x04unsealed")
    replaced = Path(state.folder, "kernels_1/a-1.py311.nbi")
    new = replaced.with_suffix(".new")
    new.write_bytes(b"rewritten elsewhere")
    os.replace(new, replaced)
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify() == 1
    assert _names(again) == _names(state) - {"kernels_1/a-1.py311.nbi"}
    assert capsys.readouterr().err.startswith("warning: 1 damaged")


def _hold_compiling_marker(folder: str, started: Path, release: Path) -> subprocess.Popen:
    """Another process: it starts compiling into ``folder`` (takes its marker), says so,
    and holds it until ``release`` exists."""
    code = textwrap.dedent(f"""
        import pathlib, sys, time
        sys.path.insert(0, {str(REPO_ROOT / 'src')!r})
        from whitted.jit import cache as _cache
        state = _cache.KernelCache({folder!r}, own=True, helper=False)
        state.compiling()
        pathlib.Path({str(started)!r}).touch()
        while not pathlib.Path({str(release)!r}).exists():
            time.sleep(0.02)
        """)
    return subprocess.Popen([sys.executable, "-c", code])


def _rewrite(path: Path, data: bytes) -> None:
    new = path.with_suffix(".new")  # as Numba writes: a new file renamed over the old
    new.write_bytes(data)
    os.replace(new, path)


def test_another_process_compiling_is_not_damage(tmp_path, capsys):
    """Two processes share a cache: one's Numba has rewritten a sealed index (a new file
    renamed into place) and not yet sealed it when the other starts. The other drops that
    file without a word (not trusted, not damage) but still tells damage in place; once
    the first has ended without sealing, its marker is stale and a rewrite is damage."""
    state = _fake_cache(tmp_path)
    started, release = tmp_path / "started", tmp_path / "release"
    other = _hold_compiling_marker(state.folder, started, release)
    try:
        while not started.exists():  # an event, not a time: it exits on any failure
            assert other.poll() is None, "the other process ended before compiling"
            time.sleep(0.02)
        _rewrite(Path(state.folder, "kernels_1/a-1.py311.nbi"), b"another signature")
        _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 3)  # in place: damage still
        again = _cache.KernelCache(state.folder, own=True, helper=False)
        assert again.verify() == 1
        assert _names(again) == _names(state) - {"kernels_1/a-1.py311.nbi",
                                                 "compile_2/b-2.py311.0.nbc"}
        err = capsys.readouterr().err.splitlines()
        assert len(err) == 1 and err[0].startswith("warning: 1 damaged")
    finally:
        release.touch()
        other.wait(timeout=60)
    stale = Path(state.folder, f"{_cache.COMPILING}{other.pid}")
    assert stale.exists()  # it ended without sealing: its marker is left, holding nothing
    _rewrite(Path(state.folder, "compile_2/b-2.py311.nbi"), b"rewritten by nobody")
    third = _cache.KernelCache(state.folder, own=True, helper=False)
    assert third.verify() == 1 and not stale.exists()


def test_a_process_seals_and_drops_its_marker(tmp_path):
    state = _fake_cache(tmp_path)
    state.compiling()
    marker = Path(state.folder, f"{_cache.COMPILING}{os.getpid()}")
    assert marker.exists()
    assert not _cache.KernelCache(state.folder, own=True, helper=False).others_compiling()
    state.seal()
    assert not marker.exists()


def test_a_copied_folder_with_a_damaged_file_is_told(tmp_path, capsys):
    """In a copy every inode is new: a damaged file there is still damage (no process is
    compiling); the good ones are kept and their new inodes recorded."""
    state = _fake_cache(tmp_path)
    copy = tmp_path / "copy" / "numba-x"
    shutil.copytree(state.folder, copy)
    _flip(copy / "compile_2/b-2.py311.1.nbc", 9)
    again = _cache.KernelCache(str(copy), own=True, helper=False)
    assert again.verify() == 1
    assert _names(again) == _names(state) - {"compile_2/b-2.py311.1.nbc"}
    assert capsys.readouterr().err.startswith("warning: 1 damaged")
    sums = json.loads(Path(copy, _cache.SUMS).read_text())
    good = copy / "kernels_1/a-1.py311.0.nbc"
    assert sums["kernels_1/a-1.py311.0.nbc"] == [sums["kernels_1/a-1.py311.0.nbc"][0],
                                                 good.stat().st_size, good.stat().st_ino]


def test_a_copied_folder_checks_clean(tmp_path, capsys):
    """The list names files by content: a copy (new inodes, times) is as good."""
    state = _fake_cache(tmp_path)
    copy = tmp_path / "copy" / "numba-x"
    shutil.copytree(state.folder, copy)
    again = _cache.KernelCache(str(copy), own=True, helper=False)
    assert again.verify() == 0 and len(_names(again)) == 5
    assert capsys.readouterr().err == ""


def test_a_file_numba_rewrote_in_this_process_is_sealed_anew(tmp_path):
    state = _fake_cache(tmp_path)
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    tmp = index.with_suffix(".tmp")
    tmp.write_bytes(b"a new signature added")
    os.replace(tmp, index)  # as Numba writes: a new file renamed over the old
    _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 5)  # in place: never sealed
    state.seal()
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify() == 1  # the flipped one only
    assert "kernels_1/a-1.py311.nbi" in _names(again)


def test_a_file_rewritten_before_its_kernel_is_looked_up_is_no_damage(tmp_path, capsys):
    # a process checks lazily (verify(lazy=True)), then Numba writes a new index for a kernel
    # this process has not looked up yet (a compile helper, or another variant's compile),
    # and the process seals it: the kernel's first look-up then finds it as sealed
    state = _fake_cache(tmp_path)
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify(lazy=True) == 0
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    tmp = index.with_suffix(".tmp")
    tmp.write_bytes(b"a new signature added")
    os.replace(tmp, index)
    again.seal()
    assert again.check_function("kernels_1", "a-1.py311") == 0
    assert index.read_bytes() == b"a new signature added"
    assert capsys.readouterr().err == ""
    # a file damaged after the seal is still found at the look-up
    _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 9)
    assert again.check_function("compile_2", "b-2.py311") == 1
    assert "damaged kernel cache file" in capsys.readouterr().err


def test_the_start_up_check_leaves_sealed_files_to_their_look_up(tmp_path, capsys):
    """The start-up check (lazy) reads only the folder's listing: a sealed file truncated
    in place (the same inode, another size) is not looked at then, and is found, deleted
    and reported in one line when its kernel is looked up; the other kernel's files are
    loaded as sealed, and a fresh check of every file agrees."""
    state = _fake_cache(tmp_path)
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    os.truncate(index, 100)
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify(lazy=True) == 0
    assert index.exists() and capsys.readouterr().err == ""
    assert again.check_function("compile_2", "b-2.py311") == 0
    assert again.check_function("kernels_1", "a-1.py311") == 1
    assert not index.exists()
    assert capsys.readouterr().err == (f"warning: 1 damaged kernel cache file in "
                                       f"{state.folder} deleted; compiling it again\n")
    assert _cache.KernelCache(state.folder, own=True, helper=False).verify() == 0
    assert _names(again) == _names(state) - {"kernels_1/a-1.py311.nbi"}


def test_a_rewrite_given_the_sealed_inode_again_is_no_damage_while_its_writer_compiles(
        tmp_path, capsys):
    """The start-up check (lazy) trusted a sealed file by its inode; another process, still
    compiling, then wrote that index anew and the file system gave the new file the old
    inode again (another size): at the look-up it is that process's work, kept without a
    word; a file changed in place at its sealed size is damage all the same."""
    state = _fake_cache(tmp_path)
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    assert again.verify(lazy=True) == 0
    started, release = tmp_path / "started", tmp_path / "release"
    other = _hold_compiling_marker(state.folder, started, release)
    try:
        while not started.exists():  # an event, not a time: it exits on any failure
            assert other.poll() is None, "the other process ended before compiling"
            time.sleep(0.02)
        index = Path(state.folder, "kernels_1/a-1.py311.nbi")
        inode = index.stat().st_ino
        index.write_bytes(b"another signature, the same inode")
        assert index.stat().st_ino == inode
        _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 3)
        assert again.check_function("kernels_1", "a-1.py311") == 0
        assert index.read_bytes() == b"another signature, the same inode"
        assert capsys.readouterr().err == ""
        assert again.check_function("compile_2", "b-2.py311") == 1
        assert "damaged kernel cache file" in capsys.readouterr().err
    finally:
        release.touch()
        other.wait(timeout=60)


def test_the_start_up_check_of_a_sealed_folder_takes_no_lock(tmp_path, monkeypatch):
    """A warm folder whose files are all as sealed is checked at start-up without the lock
    (nothing to delete or write); a file nobody sealed sends the check under the lock,
    which deletes it."""
    state = _fake_cache(tmp_path)
    again = _cache.KernelCache(state.folder, own=True, helper=False)

    def no_lock():
        raise AssertionError("the lock was taken")

    monkeypatch.setattr(again, "_acquire", no_lock)
    assert again.verify(lazy=True) == 0
    assert set(again._deferred) == _names(state)
    monkeypatch.undo()
    stray = Path(state.folder, "kernels_1/c-9.py311.nbi")
    stray.write_bytes(b"unsealed")
    taken = []
    third = _cache.KernelCache(state.folder, own=True, helper=False)
    monkeypatch.setattr(third, "_acquire", lambda: taken.append(True))
    assert third.verify(lazy=True) == 0
    assert taken and not stray.exists()
    assert set(third._deferred) == _names(state)


def test_a_file_another_process_rewrote_and_sealed_after_the_check_is_no_damage(
        tmp_path, capsys):
    """Two processes on one folder: the first checks lazily at start-up; the second then
    compiles a new signature of a kernel (Numba renames a new index over the sealed one)
    and seals it; the first's look-up of that kernel finds the second's sealed file: kept,
    loaded, no warning."""
    state = _fake_cache(tmp_path)
    first = _cache.KernelCache(state.folder, own=True, helper=False)
    assert first.verify(lazy=True) == 0
    second = _cache.KernelCache(state.folder, own=True, helper=False)
    assert second.verify(lazy=True) == 0
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    second.compiling()
    _rewrite(index, b"a new signature added by the second process")
    second.seal()
    assert first.check_function("kernels_1", "a-1.py311") == 0
    assert index.read_bytes() == b"a new signature added by the second process"
    assert capsys.readouterr().err == ""
    # real damage after that is still found, with one warning
    _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 9)
    assert first.check_function("compile_2", "b-2.py311") == 1
    assert capsys.readouterr().err.count("damaged kernel cache file") == 1
    assert _cache.KernelCache(state.folder, own=True, helper=False).verify() == 0


def test_a_file_a_live_process_rewrote_after_the_check_is_kept_at_the_look_up(
        tmp_path, capsys):
    """The first process checks lazily; another, still compiling (its marker held), has
    its Numba rename a new index over a sealed one and has not sealed it yet when the first
    looks that kernel up: the file is that process's work, kept and not called damage.
    Damage in place is still found meanwhile; once the writer has ended without sealing,
    such a file is damage."""
    state = _fake_cache(tmp_path)
    first = _cache.KernelCache(state.folder, own=True, helper=False)
    assert first.verify(lazy=True) == 0
    started, release = tmp_path / "started", tmp_path / "release"
    other = _hold_compiling_marker(state.folder, started, release)
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    try:
        while not started.exists():  # an event, not a time: it exits on any failure
            assert other.poll() is None, "the other process ended before compiling"
            time.sleep(0.02)
        _rewrite(index, b"another signature, not sealed yet")
        assert first.check_function("kernels_1", "a-1.py311") == 0
        assert index.read_bytes() == b"another signature, not sealed yet"
        assert capsys.readouterr().err == ""
        _flip(Path(state.folder, "compile_2/b-2.py311.0.nbc"), 3)  # in place: damage still
        assert first.check_function("compile_2", "b-2.py311") == 1
        assert capsys.readouterr().err.count("damaged kernel cache file") == 1
    finally:
        release.touch()
        other.wait(timeout=60)
    # its writer ended without sealing it: not trusted by the next process
    third = _cache.KernelCache(state.folder, own=True, helper=False)
    assert third.verify() == 1 and not index.exists()


def test_a_file_renamed_in_while_the_start_up_check_reads_the_folder_is_no_damage(
        tmp_path, capsys, monkeypatch):
    """Another process, compiling, has its Numba rename a new index over a sealed one after
    the start-up check listed the folder and before it hashed that file: the check judges
    the file it hashed (another inode: that process's work), never the listed one's inode
    against the new content (which reads as damage in place)."""
    state = _fake_cache(tmp_path)
    started, release = tmp_path / "started", tmp_path / "release"
    other = _hold_compiling_marker(state.folder, started, release)
    index = Path(state.folder, "kernels_1/a-1.py311.nbi")
    first = _cache.KernelCache(state.folder, own=True, helper=False)
    listed = first._entries

    def list_then_rewrite():
        files = listed()
        _rewrite(index, b"another signature from the compiling process")
        return files

    monkeypatch.setattr(first, "_entries", list_then_rewrite)
    try:
        while not started.exists():  # an event, not a time: it exits on any failure
            assert other.poll() is None, "the other process ended before compiling"
            time.sleep(0.02)
        assert first.verify() == 0
        assert "damaged" not in capsys.readouterr().err
    finally:
        release.touch()
        other.wait(timeout=60)


def test_a_cold_compile_of_one_variant_lets_other_processes_seal(tmp_path):
    # whitted warm: one process compiles the general kernels cold (holding that variant's
    # lock for the whole compile) while another compiles and seals other kernels
    state = _fake_cache(tmp_path)
    other = _cache.KernelCache(state.folder, own=True, helper=False)
    sealed, second = threading.Event(), threading.Event()

    def seal_and_compile_the_same():
        Path(state.folder, "kernels_1/c-3.py311.nbi").write_bytes(b"another kernel")
        other.seal()
        sealed.set()
        with other.compile_lock("general"):  # the same variant: waits for the first
            second.set()

    with state.compile_lock("general"):
        thread = threading.Thread(target=seal_and_compile_the_same, daemon=True)
        thread.start()
        assert sealed.wait(30)
        assert not second.wait(0.3)
    assert second.wait(30)
    thread.join(30)
    assert "kernels_1/c-3.py311.nbi" in _cache.KernelCache(state.folder, own=True,
                                                            helper=False)._read_sums()[0]


def test_a_damaged_list_of_sums_drops_everything_with_one_warning(tmp_path, capsys):
    state = _fake_cache(tmp_path)
    sums = Path(state.folder, _cache.SUMS)
    sums.write_bytes(sums.read_bytes()[:-7])
    Path(state.folder, "whitted-ready-plain").touch()
    again = _cache.KernelCache(state.folder, own=True, helper=False)
    again.verify()
    assert _names(again) == set()
    assert not Path(state.folder, "whitted-ready-plain").exists()  # compiled again, helper too
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "list of checksums" in err[0] and err[0].startswith("warning:")


def test_a_whitted_process_started_by_another_chooses_its_folder_itself(tmp_path):
    """A whitted process started by another (a bench run, a farm worker) inherits the
    NUMBA_CACHE_DIR its parent set: it takes it as whitted's own and chooses its folder again
    (for its own sources), not as a folder the user named; a folder the user named stays
    the user's."""
    code = ("import json; from whitted.jit import cache; s = cache.prepare(); "
            "print(json.dumps([s.folder, s.own, str(cache.cache_dir())]))")

    def chosen(**settings: str) -> list:
        env = {k: v for k, v in os.environ.items()
               if k not in ("NUMBA_CACHE_DIR", _cache.OWN_FOLDER_ENV)}
        env.update(PYTHONPATH=str(REPO_ROOT / "src"), WHITTED_CACHE_DIR=str(tmp_path / "c"),
                   **settings)
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, timeout=300, cwd=tmp_path)
        assert run.returncode == 0, run.stderr
        return json.loads(run.stdout.strip().splitlines()[-1])

    parents = str(tmp_path / "parents")
    folder, own, ours = chosen(NUMBA_CACHE_DIR=parents, **{_cache.OWN_FOLDER_ENV: parents})
    assert (folder, own) == (ours, True) and Path(ours).parent == tmp_path / "c"
    users = str(tmp_path / "users")
    folder, own, _ = chosen(NUMBA_CACHE_DIR=users, **{_cache.OWN_FOLDER_ENV: parents})
    assert (folder, own) == (users, False)
    assert chosen(NUMBA_CACHE_DIR=users)[:2] == [users, False]


def test_other_programs_files_in_a_users_numba_cache_dir_are_kept(tmp_path):
    state = _fake_cache(tmp_path, own=False)
    other = Path(state.folder, "elsewhere_3/theirs-4.py311.nbi")
    other.parent.mkdir()
    other.write_bytes(b"someone else's")
    again = _cache.KernelCache(state.folder, own=False, helper=False)
    assert again.verify() == 0
    assert other.exists()
    _flip(other, 3)  # sealed as found: damage after that is caught like any other
    assert _cache.KernelCache(state.folder, own=False, helper=False).verify() == 1


@pytest.mark.parametrize("problem", ["file", "readonly"])
def test_an_unusable_folder_falls_back_with_one_warning(tmp_path, monkeypatch, capsys,
                                                        problem):
    """A folder that cannot be written (here made so by refusing its temporary file: the
    tests may run as root, who writes anywhere) or that is a file: the per-user folder."""
    chosen = tmp_path / "chosen"
    if problem == "file":
        chosen.write_text("not a folder")
    else:
        chosen.mkdir()
        real = _cache.tempfile.TemporaryFile

        def refuse(*args, dir=None, **kwargs):
            if dir is not None and str(dir).startswith(str(chosen)):
                raise PermissionError(13, "Permission denied")
            return real(*args, dir=dir, **kwargs)

        monkeypatch.setattr(_cache.tempfile, "TemporaryFile", refuse)
    monkeypatch.setenv("WHITTED_CACHE_DIR", str(chosen))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "user"))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(_cache, "_state", None)
    monkeypatch.setattr(_cache, "_set_numba_cache_dir", lambda folder, own=True: None)
    state = _cache.prepare()
    assert state.folder == str(tmp_path / "user" / "whitted" / _cache._folder_name())
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"warning: kernel cache folder {chosen}")


@pytest.mark.parametrize("damaged", [False, True])
def test_a_warm_folder_that_cannot_be_written_is_loaded_from_as_it_is(tmp_path, monkeypatch,
                                                                     capsys, damaged):
    """A container image's cache, read-only and another user's (simulated: its temporary
    file refused, as the tests may run as root): used read-only, without a word, when its
    files match their sums; damaged, it cannot be used (one warning; nothing deleted)."""
    base = tmp_path / "image-cache"
    folder = base / _cache._folder_name()
    for sub, names in (("kernels_1", ("a-1.py311.nbi", "a-1.py311.0.nbc")),
                       ("compile_2", ("b-2.py311.nbi", "b-2.py311.0.nbc"))):
        (folder / sub).mkdir(parents=True)
        for k, name in enumerate(names):
            (folder / sub / name).write_bytes(bytes(range(256)) * (k + 3))
    _cache.KernelCache(str(folder), own=True, helper=False).seal()
    if damaged:
        _flip(folder / "compile_2" / "b-2.py311.0.nbc", 100)
    files = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    real = _cache.tempfile.TemporaryFile

    def refuse(*args, dir=None, **kwargs):
        if dir is not None and str(dir).startswith(str(base)):
            raise PermissionError(13, "Permission denied")
        return real(*args, dir=dir, **kwargs)

    monkeypatch.setattr(_cache.tempfile, "TemporaryFile", refuse)
    monkeypatch.setenv("WHITTED_CACHE_DIR", str(base))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "user"))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv(_cache.HELPER_ENV, raising=False)
    monkeypatch.setattr(_cache, "_state", None)
    monkeypatch.setattr(_cache, "_set_numba_cache_dir", lambda folder, own=True: None)
    state = _cache.prepare()
    err = capsys.readouterr().err.splitlines()
    if damaged:
        assert state.folder == str(tmp_path / "user" / "whitted" / _cache._folder_name())
        assert not state.read_only
        assert len(err) == 1 and err[0].startswith(f"warning: kernel cache folder {folder} "
                                                   "cannot be used (Permission denied; its "
                                                   "files do not match")
    else:
        assert state.folder == str(folder) and state.read_only and err == []
        state.unsealed = True
        state.seal()  # nothing to write there: a no-op
        with state.locked():  # no lock file made
            pass
    assert {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()} == files


# ------------------------------------------------------------------ renders


@pytest.fixture(scope="module")
def reference() -> np.ndarray:
    warm_up_kernels()
    return whitted.render(whitted.default_scene(), width=SIZE[0], height=SIZE[1],
                          threads=1).to_srgb8()


@pytest.fixture(scope="module")
def warm_folder(reference) -> Path:
    """This test session's warm kernel cache folder (the render kernels and builders)."""
    folder = Path(_cache.prepare().folder)
    assert (folder / "whitted-ready-plain").exists()
    return folder


def _render(tmp_path: Path, name: str, **settings: str) -> tuple[subprocess.CompletedProcess,
                                                                  np.ndarray | None]:
    from PIL import Image as PILImage

    out = tmp_path / f"{name}.png"
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"), WHITTED_COMPILE_HELPER="0")
    env.pop("NUMBA_CACHE_DIR", None)
    env.update(settings)
    run = subprocess.run([sys.executable, "-m", "whitted", "render", "-W", str(SIZE[0]), "-H",
                          str(SIZE[1]), "-t", "1", "-q", "-o", str(out)],
                         capture_output=True, text=True, env=env, cwd=tmp_path, timeout=900)
    image = np.asarray(PILImage.open(out)) if out.exists() else None
    return run, image


def _warnings(run) -> list[str]:
    return [line for line in run.stderr.splitlines() if line.strip()]


def _copy_warm(warm_folder: Path, base: Path) -> Path:
    copy = base / warm_folder.name
    shutil.copytree(warm_folder, copy, ignore=shutil.ignore_patterns("whitted.lock"))
    return copy


def test_damaged_numba_files_give_the_right_image_and_one_warning(tmp_path, warm_folder,
                                                                  reference):
    """A flipped bit in machine code (.nbc) and a truncated index (.nbi), of kernels the
    render loads (the BVH builder, called from Python): the render drops them, compiles
    those kernels again, and gives the reference image; the next run is clean."""
    copy = _copy_warm(warm_folder, tmp_path / "cache")
    files = sorted(copy.rglob("*.nb[ic]"))
    builder = [f for f in files if f.name.startswith("bvh._build-")]
    assert builder, [f.name for f in files][:20]
    data = [f for f in builder if f.suffix == ".nbc"]
    index = [f for f in builder if f.suffix == ".nbi"]
    _flip(data[0], 8 * (data[0].stat().st_size // 2))
    os.truncate(index[0], index[0].stat().st_size // 3)
    run, image = _render(tmp_path, "damaged", WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    assert run.returncode == 0, run.stderr
    lines = _warnings(run)
    assert len(lines) == 1 and lines[0].startswith("warning: 2 damaged kernel cache files")
    assert np.array_equal(image, reference)
    again, image = _render(tmp_path, "again", WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    assert again.returncode == 0 and _warnings(again) == [], again.stderr
    assert np.array_equal(image, reference)


@pytest.mark.parametrize("chosen", ["file", "/proc", "/dev/null"])
def test_a_cache_folder_that_cannot_be_used_falls_back_with_one_warning(tmp_path, warm_folder,
                                                                        reference, chosen):
    """WHITTED_CACHE_DIR naming a file, /proc or /dev/null: the per-user folder is used (a
    warm copy here, so nothing compiles), one warning line says so."""
    if chosen == "file":
        chosen = str(tmp_path / "a-file")
        Path(chosen).write_text("x")
    _copy_warm(warm_folder, tmp_path / "user" / "whitted")
    run, image = _render(tmp_path, "fallback", WHITTED_CACHE_DIR=chosen,
                         XDG_CACHE_HOME=str(tmp_path / "user"))
    assert run.returncode == 0, run.stderr
    lines = _warnings(run)
    assert len(lines) == 1 and lines[0].startswith(f"warning: kernel cache folder {chosen}")
    assert str(tmp_path / "user") in lines[0]
    assert np.array_equal(image, reference)


def test_no_usable_folder_at_all_compiles_in_memory(tmp_path):
    """Neither the chosen nor the per-user folder can be used: kernels compile in memory
    (cache=False), with one warning line, and still run."""
    script = textwrap.dedent("""
        import numpy as np
        from whitted.jit import kernel

        @kernel(entry=True)
        def twice(a):
            return 2.0 * a[0]

        print("RESULT", twice(np.array([1.5])), twice.dispatcher._cache.__class__.__name__)
    """)
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"), WHITTED_CACHE_DIR="/dev/null",
               XDG_CACHE_HOME="/proc")
    env.pop("NUMBA_CACHE_DIR", None)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=env, cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "RESULT 3.0 NullCache" in run.stdout
    lines = _warnings(run)
    assert len(lines) == 1 and "compiled in memory" in lines[0], run.stderr


def test_two_cold_renders_at_once_into_one_folder(tmp_path, reference):
    """Both succeed, with the reference image and no warning: the second waits for the
    first's compile (the folder's lock) and loads what it sealed."""
    from PIL import Image as PILImage

    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"),
               WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    runs = [subprocess.Popen([sys.executable, "-m", "whitted", "render", "-W", str(SIZE[0]),
                              "-H", str(SIZE[1]), "-t", "1", "-q", "-o",
                              str(tmp_path / f"{k}.png")],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=env, cwd=tmp_path) for k in range(2)]
    for k, run in enumerate(runs):
        out, err = run.communicate(timeout=1200)
        assert run.returncode == 0, err
        assert err.strip() == "", err
        assert np.array_equal(np.asarray(PILImage.open(tmp_path / f"{k}.png")), reference)
    folder = next((tmp_path / "cache").glob("numba-*"))
    assert _cache.KernelCache(str(folder), own=True, helper=False).verify() == 0
    assert (folder / _cache.SUMS).exists()
