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
wait for the safe point; the program ends with one line and the same status.

Outside a guard (while the program imports its modules and reads its input, or after the
command is done) :func:`install_process_handlers`, set first thing by the ``whitted``
program, ends the process at once with one line and the same status: nothing is being
written then, and no temporary file or child process exists. A command that runs its work
without a guard (the editor's event loop) says so with :func:`command_began`: the line then
tells what its own last words say (the editor keeps unsaved edits in its autosave first).
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Callable
from types import FrameType
from typing import TYPE_CHECKING

from .console import err

if TYPE_CHECKING:
    import typer

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "InterruptGuard", "command_began",
           "command_finished", "exit_code_of", "install_process_handlers", "last_signal"]

EXIT_INTERRUPTED = 130  # 128 + SIGINT
EXIT_TERMINATED = 143  # 128 + SIGTERM
SIGNALS = (signal.SIGINT, signal.SIGTERM)
_received: list[int] = []  # every signal a guard or the process handler took, in order
_finished: list[bool] = []  # set when the command is done (only the exit is left)
#: set by a command running its work without a guard: what a signal then says (and does)
_running: list[Callable[[], str]] = []


def exit_code_of(signum: int | None) -> int:
    """143 for SIGTERM, 130 for SIGINT (and when no signal is known)."""
    return EXIT_TERMINATED if signum == signal.SIGTERM else EXIT_INTERRUPTED


def _word(signum: int | None) -> str:
    return "terminated" if signum == signal.SIGTERM else "interrupted"


def last_signal() -> int | None:
    """The last SIGINT or SIGTERM this process took (None: none)."""
    return _received[-1] if _received else None


def install_process_handlers() -> None:
    """SIGINT and SIGTERM end the process at once (one line, 130 or 143) while no guard is
    set: the ``whitted`` program calls this before it imports anything else. Once the
    interpreter shuts down they are ignored (:func:`_ignore_while_exiting`)."""
    if threading.current_thread() is threading.main_thread():
        for sig in SIGNALS:
            signal.signal(sig, _end_at_once)
        # registered before the command runs: after the exit hooks its libraries register
        atexit.register(_ignore_while_exiting)


def _ignore_while_exiting() -> None:
    """An exit hook, run once every thread has ended and the command's files are closed:
    Python's shutdown then puts back the system's default for a signal with a Python handler
    (death by the signal, no line, while it frees its modules: some 0.1 s), never for an
    ignored one. A SIGINT or SIGTERM that late changes nothing: the process ends with the
    command's own status."""
    if threading.current_thread() is threading.main_thread():
        for sig in SIGNALS:
            with contextlib.suppress(OSError, ValueError):
                signal.signal(sig, signal.SIG_IGN)


def command_finished() -> None:
    """Say the command is done: a signal now only ends the exit sooner."""
    _finished.append(True)


def command_began(last_words: Callable[[], str]) -> None:
    """Say the command's work has begun outside a guard (the editor's window is open): a
    SIGINT or SIGTERM then calls ``last_words()``, which may save what it can, and prints
    the sentence it returns (``terminated: <it>``) before the process ends."""
    _running.append(last_words)


def _end_at_once(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    if _finished:
        what = "the command had finished"
    elif _running:
        try:
            what = _running[-1]()
        except Exception:  # noqa: BLE001 - the process ends whatever its last words do
            what = "stopped while the command was running"
    else:
        what = "stopped before the command began its work: nothing was written"
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    with contextlib.suppress(OSError):
        os.write(2, f"{_word(signum)}: {what}\n".encode())
    os._exit(exit_code_of(signum))


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
        _received.append(signum)
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
        import typer

        err.echo(f"{self.word}: {' '.join(message.split())}")
        return typer.Exit(self.exit_code)
