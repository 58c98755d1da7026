"""The command line's consoles and rich text, made on first use.

Importing rich costs tens of milliseconds; `whitted --help` and the import of the CLI never pay
it (tests/test_startup.py). User text is printed literally: no markup, no emoji codes (a
":100:" on an error line stays ":100:").

A line of plain text (:meth:`LazyConsole.line`) is written as it is while the console has not
been made: what rich writes for unstyled text printed with ``soft_wrap`` is the text and a
newline, on a terminal or not. A render never imports rich when its output goes to a pipe or
a file (a script, a film's frames, a farm worker, a benchmark), nor on a terminal when it ends
before its progress bar would appear (cli/main.py ``PROGRESS_DELAY``): 25-70 ms of its
start-up.
"""

from __future__ import annotations

import os
import sys


class LazyConsole:
    """A rich ``Console`` made on first use."""

    def __init__(self, **options) -> None:
        self._options = options
        self._made = None

    @property
    def console(self):
        if self._made is None:
            from rich.console import Console

            self._made = Console(**self._options)
        return self._made

    def __getattr__(self, name: str):
        return getattr(self.console, name)

    @property
    def _file(self):
        return self._options.get("file") or (sys.stderr if self._options.get("stderr")
                                             else sys.stdout)

    @property
    def is_terminal(self) -> bool:
        """rich's answer; False without making the console when the file is plainly not a
        terminal (not a tty, and neither ``FORCE_COLOR`` nor ``TTY_COMPATIBLE=1`` says to
        treat it as one: rich's own rules, Jupyter aside)."""
        if self._made is None and not self._terminal_possible():
            return False
        return self.console.is_terminal

    def _terminal_possible(self) -> bool:
        if "FORCE_COLOR" in os.environ or os.environ.get("TTY_COMPATIBLE") == "1":
            return True
        if "ipykernel" in sys.modules:  # rich decides about Jupyter itself
            return True
        isatty = getattr(self._file, "isatty", None)
        try:
            return bool(isatty is not None and isatty())
        except ValueError:  # a closed file
            return True

    def line(self, text: str) -> None:
        """Print ``text`` as it is (no markup, no style) and a newline."""
        if self._made is None:
            file = self._file
            file.write(text + "\n")
            file.flush()
            return
        self.console.print(Text(text), soft_wrap=True)

    # special methods are looked up on the type, not through __getattr__: rich's Live (a
    # Progress given console=err) enters the console as a context manager
    def __enter__(self):
        return self.console.__enter__()

    def __exit__(self, *exc):
        return self.console.__exit__(*exc)


class _LazyText:
    """``rich.text.Text``, imported on first use: ``Text(...)`` and ``Text.assemble(...)``."""

    def __call__(self, *args, **kwargs):
        from rich.text import Text

        return Text(*args, **kwargs)

    def __getattr__(self, name: str):
        from rich.text import Text

        return getattr(Text, name)


Text = _LazyText()
err = LazyConsole(stderr=True, highlight=False, soft_wrap=True, emoji=False)
out = LazyConsole(highlight=False, soft_wrap=True, emoji=False)
