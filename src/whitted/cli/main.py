"""The ``whitted`` command's entry point: every command registered on the app (each in its
own module), then one run of it, where a user mistake ends as one ``error:`` line and status
2, a signal as one line and 130 / 143, and nothing in a traceback."""

from __future__ import annotations

import contextlib
import gc
import os
import re
import signal
import sys

import typer

try:  # typer vendors click from 0.2x on; older releases depend on click itself
    from typer._click.exceptions import UsageError
except ImportError:  # pragma: no cover - depends on the installed typer
    from click.exceptions import UsageError

# the commands register themselves on `app` when imported
from ..errors import WhittedError
from ..jit.collector import keep_leftovers
from ..jit.progress import show_compile_bar
from . import animate as _animate  # noqa: F401
from . import bench as _bench  # noqa: F401
from . import examples as _examples  # noqa: F401
from . import export as _export  # noqa: F401
from . import info as _info  # noqa: F401
from . import render as _render  # noqa: F401
from . import stefan as _stefan  # noqa: F401
from . import sweep as _sweep  # noqa: F401
from . import warm as _warm  # noqa: F401
from .app import (
    EXIT_USER_ERROR,
    abandoned,
    app,
    collector_paused,
    ends_at_once,
    one_line,
    resume_collector,
)
from .console import Text, err
from .interrupt import command_finished, exit_code_of, last_signal

#: After an interrupt during the first compile the render thread is abandoned; the process
#: then ends at once (os._exit) instead of waiting for the compiler to let the interpreter
#: shut down (seconds). A local ``render`` also ends at once once its files are written and
#: its output flushed: tearing down the interpreter (freeing Numba's, LLVM's and NumPy's
#: modules one by one) took 0.1-0.15 s of CPU after the picture was done, and there is
#: nothing left to clean up. Tests that run the command in-process turn this off.
EXIT_AT_ONCE_WHEN_ABANDONED = True


def main() -> None:
    """Console entry point: usage mistakes end as one ``error:`` line and status 2; nothing
    ends in a traceback (set WHITTED_DEBUG=1 to see one for an internal error)."""
    if len(sys.argv) > 1 and sys.argv[1] == "render" and gc.isenabled():
        gc.disable()  # until the render's set-up is done: _resume_collector
        collector_paused.append(True)
    if EXIT_AT_ONCE_WHEN_ABANDONED and (len(sys.argv) < 2 or sys.argv[1] != "gui"):
        # this process ends with its command (the editor's does not; an in-process run in
        # a test goes on): what a compile leaves is frozen, not collected (jit/collector.py)
        keep_leftovers()

    # No BLAS thread pool: the commands' NumPy work is small matrices and element-wise
    # arithmetic (the renderer's threads are Numba's), and starting OpenBLAS's pool made
    # importing NumPy 0.05 s slower on a 2-core machine. A user's own setting is kept.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    # No search for pydantic plugins: validating a scene, pydantic would read the metadata of
    # every installed distribution (a file or two each) for plugins that observe validation,
    # 0.01 s and some 200 file system calls in a virtual environment of a hundred packages,
    # for a program that has none. A user's own setting (even an empty one) is kept.
    os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")
    show_compile_bar(False)  # the commands show a first compile in their own progress bars
    abandoned.clear()
    ends_at_once.clear()
    _summaries()  # after every command registered (program.py adds gui)
    try:
        with only_the_command_named(sys.argv):
            code = app(standalone_mode=False)
        command_finished()
        if (abandoned or ends_at_once) and EXIT_AT_ONCE_WHEN_ABANDONED:
            _exit_now(code if isinstance(code, int) else 0)
    except UsageError as exc:
        command = "whitted" if exc.ctx is None or exc.ctx.parent is None else (
            f"whitted {exc.ctx.info_name}"
        )
        hint = f" (see '{command} --help')"
        err.print(Text.assemble(("error:", "bold red"), " ",
                                one_line(exc.format_message()) + hint), soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except (typer.Abort, KeyboardInterrupt):  # a second signal: stopped at once
        signum = last_signal()
        err.echo(f"{'terminated' if signum == signal.SIGTERM else 'interrupted'}: stopped at "
                 "once (what was being written was not kept)")
        sys.exit(exit_code_of(signum))
    except typer.Exit as exc:  # raised with standalone_mode=False only by an eager callback
        sys.exit(exc.exit_code)
    except WhittedError as exc:  # a user mistake a command did not catch itself
        err.print(Text.assemble(("error:", "bold red"), " ", one_line(str(exc))), soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except MemoryError:
        from ..files.memory import memory_room

        room = memory_room()
        err.print(Text.assemble(("error:", "bold red"), " ", one_line(
            "out of memory" + (f": {room.describe()}" if room is not None else ""))),
            soft_wrap=True)
        sys.exit(EXIT_USER_ERROR)
    except Exception as exc:  # noqa: BLE001 - a bug: one line, the traceback on request
        if os.environ.get("WHITTED_DEBUG"):
            raise
        err.print(Text.assemble(("internal error:", "bold red"), " ", one_line(
            f"{type(exc).__name__}: {exc} (please report it; WHITTED_DEBUG=1 shows the "
            "traceback)")), soft_wrap=True)
        sys.exit(1)
    finally:
        resume_collector()  # a render that ended before its job (a usage error), a caller
    sys.exit(code if isinstance(code, int) else 0)


def _first_sentence(text: str) -> str:
    """The first sentence of a docstring, its lines joined."""
    joined = " ".join(text.split())
    return re.split(r"(?<=[.!?])\s+(?=[A-Z])", joined, maxsplit=1)[0]


def _summaries() -> None:
    """Give every command a one-sentence summary for the list ``whitted --help`` shows:
    typer shows a command's first paragraph there with its docstring's line breaks kept (a
    line cut short in mid-sentence), and a whole paragraph is too long for a list."""
    groups = [app]
    while groups:
        group = groups.pop()
        groups.extend(g.typer_instance for g in group.registered_groups if g.typer_instance)
        for info in group.registered_commands:
            if info.short_help is None:
                doc = info.help or (info.callback.__doc__ if info.callback else None)
                if doc:
                    info.short_help = _first_sentence(doc)


def _command_name(info: typer.models.CommandInfo) -> str:
    return info.name or typer.main.get_command_name(info.callback.__name__)


@contextlib.contextmanager
def only_the_command_named(argv: list[str]):
    """While ``app`` runs: only the command ``argv`` names, when its first argument names
    one. Before it dispatches, typer makes a click command of every registered command,
    evaluating each parameter's annotation: 18 ms of every run for whitted's eight, against
    about 3 ms for one. Anything else (no argument, an option first, the ``stefan`` group, a
    misspelt command) keeps them all, so ``whitted --help`` and typer's suggestions are whole;
    a command's own help and errors are the same either way (tests/test_cli.py)."""
    chosen = [info for info in app.registered_commands
              if len(argv) > 1 and _command_name(info) == argv[1]]
    if len(chosen) != 1:
        yield
        return
    saved = app.registered_commands, app.registered_groups
    app.registered_commands, app.registered_groups = chosen, []
    try:
        yield
    finally:
        app.registered_commands, app.registered_groups = saved


def _exit_now(code: int) -> None:
    """End the process now (output flushed), not waiting for an abandoned render thread."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
    os._exit(code)
