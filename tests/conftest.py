"""Fixtures shared by the test modules."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def examples_dir() -> Path:
    """The repository's ``examples/`` folder of scene files."""
    return REPO_ROOT / "examples"


@pytest.fixture(scope="session")
def lecture_scene(examples_dir: Path) -> Path:
    """The lecture's two-rectangle scene (161x161; its golden pixel is row 80, column 130)."""
    return examples_dir / "lecture_rectangles.toml"
