"""Where compiled kernels are kept between runs, and how whitted checks them before use.

**The folder.** Numba's ``cache=True`` keys each cached function on its own source file only,
so a change in a helper it calls would leave a stale machine-code copy behind. whitted
therefore puts its cache in a folder named after a hash of all kernel sources: any change to
any kernel starts a fresh cache, and different whitted versions never share one. The folder
is ``$WHITTED_CACHE_DIR/numba-<hash>`` (default ``~/.cache/whitted``; ``numba-<hash>-stock``
with ``WHITTED_NUMBA_TUNING=0``); an explicit ``NUMBA_CACHE_DIR`` set by the user wins. whitted
points Numba at the folder through ``NUMBA_CACHE_DIR`` too, and says so in
``WHITTED_OWN_NUMBA_CACHE_DIR``: a whitted process started by another (a bench run, a farm
worker) inherits both and chooses its own folder again, as a process started by the user does.

**A folder that cannot be used** (read-only, a file, ``/proc``, ``/dev/null``): whitted says so
in one ``warning:`` line and uses the per-user folder instead, or, when that cannot be used
either, compiles in memory (every run compiles again). Never an error.

**A warm folder this process cannot write** (a container image's cache, baked at build time
and owned by another user; a shared read-only mount) is used as it is, for loading only
(:attr:`KernelCache.read_only`), without a word, when it holds whitted's list of sums and
every file in it matches the list (nothing could be deleted or sealed there). Nothing is
written to it: no lock, no seal, no marker, no compile helper. A kernel it lacks is compiled
in memory, with one ``warning:`` line (:func:`read_only_miss`, from jit/dispatcher.py);
with stock Numba (no tuned dispatcher, which can load from a folder it cannot write) every
kernel is, with that same one line. A read-only folder that fails its check is one that
cannot be used (above).

**Checked before use.** Numba's cache files (``.nbi`` indexes, ``.nbc`` machine code) carry no
checksum: one flipped bit can crash the process that loads them or give a wrong image. whitted
keeps a list of their SHA-256 sums (:data:`SUMS`, written by whitted under a lock, whole or not
at all) and, before Numba first loads anything in a process (:func:`prepare`), checks every
cache file against it:

- a file whose sum differs from its entry, changed in place (the inode the entry records),
  was damaged: it is deleted (Numba then compiles that kernel again and caches it anew) and
  one ``warning:`` line says how many were;
- a file the list does not name (written by a process that was stopped before it sealed
  it, or put there by hand) is not trusted either: in whitted's own folder it is deleted
  silently (it is compiled again); in a folder the user named with ``NUMBA_CACHE_DIR``, which
  may hold other programs' cache files, it is taken as found;
- a new file under a name the list has (another inode: Numba writes a file whole and renames
  it into place) while another process is compiling into the folder (it holds a
  ``whitted-compiling-<pid>`` marker from its first compile to its seal) is that process's
  work in progress: deleted silently too, never trusted, never reported as damage. With no
  process compiling, it is damage like any other;
- a damaged list is a list of nothing: every file is then compiled again, with one warning.

A file as sealed (its entry's inode, which the folder's listing gives without a ``stat``) has
its content, and so its size, checked only when its kernel is first looked up
(:meth:`KernelCache.check_function`): a process reads the listing and the list, and hashes
the few files it loads. A warm folder whose files are all as sealed is checked so without
the lock (there is nothing to delete or write); anything else is checked under it. Other
processes keep writing meanwhile:
a file that no longer has the sum the start-up check saw is judged under the lock, against
the list and the markers as they are then: sealed since by another process, it is loaded;
a new file (another inode) while another process is compiling is that process's work, kept
for it to seal; only a file changed in place, or replaced by no live process, is damage.
Every check judges the file it hashed (its status read from the same open file, never the
inode listed before another process's Numba renamed a new file in), and deletes a file only
while it is still the one judged.

After Numba wrote files (a compile of a kernel called from Python, the warm-up), whitted
:func:`seal` s them: the files that are new since this process last looked, or were replaced
by a new file (a new inode: Numba writes a file whole and renames it into place), get their
entries; a file changed in place keeps its old entry, so damage is not sealed. A list that
names files by content (size and SHA-256; the inode only tells a rewrite from damage) survives
copying the folder elsewhere (a container image). Two
processes compiling at once take turns through a lock file (``whitted.lock``); the
cold compile of the render kernels holds it throughout (render/warm_up.py), so a second cold
render waits and then loads what the first compiled.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import sys
import tempfile
import threading
from pathlib import Path

#: the sources that decide the kernels' machine code: every file of these packages (their
#: subpackages too: kernels/shapes/), and the two modules of this one that choose how
#: kernels are compiled
KERNEL_DIRS = ("kernels", "compile", "assets")
KERNEL_FILES = ("jit/decorators.py", "jit/dispatcher.py")
#: the list of sums in the cache folder
SUMS = "whitted-sums.json"
LOCK = "whitted.lock"
#: the lock a process holds while it compiles a variant of the render kernels cold
COMPILE_LOCK = "whitted-compile-"
#: the marker a process holds while it has compiled files not yet in the list
COMPILING = "whitted-compiling-"
#: what Numba writes into the cache folder
CACHE_SUFFIXES = (".nbi", ".nbc")
#: set in the environment of the compile helper (render/warm_up.py): its parent checked the
#: folder and holds the lock; the helper neither checks nor seals
HELPER_ENV = "WHITTED_KERNEL_CACHE_HELPER"
LOCK_WAIT_SECONDS = 900.0  # a process holding the lock longer than this is not waited for


def kernel_source_hash(root: Path | None = None) -> str:
    """A hash of the sources that decide the kernels' machine code, under ``root`` (whitted's
    package folder unless given: read once a process, which names its cache folder and
    digests its jobs with it)."""
    if root is None:
        return _own_kernel_source_hash()
    return _kernel_source_hash(root)


@functools.cache
def _own_kernel_source_hash() -> str:
    return _kernel_source_hash(Path(__file__).parents[1])


def _kernel_source_hash(root: Path) -> str:
    h = hashlib.sha256()
    paths = [path for folder in KERNEL_DIRS for path in sorted((root / folder).rglob("*.py"))]
    for path in paths + [root / name for name in KERNEL_FILES]:
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _user_base() -> str:
    return os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"),
                        "whitted")


def toolchain() -> str:
    """The Numba and llvmlite versions that compile the kernels (imports Numba, through
    lean_numba.py's hook)."""
    from .. import marks

    if "numba" not in sys.modules:
        marks.mark("numba:start")  # whitted bench --startup counts it with the imports
    import llvmlite
    import numba

    marks.mark("numba:end")
    return f"numba{numba.__version__}-llvmlite{llvmlite.__version__}"


def _folder_name() -> str:
    # stock Numba's code (WHITTED_NUMBA_TUNING=0, jit/dispatcher.py) is kept apart from
    # the tuned dispatcher's: the same kernel and types, compiled with other options
    stock = "-stock" if os.environ.get("WHITTED_NUMBA_TUNING", "1") == "0" else ""
    return f"numba-{kernel_source_hash()}-{toolchain()}{stock}"


def cache_root() -> Path:
    """The per-user folder of whitted's caches (``$WHITTED_CACHE_DIR``, default
    ``~/.cache/whitted``): the same for a checkout, an editable and a wheel install."""
    return Path(os.environ.get("WHITTED_CACHE_DIR") or _user_base())


def cache_dir() -> Path:
    """The kernel cache folder: named after what decides the machine code (every kernel
    source, the Numba and llvmlite versions; the CPU is in Numba's index), never after
    where whitted is installed."""
    return cache_root() / _folder_name()


def _warn(message: str) -> None:
    print(f"warning: {message}", file=sys.stderr, flush=True)


def _usable(folder: str) -> str | None:
    """None when Numba can keep files in ``folder`` (made if missing), else why not."""
    try:
        os.makedirs(folder, exist_ok=True)
        if not os.path.isdir(folder):
            return "not a folder"
        tempfile.TemporaryFile(dir=folder).close()
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    return None


def _file_lock(path: str, timeout: float = -1):
    """A lock on the file ``path`` (filelock: ``flock`` on Unix, ``msvcrt`` on Windows), held
    by one process at a time and released when its process ends however it ends. Without a
    lock-file fallback: a file system without locks means no lock (a leftover lock file of a
    killed process would stop every later one)."""
    from filelock import FileLock

    try:
        return FileLock(path, timeout=timeout, mode=0o666, thread_local=False,
                        fallback_to_soft=False)
    except TypeError:  # a filelock without soft locks, so without the fallback
        return FileLock(path, timeout=timeout, mode=0o666, thread_local=False)


def _marker_lock(path: str):
    """The lock on a ``whitted-compiling-<pid>`` marker: held by its process while it
    compiles; another process that can take it knows the owner has ended."""
    return _file_lock(path)


class KernelCache:
    """The kernel cache folder this process uses (``folder``; None: compiling in memory)."""

    def __init__(self, folder: str | None, own: bool, helper: bool,
                 read_only: bool = False) -> None:
        self.folder = folder
        self.own = own  # whitted's folder (not one the user named with NUMBA_CACHE_DIR)
        self.helper = helper
        #: a warm folder this process cannot write: kernels are loaded from it, never saved
        self.read_only = read_only
        self.missed = False  # a kernel it lacked was compiled in memory (and said so)
        self._seen: dict[str, tuple[int, int, int]] = {}  # file -> (inode, size, mtime)
        #: files whose content verify() left to check when their kernel is looked up
        self._deferred: dict[str, str] = {}
        self._lock = threading.RLock()
        self._file_lock = None  # the folder's lock file, held (filelock.FileLock)
        self._lock_depth = 0
        self.unsealed = False  # Numba compiled something since the last seal
        self._compiling_lock = None  # held while this process has unsealed files

    # ---------------------------------------------------------------- lock
    @contextlib.contextmanager
    def locked(self):
        """Held by one process at a time (and one thread of it), for checking, sealing and
        a cold compile. Without a lock file (it cannot be made) it does nothing."""
        if self.folder is None or self.helper or self.read_only:
            yield
            return
        with self._lock:
            if self._lock_depth == 0:
                self._acquire()
            self._lock_depth += 1
            try:
                yield
            finally:
                self._lock_depth -= 1
                if self._lock_depth == 0:
                    self._release()

    def _acquire(self) -> None:
        self._file_lock = self._take(LOCK)

    def _take(self, name: str, wait: float = LOCK_WAIT_SECONDS):
        """The lock file ``name`` in the folder, acquired (None: not waited for longer, or
        it cannot be made)."""
        from filelock import Timeout

        lock = _file_lock(os.path.join(self.folder, name), wait)
        try:
            lock.acquire(poll_interval=0.05)
        except Timeout:
            return None  # a process holding it this long is not waited for
        except (OSError, NotImplementedError):
            return None  # it cannot be made, or a file system without locks
        return lock

    @contextlib.contextmanager
    def compile_lock(self, variant: str):
        """Held by one process at a time while it compiles the kernels of ``variant`` cold
        (render/warm_up.py): a second process that needs them waits, then loads them.
        Apart from :meth:`locked` (held only to check and seal), so that processes
        compiling other variants at the same time (``whitted warm``) seal theirs
        meanwhile."""
        if self.folder is None or self.helper or self.read_only:
            yield
            return
        lock = self._take(f"{COMPILE_LOCK}{variant}")
        try:
            yield
        finally:
            if lock is not None:
                lock.release()

    def take_compile_lock(self, variant: str):
        """The lock of :meth:`compile_lock`, taken only if no other process holds it (not
        waited for): the acquired lock, to ``release()`` when the compile is done, or None
        (another process compiles ``variant``, or no lock can be made here)."""
        if self.folder is None or self.helper or self.read_only:
            return None
        return self._take(f"{COMPILE_LOCK}{variant}", wait=0)

    def _release(self) -> None:
        lock, self._file_lock = self._file_lock, None
        if lock is not None:
            lock.release()

    # ---------------------------------------------------------------- compiling marker
    def compiling(self) -> None:
        """Numba is compiling here: until the next :meth:`seal`, this process may leave
        cache files the list does not name yet, and says so to other processes with a marker
        file it holds a lock on (``whitted-compiling-<pid>``; a process that ended holds
        nothing, whatever its marker says)."""
        if self.folder is None or self.helper or self.read_only \
                or self._compiling_lock is not None:
            return
        lock = _marker_lock(os.path.join(self.folder, f"{COMPILING}{os.getpid()}"))
        try:
            lock.acquire(timeout=0)
        except Exception:  # noqa: BLE001 - cannot be made or locked: no marker, as before
            return
        self._compiling_lock = lock

    def _done_compiling(self) -> None:
        if self._compiling_lock is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(os.path.join(self.folder, f"{COMPILING}{os.getpid()}"))
        self._compiling_lock.release()
        self._compiling_lock = None

    def others_compiling(self) -> bool:
        """Whether another live process is compiling into this folder now (its new files
        are not sealed yet). Markers of processes that ended are deleted."""
        from filelock import Timeout

        busy = False
        for marker in Path(self.folder).glob(f"{COMPILING}*"):
            if marker.name == f"{COMPILING}{os.getpid()}":
                continue
            lock = _marker_lock(str(marker))
            try:
                lock.acquire(timeout=0)
            except Timeout:
                busy = True
            except (OSError, NotImplementedError):
                pass
            else:
                with contextlib.suppress(OSError):
                    marker.unlink()
                lock.release()
        return busy

    # ---------------------------------------------------------------- sums
    def _entries(self) -> dict[str, os.DirEntry]:
        """The cache files in the folder (one level down), by name, as listed: their inodes
        come with the listing (``DirEntry.inode()``, no system call on POSIX); their status
        costs a ``stat`` each, made only where needed (a cache of every variant holds about
        a thousand files, and a process loads a few of them)."""
        found: dict[str, os.DirEntry] = {}
        root = self.folder
        try:
            folders = [e for e in os.scandir(root) if e.is_dir(follow_symlinks=False)]
        except OSError:
            return found
        for sub in folders:
            try:
                entries = list(os.scandir(sub.path))
            except OSError:
                continue
            for entry in entries:
                if entry.name.endswith(CACHE_SUFFIXES):
                    found[f"{sub.name}/{entry.name}"] = entry
        return found

    def _files(self) -> dict[str, os.stat_result]:
        found: dict[str, os.stat_result] = {}
        for name, entry in self._entries().items():
            with contextlib.suppress(OSError):
                found[name] = entry.stat(follow_symlinks=False)
        return found

    def _read_sums(self) -> tuple[dict, bool]:
        """The list of sums, and whether it was damaged (then empty)."""
        try:
            with open(os.path.join(self.folder, SUMS), "rb") as f:
                data = json.loads(f.read())
        except FileNotFoundError:
            return {}, False
        except (OSError, ValueError):
            return {}, True
        if not isinstance(data, dict) or not all(
                isinstance(v, list) and len(v) in (2, 3) and isinstance(v[0], str)
                and all(isinstance(n, int) for n in v[1:]) for v in data.values()):
            return {}, True
        return data, False

    def _write_sums(self, sums: dict) -> None:
        path = os.path.join(self.folder, SUMS)
        tmp = f"{path}.{os.getpid()}.tmp"
        try:
            with open(tmp, "w") as f:
                json.dump(sums, f, sort_keys=True)
            os.replace(tmp, path)
        except OSError:  # full or read-only: the files stay unsealed, compiled again later
            with contextlib.suppress(OSError):
                os.unlink(tmp)

    @staticmethod
    def _digest(path: str) -> str | None:
        return KernelCache._read_file(path)[0]

    @staticmethod
    def _read_file(path: str) -> tuple[str | None, os.stat_result | None]:
        """The SHA-256 sum of the file at ``path`` and the status of that same file (one
        open file: another process's Numba may rename a new file over ``path`` at any
        moment, and a sum must never be judged against another file's inode)."""
        try:
            with open(path, "rb") as f:
                return hashlib.sha256(f.read()).hexdigest(), os.fstat(f.fileno())
        except OSError:
            return None, None

    @staticmethod
    def _drop(path: str, judged: os.stat_result) -> None:
        """Delete the file at ``path`` when it is still the one judged (``judged``, its
        status), not a new one another process's Numba has renamed in since."""
        with contextlib.suppress(OSError):
            if os.stat(path).st_ino == judged.st_ino:
                os.unlink(path)

    def verify(self, lazy: bool = False) -> int:
        """Check every cache file against the list (module docstring); delete what fails.
        Returns how many damaged files were deleted. ``lazy``: a file that is as sealed (its
        entry's inode) has its content checked only when a kernel of its is first
        looked up in this process (:meth:`check_function`, from jit/locator.py), so a process
        hashes the few files it loads, not the whole cache of every variant."""
        if self.folder is None or self.helper:
            return 0
        if lazy and self._all_as_sealed():
            return 0
        with self.locked():
            sums, damaged_list = self._read_sums()
            damaged = 0
            deleted = refreshed = False
            files = self._entries()
            rewriting = self.others_compiling()
            for name, listed in files.items():
                path = os.path.join(self.folder, name)
                entry = sums.get(name)
                if lazy and not damaged_list and entry is not None \
                        and entry[2:] == [_inode(listed)]:
                    # the file as sealed (the same inode): its content, and so its size, is
                    # checked when its kernel is first looked up, without a stat now
                    self._deferred[name] = entry[0]
                    self._seen[name] = (entry[2], entry[1], 0)
                    continue
                digest, st = self._read_file(path) if entry is not None else (None, None)
                if st is None:
                    try:
                        st = listed.stat(follow_symlinks=False)
                    except OSError:
                        st = None
                if st is None:  # gone since the folder was listed: nothing to judge
                    if entry is not None:
                        sums.pop(name, None)
                        refreshed = True
                    continue
                good = entry is not None and entry[1] == st.st_size and digest == entry[0]
                if good:
                    self._seen[name] = (st.st_ino, st.st_size, st.st_mtime_ns)
                    if entry[2:] != [st.st_ino]:  # a copied folder: new inodes, same content
                        sums[name] = [entry[0], entry[1], st.st_ino]
                        refreshed = True
                    continue
                if entry is None and not damaged_list and not self.own:
                    continue  # another program's file in the user's NUMBA_CACHE_DIR
                if entry is None and not damaged_list and rewriting:
                    continue  # new, from a process compiling now: it seals it
                if entry is not None and (entry[2:] == [st.st_ino] or not rewriting):
                    damaged += 1  # changed in place, or by no process compiling: damage
                # else a new file under a sealed name while another process compiles (its
                # Numba rewrote it and it has not sealed it yet): dropped without a word
                if entry is not None or self.own or damaged_list:
                    self._drop(path, st)
                    deleted = True
                sums.pop(name, None)
            stale = [name for name in sums if name not in files]
            for name in stale:
                del sums[name]
            if damaged or damaged_list:
                self._write_sums(sums)
                self._clear_markers()
            elif stale or refreshed:
                self._write_sums(sums)
            if deleted:
                self._clear_markers()
            if damaged_list:
                _warn(f"the kernel cache's list of checksums in {self.folder} was damaged; "
                      "its kernels are compiled again")
            elif damaged:
                _warn(f"{damaged} damaged kernel cache file{'s' * (damaged > 1)} in "
                      f"{self.folder} deleted; compiling {'them' if damaged > 1 else 'it'} "
                      "again")
            if not self.own and not damaged_list:  # files found in the user's folder: as found
                self.unsealed = True
                self.seal()
            return damaged

    def _all_as_sealed(self) -> bool:
        """The lazy start-up check of a warm folder, without the lock: True when every
        cache file listed is as sealed (its entry's inode) and every entry names a listed
        file. Then there is nothing to delete or to write, and each file's content is left
        for its kernel's first look-up (:meth:`check_function`), as :meth:`verify` leaves
        it. Anything else (a file not in the list, another inode, an entry without its file,
        a damaged list) is for the check under the lock. The list is written whole or not
        at all (a new file renamed over it), so it is read whole without the lock; a file
        another process writes or deletes meanwhile is judged when it is looked up."""
        sums, damaged_list = self._read_sums()
        if damaged_list or not sums:
            return False
        files = self._entries()
        if len(files) != len(sums):
            return False
        found = []
        for name, listed in files.items():
            entry = sums.get(name)
            if entry is None or entry[2:] != [_inode(listed)]:
                return False
            found.append((name, entry))
        for name, entry in found:
            self._deferred[name] = entry[0]
            self._seen[name] = (entry[2], entry[1], 0)
        return True

    def check_function(self, subfolder: str, filename_base: str) -> int:
        """Before Numba looks up a kernel (its cache files ``<subfolder>/<filename_base>.*``):
        check the content of those of its files :meth:`verify` left for later; a damaged one
        is deleted (compiled again) with one ``warning:`` line. Returns how many were."""
        prefix = f"{subfolder}/{filename_base}."
        with self._lock:
            names = [n for n in self._deferred if n.startswith(prefix)]
            if not names:
                return 0
            wanted = {n: self._deferred.pop(n) for n in names}
        if all(self._digest(os.path.join(self.folder, n)) == d for n, d in wanted.items()):
            return 0
        with self.locked():  # another process seals (and drops its marker) under this lock
            sums, _ = self._read_sums()
            rewriting = None
            bad = []
            for name, digest in wanted.items():
                path = os.path.join(self.folder, name)
                now, st = self._read_file(path)
                if now is None or now == digest:
                    continue  # gone (another process's check), or as verify() saw it
                entry = sums.get(name)
                seen = self._seen.get(name)
                if entry is not None and entry[0] == now and entry[1] == st.st_size:
                    # written anew by another process since verify() and sealed by it
                    self._seen[name] = (st.st_ino, st.st_size, st.st_mtime_ns)
                    continue
                if seen is not None and (seen[0] != st.st_ino or seen[1] != st.st_size) \
                        and not self.read_only:
                    # a new file renamed in since verify() (as Numba writes) and not sealed
                    # yet (a new inode, or the old inode given again by the file system to
                    # the new file of another size): while its writer is still compiling,
                    # it is that process's work (whole, and sealed by it): kept, never taken
                    # for damage; a file changed in place at its sealed size is damage
                    if rewriting is None:
                        rewriting = self.others_compiling()
                    if rewriting:
                        continue
                bad.append((name, st))
            if not bad:
                return 0
            for name, st in bad:
                self._drop(os.path.join(self.folder, name), st)
                sums.pop(name, None)
                self._seen.pop(name, None)
            if not self.read_only:
                self._write_sums(sums)
                self._clear_markers()
        _warn(f"{len(bad)} damaged kernel cache file{'s' * (len(bad) > 1)} in {self.folder} "
              f"deleted; compiling {'them' if len(bad) > 1 else 'it'} again")
        return len(bad)

    def intact(self) -> bool:
        """For a folder used read-only: whether it holds a list of sums that every cache file
        in it matches (then Numba may load any of them). Changes nothing."""
        sums, damaged_list = self._read_sums()
        if damaged_list or not sums:
            return False
        files = self._files()
        for name, st in files.items():
            entry = sums.get(name)
            if entry is None or entry[1] != st.st_size \
                    or self._digest(os.path.join(self.folder, name)) != entry[0]:
                return False
            self._seen[name] = (st.st_ino, st.st_size, st.st_mtime_ns)
        return True

    def _clear_markers(self) -> None:
        for marker in Path(self.folder).glob("whitted-ready-*"):
            with contextlib.suppress(OSError):
                marker.unlink()

    def seal(self) -> None:
        """Enter in the list the cache files written since this process last looked: new
        ones, and ones replaced by a new file (module docstring)."""
        if self.folder is None or self.helper or self.read_only:
            self.unsealed = False
            return
        with self.locked():
            self.unsealed = False
            self._done_compiling()
            sums, damaged_list = self._read_sums()
            changed = False
            for name, listed in self._entries().items():
                seen = self._seen.get(name)
                entry = sums.get(name)
                if seen is not None and entry is not None and seen[0] == _inode(listed):
                    continue  # as checked (or changed in place: not sealed)
                digest, st = self._read_file(os.path.join(self.folder, name))
                if digest is None:
                    continue
                sums[name] = [digest, st.st_size, st.st_ino]  # the file hashed
                self._seen[name] = (st.st_ino, st.st_size, st.st_mtime_ns)
                # a file verify() left for later and Numba (here or in the compile helper)
                # has since written anew: sealed with its new content, so its kernel's first
                # look-up must not take it for damage and compile it a second time
                self._deferred.pop(name, None)
                changed = True
            if changed or damaged_list:
                self._write_sums(sums)


def _inode(entry: os.DirEntry) -> int | None:
    """A listed file's inode (None: gone since it was listed)."""
    try:
        return entry.inode()
    except OSError:  # Windows stats the file for it
        return None


_state: KernelCache | None = None
_state_lock = threading.Lock()


#: jit/locator.py's locator, as Numba's NUMBA_CACHE_LOCATOR_CLASSES names it
LOCATOR = "whitted.jit.locator.KernelLocator"
#: Numba's own locators, in Numba's order (after whitted's)
NUMBA_LOCATORS = ("UserProvidedCacheLocator", "InTreeCacheLocator", "UserWideCacheLocator",
                  "IPythonCacheLocator", "ZipCacheLocator")


def locator_setting(current: str) -> str:
    """The value of ``NUMBA_CACHE_LOCATOR_CLASSES`` with whitted's locator first: before the
    user's own list when there is one, else before Numba's default order."""
    names = [n.strip() for n in current.split(",") if n.strip()] or list(NUMBA_LOCATORS)
    return ",".join([LOCATOR] + [n for n in names if n != LOCATOR])


def read_only(path: str) -> bool:
    """Whether ``path`` is in the kernel cache folder this process uses read-only."""
    state = _state
    return (state is not None and state.read_only and state.folder is not None
            and os.path.abspath(path).startswith(os.path.abspath(state.folder)))


#: set beside ``NUMBA_CACHE_DIR`` when whitted chose that folder itself (not the user): a
#: whitted process this one starts (a bench run, a farm worker, ``whitted warm``'s workers)
#: inherits the environment, and must take the folder as whitted's own, chosen again for its
#: own sources, not as a folder the user named (which is checked under the lock and sealed
#: by every process, and may hold other programs' files)
OWN_FOLDER_ENV = "WHITTED_OWN_NUMBA_CACHE_DIR"


def _set_numba_cache_dir(folder: str, own: bool = True) -> None:
    os.environ["NUMBA_CACHE_DIR"] = folder
    if own:
        os.environ[OWN_FOLDER_ENV] = folder
    else:
        os.environ.pop(OWN_FOLDER_ENV, None)
    # whitted's functions filed by their folder inside whitted, not by the install path
    locators = locator_setting(os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES", ""))
    os.environ["NUMBA_CACHE_LOCATOR_CLASSES"] = locators
    if "numba" in sys.modules:  # numba already read its settings: tell it directly
        import numba

        numba.config.CACHE_DIR = folder
        numba.config.CACHE_LOCATOR_CLASSES = locators


def prepare() -> KernelCache:
    """Choose the kernel cache folder, point Numba at it, and check its files (once per
    process, before Numba loads any kernel)."""
    global _state
    if _state is not None:
        return _state
    with _state_lock:
        if _state is not None:
            return _state
        helper = os.environ.get(HELPER_ENV) == "1"
        chosen = os.environ.get("NUMBA_CACHE_DIR")
        if chosen and not helper and chosen == os.environ.get(OWN_FOLDER_ENV):
            chosen = None  # whitted's own choice, inherited from the process that started this
        own = not chosen or helper
        if not chosen:
            chosen = str(cache_dir())
        folder: str | None = chosen
        problem = _usable(chosen)
        if problem is not None and not helper and _warm_to_read(chosen):
            state = KernelCache(chosen, own, helper, read_only=True)
            if state.intact():  # a warm folder this process cannot write: loaded from only
                _set_numba_cache_dir(chosen, own)
                _state = state
                return state
            problem = f"{problem}; its files do not match its list of checksums"
        if problem is not None:
            fallback = str(Path(_user_base()) / _folder_name())
            if fallback != chosen and _usable(fallback) is None:
                _warn(f"kernel cache folder {chosen} cannot be used ({problem}); "
                      f"using {fallback}")
                folder, own = fallback, True
            else:
                _warn(f"kernel cache folder {chosen} cannot be used ({problem}); kernels are "
                      "compiled in memory (every run compiles them again)")
                folder = None
        if folder is None:
            os.environ.pop("NUMBA_CACHE_DIR", None)
            os.environ.pop(OWN_FOLDER_ENV, None)
            if "numba" in sys.modules:
                import numba

                numba.config.CACHE_DIR = ""
        else:
            _set_numba_cache_dir(folder, own)
        state = KernelCache(folder, own, helper)
        state.verify(lazy=_locator_checks())
        _state = state
        return state


def _locator_checks() -> bool:
    """Whether Numba takes jit/locator.py's locator (its NUMBA_CACHE_LOCATOR_CLASSES setting),
    which checks each kernel's files when the kernel is first looked up."""
    import numba

    return hasattr(numba.config, "CACHE_LOCATOR_CLASSES")


def _warm_to_read(folder: str) -> bool:
    """Whether ``folder`` looks like a warm kernel cache this process can read: a folder
    with whitted's list of sums in it."""
    return (os.path.isdir(folder) and os.access(folder, os.R_OK | os.X_OK)
            and os.access(os.path.join(folder, SUMS), os.R_OK))


def read_only_miss(why: str = "") -> None:
    """A kernel the read-only folder lacks is compiled in memory: say so once a process."""
    state = _state
    if state is None or state.missed:
        return
    state.missed = True
    why = why or "it lacks some kernels; warm it with this whitted, docs/farm.md"
    _warn(f"kernel cache folder {state.folder} cannot be written ({why}): kernels are "
          "compiled in memory (every run compiles them again)")


def configure_kernel_cache() -> str:
    """Point Numba's on-disk cache at whitted's checked folder (:func:`prepare`) and return
    it ("" when kernels are compiled in memory)."""
    return prepare().folder or ""
