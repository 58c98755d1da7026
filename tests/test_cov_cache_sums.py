"""The kernel cache's list of checksums (jit/cache.py ``KernelCache``) on a folder of
stand-in cache files: a list of the wrong shape, a list that cannot be written, a missing
folder, a read-only folder's one warning; and the renderer's fingerprint built from the
kernel sources' hash (whitted/fingerprint.py)."""

from __future__ import annotations

import hashlib
import json
import re

from hypothesis import given
from hypothesis import strategies as st

from whitted.jit import cache as _cache
from whitted.jit.cache import SUMS, KernelCache


def _folder(tmp_path):
    """A cache folder holding two stand-in Numba files in a module's subfolder."""
    sub = tmp_path / "cache" / "whitted_kernels"
    sub.mkdir(parents=True)
    (sub / "k.f-1.py312.nbi").write_bytes(b"index")
    (sub / "k.f-1.py312.1.nbc").write_bytes(b"code")
    return tmp_path / "cache"


def test_sealed_files_are_intact_and_kept(tmp_path):
    folder = _folder(tmp_path)
    cache = KernelCache(str(folder), True, False)
    cache.unsealed = True
    cache.seal()
    sums = json.loads((folder / SUMS).read_text())
    assert sums["whitted_kernels/k.f-1.py312.nbi"][:2] == [
        hashlib.sha256(b"index").hexdigest(), 5]
    assert KernelCache(str(folder), True, False, read_only=True).intact()
    assert KernelCache(str(folder), True, False).verify() == 0
    assert sorted(p.name for p in (folder / "whitted_kernels").iterdir()) == [
        "k.f-1.py312.1.nbc", "k.f-1.py312.nbi"]


def test_a_list_of_the_wrong_shape_is_damaged_and_its_files_go(tmp_path, capsys):
    folder = _folder(tmp_path)
    (folder / SUMS).write_text(json.dumps({"whitted_kernels/k.f-1.py312.nbi": "not a list"}))
    assert not KernelCache(str(folder), True, False, read_only=True).intact()
    assert KernelCache(str(folder), True, False).verify() == 0
    err = capsys.readouterr().err
    assert err == (f"warning: the kernel cache's list of checksums in {folder} was damaged; "
                   "its kernels are compiled again\n")
    assert list((folder / "whitted_kernels").iterdir()) == []
    assert json.loads((folder / SUMS).read_text()) == {}  # rewritten, empty


def test_a_list_that_cannot_be_written_leaves_the_files_unsealed(tmp_path):
    folder = _folder(tmp_path)
    (folder / SUMS).mkdir()  # the list's name taken by a folder: the rename fails
    cache = KernelCache(str(folder), True, False)
    cache.unsealed = True
    cache.seal()  # no error
    assert (folder / SUMS).is_dir()
    assert [p.name for p in folder.iterdir() if p.name.endswith(".tmp")] == []


def test_a_missing_folder_has_no_files_and_a_missing_file_no_digest(tmp_path):
    cache = KernelCache(str(tmp_path / "missing"), True, False)
    assert cache._files() == {}
    assert KernelCache._digest(str(tmp_path / "missing" / "x.nbi")) is None


def test_a_read_only_folder_says_once_that_it_compiles_in_memory(tmp_path, monkeypatch,
                                                                   capsys):
    folder = _folder(tmp_path)
    state = KernelCache(str(folder), True, False, read_only=True)
    monkeypatch.setattr(_cache, "_state", state)
    _cache.read_only_miss()
    _cache.read_only_miss("again")
    assert capsys.readouterr().err == (
        f"warning: kernel cache folder {folder} cannot be written (it lacks some kernels; "
        "warm it with this whitted, docs/farm.md): kernels are compiled in memory (every run "
        "compiles them again)\n")
    assert state.missed


def test_the_fingerprint_names_the_version_the_source_the_libraries_and_the_cpu():
    import llvmlite
    import numba
    import numpy

    import whitted
    from whitted.fingerprint import renderer_fingerprint, source_hash

    fingerprint = renderer_fingerprint()
    assert fingerprint.startswith(f"whitted {whitted.__version__} source {source_hash()} "
                                  f"numba {numba.__version__} llvmlite {llvmlite.__version__} "
                                  f"numpy {numpy.__version__} cpu ")
    assert re.fullmatch(r"whitted \S+ source [0-9a-f]{16} numba \S+ llvmlite \S+ numpy \S+ "
                        r"cpu \S+/[0-9a-f]{8}", fingerprint)
    assert renderer_fingerprint() is fingerprint  # computed once


_WORD = st.text(alphabet="abcdefghijklmnopqrstuvwxyz0123456789./-+", min_size=1, max_size=12)


@given(st.dictionaries(_WORD, _WORD, min_size=1, max_size=6), st.data())
def test_a_fingerprint_difference_names_exactly_what_differs(ours, data):
    from whitted.fingerprint import fingerprint_difference, fingerprint_fields

    changed = data.draw(st.sets(st.sampled_from(sorted(ours))))
    theirs = {k: (v + "x" if k in changed else v) for k, v in ours.items()}
    a = " ".join(f"{k} {v}" for k, v in theirs.items())
    b = " ".join(f"{k} {v}" for k, v in ours.items())
    assert fingerprint_fields(a) == theirs and fingerprint_fields(b) == ours
    text = fingerprint_difference(a, b)
    if not changed:
        assert text == a  # nothing differs: the fingerprint itself
        return
    parts = text.split("; ")
    assert [p.split(" ")[0] for p in parts] == [k for k in ours if k in changed]
    for part in parts:
        name = part.split(" ")[0]
        assert part == f"{name} {theirs[name]}, the client's {ours[name]}"


def test_the_source_hash_covers_every_file_of_the_package(tmp_path):
    """Any file of the package, kernel or not, source or data, changes the hash; compiled
    bytecode does not."""
    import shutil
    from pathlib import Path

    import whitted
    from whitted.fingerprint import source_hash

    copy = tmp_path / "whitted"
    shutil.copytree(Path(whitted.__file__).parent, copy,
                    ignore=shutil.ignore_patterns("__pycache__"))
    before = source_hash(copy)
    (copy / "__pycache__").mkdir(exist_ok=True)
    (copy / "__pycache__" / "x.cpython-311.pyc").write_bytes(b"\0")
    assert source_hash.__wrapped__(copy) == before
    seen = {before}
    for name in ("scene/interpolate.py", "cli/render.py", "scene/data/default.toml"):
        path = copy / name
        path.write_bytes(path.read_bytes() + b"\n")
        now = source_hash.__wrapped__(copy)
        assert now not in seen
        seen.add(now)
