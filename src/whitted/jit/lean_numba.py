"""Import Numba without its three optional probes: SciPy, PyYAML and coverage.py.

``import numba`` imports SciPy, when it is installed, only to check its version; PyYAML only
to read a ``.numba_config.yaml`` in the working folder, if there is one; and coverage.py only
so that, when a coverage measurement is running in the process, it can report the lines of
compiled functions. whitted's kernels need none of them, but its extras install the first
two (scikit-image brings SciPy, Dask brings PyYAML) and a development environment the third
(41 modules), and the three imports cost every render about 0.045 s of start-up (AMD EPYC,
Python 3.11: 10.9 ms SciPy, 10.8 ms PyYAML, 23 ms coverage.py, out of Numba's 0.14 s).

:func:`install` puts a one-shot finder on ``sys.meta_path``: when Numba is first imported it
runs Numba's own loader with those names marked absent in ``sys.modules`` (so ``import
scipy`` there raises ImportError, which Numba expects), then removes the marks and itself.
All three stay importable afterwards: the Stefan solver's scikit-image and the farm's Dask
import them as usual. PyYAML is left alone when a ``.numba_config.yaml`` is there to read;
coverage.py when it is imported already (``coverage run``, pytest-cov: a measurement can only
be running once it is), so Numba still reports compiled lines to a running measurement.
Numba's SciPy-backed linear algebra imports SciPy when such a function compiles, not at import.
"""

from __future__ import annotations

import os
import sys
from importlib.machinery import PathFinder

#: What Numba imports only to probe for (see the module docstring).
PROBES = ("scipy", "yaml", "coverage")
NUMBA_CONFIG_FILE = ".numba_config.yaml"


def probes_to_skip() -> list[str]:
    """The probes to mark absent now: those not imported already, and PyYAML only when there
    is no Numba config file for it to read."""
    skip = [name for name in PROBES if name not in sys.modules]
    if "yaml" in skip and os.path.isfile(NUMBA_CONFIG_FILE):
        skip.remove("yaml")
    return skip


class LeanNumbaFinder:
    """A meta path finder (importing ``importlib.abc`` for its base class would cost more
    than it saves) that finds nothing itself: on the first ``import numba`` it wraps the
    real loader."""

    def find_spec(self, fullname, path, target=None):
        if fullname != "numba":
            return None
        uninstall()
        spec = PathFinder.find_spec(fullname, path)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run_module = spec.loader.exec_module

        def exec_module(module):
            skipped = probes_to_skip()
            for name in skipped:
                sys.modules[name] = None  # "import scipy" raises ImportError
            try:
                run_module(module)
            finally:
                for name in skipped:
                    if name in sys.modules and sys.modules[name] is None:
                        del sys.modules[name]

        spec.loader.exec_module = exec_module
        return spec


_finder = LeanNumbaFinder()


def install() -> None:
    """Make the next first ``import numba`` lean (nothing to do once Numba is imported)."""
    if "numba" not in sys.modules and _finder not in sys.meta_path:
        sys.meta_path.insert(0, _finder)


def uninstall() -> None:
    if _finder in sys.meta_path:
        sys.meta_path.remove(_finder)
