"""Where one ``whitted`` process spends its time: named moments on the system-wide monotonic
clock, for ``whitted bench --startup`` (bench/startup.py).

Only when ``WHITTED_STARTUP_MARKS`` names a file: :func:`mark` notes the moment (a list in
memory) and :func:`write` puts them there as JSON lines. Otherwise both do nothing and cost
a dictionary look-up. Imports nothing of whitted, so ``whitted/__init__.py`` marks the moment
the interpreter reached whitted's first line.
"""

from __future__ import annotations

import json
import os
import time

ENV = "WHITTED_STARTUP_MARKS"
_marks: list[tuple[str, float]] = []


def enabled() -> bool:
    return bool(os.environ.get(ENV))


def mark(name: str, at: float | None = None) -> None:
    """Note that ``name`` happened now (or at ``at``, a ``time.monotonic()`` value)."""
    if os.environ.get(ENV):
        _marks.append((name, time.monotonic() if at is None else at))


def note(name: str, seconds: float) -> None:
    """Note a duration measured inside a phase (the kernels' loading, the render)."""
    if os.environ.get(ENV):
        _marks.append((f"{name}:seconds", seconds))


def count(name: str, value: int) -> None:
    """Note a count (the rays of each kind a render traced)."""
    if os.environ.get(ENV):
        _marks.append((f"{name}:count", value))


def write() -> None:
    """Append the marks to the file ``WHITTED_STARTUP_MARKS`` names (nothing when unset)."""
    path = os.environ.get(ENV)
    if not path or not _marks:
        return
    with open(path, "a", encoding="utf-8") as f:
        for name, value in _marks:
            f.write(json.dumps({"name": name, "value": value}) + "\n")
    _marks.clear()
