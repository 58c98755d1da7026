"""Builders run as Python on small inputs until they are compiled.

A builder (``@builder``: the kernels that read model files and build a scene's BVH and
normals) is the same source whether Numba compiles it or the interpreter runs it. Compiling
the builders costs about 6 s of CPU; running them as Python costs about 0.1 s on the default
scene's 642 triangles and grows with the input. So, until the builders are in the kernel
cache (``whitted warm`` compiles them, and so does the first input too large to run as
Python), an input under a builder's limit runs as Python: the first render of a small scene
does not wait for a compile whose result it does not need.

:func:`for_size` picks the callable. A builder's *Python twin* is its Python function with
the kernels it calls replaced by their own twins (a copy of each module's globals, so the
modules themselves are untouched). Both run the same statements on the same types, so they
give the same arrays; tests/test_python_twins.py holds every builder to that, on the bench
scenes' inputs and on random ones. Builders whose code relies on fast-math or on Numba's
types where NumPy's differ (float32 arithmetic widened to float64) are not given a limit.

The choice is made again at every call and never depends on timing: a builder is compiled
(loaded from the cache, or compiled now) when the builders' marker is in the cache folder
(:func:`builders_cached`), when it was already compiled in this process, or when the input
is over the limit.
"""

from __future__ import annotations

import contextlib
import threading
import types
from pathlib import Path

from .decorators import Kernel, kernels_by_function

#: the file in the cache folder that records the builders as compiled there
BUILDERS_MARKER = "whitted-ready-builders"

_lock = threading.Lock()
_twins: dict = {}  # Python function -> its twin
_quiet: dict = {}  # Python function -> its twin, called with NumPy's warnings off
_namespaces: dict[int, dict] = {}  # id(a module's globals) -> the twins' copy of them
_forced = threading.local()  # compiled() and as_python() blocks on this thread
#: the mode outside such blocks: None chooses by size and cache (:func:`for_size`);
#: "compiled" or "python" always (a process that tests one of them, a tool)
default_mode: str | None = None


def _python_function(value):
    """The Python function of a whitted kernel (a Kernel, or the Numba dispatcher that
    replaced it in a module's globals), else None."""
    if isinstance(value, Kernel):
        return value.py_func
    function = getattr(value, "py_func", None)
    if function is not None and function in kernels_by_function:
        return function
    return None


def _twin_of(function):
    made = _twins.get(function)
    if made is not None:
        return made
    source = function.__globals__
    namespace = _namespaces.get(id(source))
    fresh = namespace is None
    if fresh:
        namespace = dict(source)
        _namespaces[id(source)] = namespace
    made = types.FunctionType(function.__code__, namespace, function.__name__,
                              function.__defaults__, function.__closure__)
    made.__kwdefaults__ = function.__kwdefaults__
    made.__qualname__ = function.__qualname__
    made.__doc__ = function.__doc__
    _twins[function] = made
    if fresh:  # every kernel the module's functions call, as its twin
        for key, value in list(namespace.items()):
            inner = _python_function(value)
            if inner is not None:
                namespace[key] = _twin_of(inner)
    return made


def python_twin(kernel):
    """The kernel run as Python: its function, calling the twins of the kernels it calls."""
    function = _python_function(kernel)
    if function is None:
        raise TypeError(f"{kernel!r} is not a whitted kernel")
    with _lock:
        return _twin_of(function)


def _marker() -> Path | None:
    from .cache import prepare

    folder = prepare().folder
    return None if folder is None else Path(folder) / BUILDERS_MARKER


def builders_cached() -> bool:
    """Whether the builders are compiled in the kernel cache (their marker is there)."""
    marker = _marker()
    return marker is not None and marker.exists()


def mark_builders_cached() -> None:
    """Record that every builder is compiled in the cache folder (nothing where the folder
    cannot take it)."""
    marker = _marker()
    if marker is not None:
        with contextlib.suppress(OSError):
            marker.touch()


@contextlib.contextmanager
def _mode(mode: str):
    outer = getattr(_forced, "mode", None)
    _forced.mode = mode
    try:
        yield
    finally:
        _forced.mode = outer


def compiled():
    """In the block (on this thread), builders run compiled whatever their input's size:
    what compiles them for the cache."""
    return _mode("compiled")


def as_python():
    """In the block (on this thread), builders run as their Python twins whatever their
    input's size (what the tests compare with the compiled builders)."""
    return _mode("python")


def _compiled_here(kernel) -> bool:
    dispatcher = kernel._dispatcher if isinstance(kernel, Kernel) else kernel
    return dispatcher is not None and bool(getattr(dispatcher, "signatures", ()))


def for_size(kernel, size: int, limit: int):
    """What to call for ``kernel`` on an input of ``size`` (bytes, triangles, nodes: the
    unit of the call's ``limit``): the kernel itself, or its Python twin while the builders
    are not compiled and the input is at most ``limit``."""
    from .decorators import _jit_disabled

    if _jit_disabled():
        return kernel  # a Python function already
    mode = getattr(_forced, "mode", None) or default_mode
    if mode != "python" and (mode == "compiled" or size > limit or _compiled_here(kernel)
                             or builders_cached()):
        return kernel
    return _quiet_twin(kernel)


def _quiet_twin(kernel):
    """The twin, run with NumPy's floating-point warnings off: an overflow to inf (a model's
    coordinates near 1e308) is a value, as in the compiled builder, not a warning line."""
    function = _python_function(kernel)
    made = _quiet.get(function)
    if made is None:
        twin = python_twin(kernel)

        def made(*args):
            import numpy as np

            with np.errstate(all="ignore"):
                return twin(*args)

        made.__wrapped__ = twin
        _quiet[function] = made
    return made
