"""Which renderer made a picture: everything besides the scene that decides its pixels.

A fingerprint is one line of ``name value`` pairs (here on two)::

    whitted 0.1.0 source 1906c1d2e3f4a5b6 numba 0.68.1 llvmlite 0.50.0 numpy 2.4.6
        cpu znver4/3f2a9c1e

- ``whitted``: the version installed (a name only: the source's hash is what counts);
- ``source``: a hash of every file of the whitted package (its Python source and its data
  files), by path: a change anywhere (a kernel, the scene's interpolation, the compiler, a
  default) is another renderer;
- ``numba``, ``llvmlite``, ``numpy``: the versions of the libraries that compile and run the
  kernels;
- ``cpu``: the CPU target the kernels are compiled for, as Numba chooses it: its
  ``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES`` when set (``generic``: code any CPU of the
  architecture runs), else this machine's CPU and its features (LLVM's host CPU); the
  features as a hash (``name/8 hex``).

Two processes with the same fingerprint render the same pixels from the same scene. The
render farm checks every worker's fingerprint against the client's when the worker joins, and
a film's frame records the fingerprint of the process that rendered it, so a frame made by
another renderer is never taken for a finished one.

This module imports nothing of whitted: it sits below everything that renders.
"""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

#: the PNG text key of a frame's record that holds the renderer's fingerprint
FINGERPRINT_KEY = "whitted:renderer"
#: files of the package that are not source: compiled bytecode and its folders
_NOT_SOURCE = ("__pycache__",)
_NOT_SOURCE_SUFFIXES = (".pyc", ".pyo")


def _version(distribution: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(distribution)
    except PackageNotFoundError:  # a source tree that is not installed
        return "0+unknown"


def whitted_version() -> str:
    """whitted's installed version (``0+unknown`` in a source tree that is not installed)."""
    return _version("whitted")


def package_files(root: Path | None = None) -> list[Path]:
    """Every file of the whitted package (``root``: its folder), sorted by relative path,
    compiled bytecode left out."""
    root = root or Path(__file__).parent
    files = []
    for path in root.rglob("*"):
        if any(part in _NOT_SOURCE for part in path.relative_to(root).parts):
            continue
        if path.suffix in _NOT_SOURCE_SUFFIXES or not path.is_file():
            continue
        files.append(path)
    return sorted(files, key=lambda p: p.relative_to(root).as_posix())


@functools.cache
def source_hash(root: Path | None = None) -> str:
    """16 hex digits of SHA-256 over every file of the package: its relative path, its
    size and its bytes."""
    root = root or Path(__file__).parent
    h = hashlib.sha256(b"whitted-source-v1")
    for path in package_files(root):
        data = path.read_bytes()
        h.update(f"\0{path.relative_to(root).as_posix()}\0{len(data)}\0".encode())
        h.update(data)
    return h.hexdigest()[:16]


def cpu_target() -> str:
    """``name/features-hash`` of the CPU the kernels are compiled for (Numba's choice)."""
    import llvmlite.binding as llvm
    from numba import config

    name = config.CPU_NAME or llvm.get_host_cpu_name()
    features = config.CPU_FEATURES
    if features is None:
        try:
            host = llvm.get_host_cpu_features()
        except RuntimeError:
            features = ""
        else:
            if not config.ENABLE_AVX:  # Numba leaves AVX out then
                for key in host:
                    if key.startswith("avx"):
                        host[key] = False
            features = host.flatten()
    digest = hashlib.sha256(",".join(sorted(features.split(","))).encode()).hexdigest()
    return f"{name}/{digest[:8]}"


@functools.cache
def renderer_fingerprint() -> str:
    """This process's fingerprint (computed once; module docstring)."""
    fields = [("whitted", whitted_version()), ("source", source_hash()),
              ("numba", _version("numba")), ("llvmlite", _version("llvmlite")),
              ("numpy", _version("numpy")), ("cpu", cpu_target())]
    if os.environ.get("WHITTED_NUMBA_TUNING", "1") == "0":  # stock Numba's compile options
        fields.append(("numba-tuning", "stock"))
    return " ".join(f"{name} {value}" for name, value in fields)


def fingerprint_fields(fingerprint: str) -> dict[str, str]:
    """The ``name value`` pairs of a fingerprint (an older or damaged one: what pairs up)."""
    words = fingerprint.split()
    return dict(zip(words[0::2], words[1::2], strict=False))


def fingerprint_difference(theirs: str, ours: str, whose: str = "the client's") -> str:
    """What differs between two fingerprints, for one line: ``source 2c5e..., the
    client's 1906...; cpu generic/..., the client's znver4/...``."""
    a, b = fingerprint_fields(theirs), fingerprint_fields(ours)
    names = list(dict.fromkeys([*b, *a]))
    parts = [f"{name} {a.get(name, 'none')}, {whose} {b.get(name, 'none')}"
             for name in names if a.get(name) != b.get(name)]
    return "; ".join(parts) or theirs
