"""A first compile is never silent: what whitted says while Numba compiles kernels.

render/warm_up.py counts the functions compiled (``compile_progress()``, 0..1); this module
says so to the user of the Python API, who has no progress bar of their own:

- a log record on the ``whitted`` logger when a compile starts (with how long the last one of
  its kind took on this machine) and when it ends;
- a progress bar (rich: on a terminal, and in a Jupyter notebook through its widgets) with the
  fraction done and the time left, on standard error, while it runs.

The command line, the editor and the farm show the compile in their own way (a bar, a
caption, a worker's log) and turn the bar off (:func:`show_compile_bar`). How long each kind
of compile took is kept in the per-user cache folder (``compile-times.json``, one figure per
kind and kernel cache folder), so a later first compile (after an upgrade) and ``whitted bench``
can say up front how long it will take.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import threading
import time
from collections.abc import Callable


def _log(message: str, *args) -> None:
    import logging

    logging.getLogger("whitted").info(message, *args)

#: "auto": a bar where it can be seen (a terminal, a notebook); False: the caller shows it
_bar: bool | str = "auto"
#: a first compile of the default scene's kernels on a 2-core machine when nothing was ever
#: measured here (docs/performance.md); only the first estimate depends on it
DEFAULT_SECONDS = {"the kernels": 20.0, "the caustics kernels": 25.0}
TIMES = "compile-times.json"


def show_compile_bar(on: bool | str) -> None:
    """``False``: the caller shows compiles itself (the CLI's bar, the editor); ``"auto"``
    (the default): a bar on a terminal or in a notebook; ``True``: always a bar."""
    global _bar
    _bar = on


def compile_bar_setting() -> bool | str:
    """What :func:`show_compile_bar` was last given (to put it back after a while)."""
    return _bar


def _times_file():
    from .cache import cache_root

    return cache_root() / TIMES


def _key(label: str) -> str:
    from .cache import kernel_source_hash

    return f"{label} {kernel_source_hash()}"


def expected_seconds(label: str) -> float:
    """How long a first compile of ``label`` takes here: the last one measured on this
    machine (any kernel version, the newest first), else a typical figure."""
    try:
        times = json.loads(_times_file().read_text(encoding="utf-8"))
    except (OSError, ValueError):
        times = {}
    if not isinstance(times, dict):
        times = {}
    exact = times.get(_key(label))
    if isinstance(exact, (int, float)) and exact > 0:
        return float(exact)
    same_kind = [v for k, v in times.items()
                 if k.startswith(label + " ") and isinstance(v, (int, float)) and v > 0]
    return float(same_kind[-1]) if same_kind else DEFAULT_SECONDS.get(label, 20.0)


def record_seconds(label: str, seconds: float) -> None:
    """Keep how long a complete first compile of ``label`` took (nothing on failure)."""
    path = _times_file()
    try:
        times = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(times, dict):
            times = {}
    except (OSError, ValueError):
        times = {}
    times.pop(_key(label), None)
    times[_key(label)] = round(seconds, 2)
    times = dict(list(times.items())[-16:])  # a few kernel versions, not every one
    tmp = path.with_name(f"{TIMES}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps(times), encoding="utf-8")
        os.replace(tmp, path)
    except OSError:
        with contextlib.suppress(OSError):
            tmp.unlink()


def _bar_wanted() -> bool:
    if _bar is True:
        return True
    if _bar is False:
        return False
    stream = sys.stderr
    try:
        if stream is not None and stream.isatty():
            return True
    except (AttributeError, ValueError):
        pass
    return "ipykernel" in sys.modules  # a notebook: rich draws its bar with a widget


class CompileReport:
    """Around a first compile: log records, and a bar while it runs (module docstring).
    ``fraction()`` says how far along it is (0..1)."""

    def __init__(self, label: str, fraction: Callable[[], float | None]) -> None:
        self.label = label
        self.fraction = fraction
        self.expected = expected_seconds(label)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.started = 0.0

    def __enter__(self) -> CompileReport:
        self.started = time.monotonic()
        _log("compiling %s (first run only; about %.0f s)", self.label, self.expected)
        if _bar_wanted():
            self._thread = threading.Thread(target=self._show, daemon=True,
                                            name="whitted-compile-bar")
            self._thread.start()
        return self

    def __exit__(self, kind, exc, tb) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5)
        seconds = time.monotonic() - self.started
        if kind is None:
            record_seconds(self.label, seconds)
            _log("compiled %s in %.1f s (the next runs load them from the cache)",
                     self.label, seconds)
        else:
            _log("compiling %s stopped after %.1f s", self.label, seconds)

    def _show(self) -> None:
        try:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                Progress,
                TaskProgressColumn,
                TextColumn,
                TimeRemainingColumn,
            )
        except ImportError:  # no bar without rich: the log records stay
            return
        console = Console(stderr=True)
        with Progress(TextColumn("[progress.description]{task.description}"), BarColumn(),
                      TaskProgressColumn(), TimeRemainingColumn(), console=console,
                      transient=True) as bar:
            task = bar.add_task(f"whitted: compiling {self.label} (first run only)",
                                total=1.0)
            while not self._stop.wait(0.1):
                bar.update(task, completed=self.fraction() or 0.0)
