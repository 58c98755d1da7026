"""The one interrupt guard of every long command (render, animate, sweep, stefan run/film, the
farm's runs).

While a command runs inside :class:`InterruptGuard`, SIGINT (Ctrl-C) and SIGTERM are handled
alike: the first one sets the guard's event and calls what the command registered
(``guard.on_interrupt(token.cancel)``): the work stops at its next safe point, every finished
frame, tile, cell or saved time is kept, temporary files are removed by the writers
(``atomic_write``), and child processes (ffmpeg) are stopped by whoever started them when
they see the cancel. The command then ends with :meth:`InterruptGuard.exit`: one line on stderr
and exit status 130 (SIGINT) or 143 (SIGTERM). A second signal raises ``KeyboardInterrupt`` at
once (a write in progress is undone by its ``atomic_write``), for a user who does not want to
wait for the safe point.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from types import FrameType

import typer

from .console import err

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "InterruptGuard"]

EXIT_INTERRUPTED = 130  # 128 + SIGINT
EXIT_TERMINATED = 143  # 128 + SIGTERM
SIGNALS = (signal.SIGINT, signal.SIGTERM)


class InterruptGuard:
    """SIGINT and SIGTERM handled alike while the ``with`` block runs (see the module).
    ``at_once``: the first signal raises ``KeyboardInterrupt`` too, for work that cannot look
    at an event (a Dask client waiting for its workers): the command catches it and ends with
    :meth:`exit`, the code saying which signal came."""

    def __init__(self, *, at_once: bool = False) -> None:
        self.at_once = at_once
        self.event = threading.Event()
        self.signum: int | None = None
        self._callbacks: list[Callable[[], object]] = []
        self._previous: dict[int, object] = {}

    def on_interrupt(self, callback: Callable[[], object]) -> InterruptGuard:
        """Call ``callback()`` (a cancel token's ``cancel``) on the first signal; at once when
        one came already."""
        self._callbacks.append(callback)
        if self.event.is_set():
            callback()
        return self

    def __enter__(self) -> InterruptGuard:
        if threading.current_thread() is threading.main_thread():
            for sig in SIGNALS:
                self._previous[sig] = signal.getsignal(sig)
                signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]
        self._previous.clear()

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.event.is_set():  # the second one: stop now
            raise KeyboardInterrupt
        self.signum = signum
        self.event.set()
        for callback in self._callbacks:
            callback()
        if self.at_once:
            raise KeyboardInterrupt

    def interrupt(self, signum: int = signal.SIGINT) -> None:
        """What a signal does, from code (tests, a caller that stops the command)."""
        self._handle(signum, None)

    @property
    def interrupted(self) -> bool:
        return self.event.is_set()

    def is_set(self) -> bool:
        """Whether a signal came: a ``should_stop`` callable."""
        return self.event.is_set()

    @property
    def terminated(self) -> bool:
        return self.signum == signal.SIGTERM

    @property
    def exit_code(self) -> int:
        return EXIT_TERMINATED if self.terminated else EXIT_INTERRUPTED

    @property
    def word(self) -> str:
        """``terminated`` (SIGTERM) or ``interrupted``."""
        return "terminated" if self.terminated else "interrupted"

    def exit(self, message: str) -> typer.Exit:
        """Print ``<word>: message`` (one line) and return the exit to raise (130 or 143)."""
        err.line(f"{self.word}: {' '.join(message.split())}")
        return typer.Exit(self.exit_code)
