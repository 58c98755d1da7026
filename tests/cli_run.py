"""Running ``whitted ARGS`` in the test's own process through the console entry point (fast,
and it includes main()'s error handling): the status, stdout and stderr, and the check that
an outcome is exactly one ``error:`` line."""

from __future__ import annotations

import contextlib
import io
import os
import sys
from pathlib import Path

from whitted.cli import main as cli_main


def run_main(*args: object, cwd: Path) -> tuple[int, str, str]:
    """``whitted ARGS`` run in this process from ``cwd``: (status, stdout, stderr). The
    process is never ended at once after the command (main()'s shortcut for a real run)."""
    out, err = io.StringIO(), io.StringIO()
    previous_cwd, previous_argv = Path.cwd(), sys.argv
    previous_exit = cli_main.EXIT_AT_ONCE_WHEN_ABANDONED
    cli_main.EXIT_AT_ONCE_WHEN_ABANDONED = False
    os.chdir(cwd)
    sys.argv = ["whitted", *map(str, args)]
    code: object = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                cli_main.main()
            except SystemExit as exc:
                code = exc.code
    finally:
        os.chdir(previous_cwd)
        sys.argv = previous_argv
        cli_main.EXIT_AT_ONCE_WHEN_ABANDONED = previous_exit
    return (code if isinstance(code, int) else 0 if code is None else 1), out.getvalue(), \
        err.getvalue()


def one_line_error(result: tuple[int, str, str], *needles: str) -> str:
    """The one ``error:`` line of a status-2 outcome, holding every needle."""
    code, out, err = result
    assert code == 2, result
    assert "Traceback" not in err + out
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), lines[0]
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]
