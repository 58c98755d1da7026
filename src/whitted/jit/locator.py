"""Where Numba keeps a whitted kernel's cache files: the same place however whitted is
installed.

Numba's own locator for a cache folder the user names (``NUMBA_CACHE_DIR``) files a function's
cache under a subfolder derived from the *absolute* path of its source file's folder
(``kernels_<sha1 of /path/to/site-packages/whitted/kernels>``), so a checkout, an editable
install and a wheel install of the same whitted would each compile every kernel again. Its
source stamp is a hash of the file's content (Numba 0.68; older Numbas used the file's
modification time and size, which a wheel install also changes).

:class:`KernelLocator` is Numba's locator with one change: a function defined in a file of the
whitted package is filed under ``<cache folder>/<the file's folder inside whitted>``
(``kernels``, ``compile``, ``assets``, ``stefan``), so what decides where its machine code
lives is only what decides the machine code: the sources (the content stamp, and the kernel
cache folder named after a hash of every kernel source, jit/cache.py), the Numba and llvmlite
versions (the folder's name too) and the CPU (Numba's index keys each entry by the CPU name
and features). Other functions are left to Numba's own locators, in Numba's order.

It is chosen through Numba's ``NUMBA_CACHE_LOCATOR_CLASSES`` setting (a list of locator
classes, tried in order; jit/cache.py sets it), documented in Numba's reference of
environment variables since 0.62, which allows "custom locator classes ... using their full
module path". It subclasses ``numba.core.caching.UserProvidedCacheLocator`` (the locator
Numba uses for ``NUMBA_CACHE_DIR``, a public name since 0.62) and overrides only the methods
of the locator interface (``from_function``, ``get_cache_path``, ``ensure_cache_path``),
which Numba describes in its source rather than its user manual; it reads none of Numba's
private attributes. It also checks that a folder can be
written once per process rather than once per dispatcher (Numba writes a temporary file each
time), and takes a read-only warm folder (jit/cache.py ``KernelCache.read_only``) without
that check, for loading only.

This module imports Numba: Numba imports it when it first makes a cache (never before
:func:`whitted.jit.load_numba`).
"""

from __future__ import annotations

import os
import sys

from numba import config
from numba.core.caching import UserProvidedCacheLocator

from .cache import read_only

#: the whitted package's folder (this file is whitted/jit/locator.py)
PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
def package_folder(py_file: str) -> str | None:
    """The folder of ``py_file`` inside the whitted package (``kernels``, ``stefan``, ...),
    or None for a file outside it."""
    folder = os.path.dirname(os.path.abspath(py_file))
    try:
        relative = os.path.relpath(folder, PACKAGE_ROOT)
    except ValueError:  # another drive (Windows)
        return None
    if relative == os.curdir:
        return "whitted"
    if relative.startswith(os.pardir):
        return None
    return relative.replace(os.sep, "/")


class KernelLocator(UserProvidedCacheLocator):
    """Numba's locator for ``NUMBA_CACHE_DIR``, filing whitted's functions by their folder
    inside the package instead of by their absolute path (module docstring)."""

    _usable: set[str] = set()  # folders checked (once a process)

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        # one level, as jit/cache.py checks the folder's files one level down
        self._whitted_path = os.path.join(config.CACHE_DIR,
                                          package_folder(py_file).replace("/", "."))

    def get_cache_path(self):
        """The folder of the function's cache files (the locator interface's method)."""
        return self._whitted_path

    @classmethod
    def from_function(cls, py_func, py_file):
        if not config.CACHE_DIR or package_folder(py_file) is None:
            return None  # not whitted's: Numba's own locators decide
        locator = super().from_function(py_func, py_file)
        if locator is not None:
            locator.check_files(py_func, py_file)
        return locator

    def check_files(self, py_func, py_file: str) -> None:
        """Before Numba reads this function's cache files: have jit/cache.py check the ones
        whose content it left for now (it hashes only the files a process loads). Their
        names are Numba's: ``<module>.<qualname>-<line>.py<version>`` then ``.nbi`` or
        ``.<n>.nbc``."""
        from .cache import _state

        if _state is None or _state.folder is None:
            return
        modname = os.path.splitext(os.path.basename(py_file))[0]
        qualname = py_func.__qualname__.replace("<", "").replace(">", "")
        base = (f"{modname}.{qualname}-{self.get_disambiguator()}.py{sys.version_info[0]}"
                f"{sys.version_info[1]}{getattr(sys, 'abiflags', '')}")
        subfolder = os.path.relpath(self.get_cache_path(), _state.folder).replace(os.sep, "/")
        _state.check_function(subfolder, base)

    def ensure_cache_path(self):
        path = self.get_cache_path()
        if path in self._usable:
            return
        if not read_only(path):  # a read-only warm folder: loaded from only
            super().ensure_cache_path()  # OSError when the folder cannot be used
        self._usable.add(path)
