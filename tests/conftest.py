"""Fixtures shared by the test modules."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

from whitted.jit import python_twins

# Property tests draw the same cases on every run (CI and here): a failure is reproducible,
# and a run never fails on a case no earlier run drew. Explore with HYPOTHESIS_PROFILE=explore.
settings.register_profile("whitted", derandomize=True, database=None, deadline=None)
settings.register_profile("explore", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "whitted"))

REPO_ROOT = Path(__file__).resolve().parents[1]

# The tests' own processes run the compiled builders on every input, as a warmed cache does;
# small inputs would otherwise run their Python twins until the builders are compiled
# (jit/python_twins.py). tests/test_python_twins.py holds the twins to the compiled results,
# and the command tests (processes of their own) meet the twins on an empty cache.
python_twins.default_mode = "compiled"


@pytest.fixture(scope="session")
def examples_dir() -> Path:
    """The repository's ``examples/`` folder of scene files."""
    return REPO_ROOT / "examples"


@pytest.fixture(scope="session")
def lecture_scene(examples_dir: Path) -> Path:
    """The lecture's two-rectangle scene (161x161; its golden pixel is row 80, column 130)."""
    return examples_dir / "lecture_rectangles.toml"
