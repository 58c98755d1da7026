"""Every package of whitted imports on its own, first, in a fresh interpreter: the lazy public
API means nothing imports the scene models before, say, ``whitted.animation``, so an import
cycle between packages shows only when that package is the first one imported."""

from __future__ import annotations

import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import whitted

SRC = Path(whitted.__file__).resolve().parents[1]
PACKAGES = sorted(
    f"whitted.{info.name}" for info in pkgutil.iter_modules(whitted.__path__) if info.ispkg)


def test_there_are_packages_to_check():
    assert {"whitted.scene", "whitted.animation", "whitted.render"} <= set(PACKAGES)


@pytest.mark.parametrize("package", PACKAGES)
def test_package_imports_first(package):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
    result = subprocess.run([sys.executable, "-c", f"import {package}"], capture_output=True,
                            text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr.strip().splitlines()[-1:]


def test_render_stays_the_function_after_the_render_package_is_imported():
    """``whitted.render`` is the function, even once ``whitted.render`` the subpackage has been
    imported (Python would otherwise set the module's attribute to the subpackage)."""
    code = ("import whitted.render.api, whitted.animation, whitted\n"
            "import inspect\n"
            "assert inspect.isfunction(whitted.render), whitted.render\n"
            "assert whitted.render is whitted.render.__globals__['render']\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env=env, timeout=300)
    assert result.returncode == 0, result.stderr.strip().splitlines()[-1:]
