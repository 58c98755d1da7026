"""The command line's consoles and rich text, made on first use.

Importing rich costs tens of milliseconds; `whitted --help` and the import of the CLI never pay
it (tests/test_startup.py). User text is printed literally: no markup, no emoji codes (a
":100:" on an error line stays ":100:").

A line of plain text (:meth:`LazyConsole.echo`) is written as it is while the console has not
been made: what rich writes for unstyled printable text printed with ``soft_wrap`` is the text
and a newline, on a terminal or not (text with tabs or control characters goes to rich, which
expands or drops them). A render never imports rich when its output goes to a pipe or
a file (a script, a film's frames, a farm worker, a benchmark), nor on a terminal when it ends
before its progress bar would appear (cli/render.py ``PROGRESS_DELAY``): 25-70 ms of its
start-up.

A :class:`LazyConsole` stands in for rich's ``Console`` wherever rich takes one (a ``Progress``,
a ``Live``, a ``Status``): it adds only names rich's ``Console`` does not have (``echo``) and
answers ``is_terminal`` as rich does, so rich calling any of its console's methods on it (a
``Live`` ending with ``console.line()``) reaches the real console.
"""

from __future__ import annotations

import os
import sys


class LazyConsole:
    """A rich ``Console`` made on first use; every attribute but :meth:`echo` and the
    lazily answered ``is_terminal`` is the console's own."""

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
    def _target(self):
        return self._options.get("file") or (sys.stderr if self._options.get("stderr")
                                             else sys.stdout)

    @property
    def is_terminal(self) -> bool:
        """rich's ``Console.is_terminal``, answered by rich's own rules without making the
        console (``TTY_COMPATIBLE``, then ``FORCE_COLOR``, then ``isatty()``); Jupyter, IDLE
        and an explicit ``force_terminal`` are left to rich."""
        if self._made is None:
            answer = self._terminal_by_rules()
            if answer is not None:
                return answer
        return self.console.is_terminal

    def _terminal_by_rules(self) -> bool | None:
        if ("force_terminal" in self._options or "ipykernel" in sys.modules
                or getattr(sys.stdin, "__module__", "").startswith("idlelib")):
            return None
        compatible = os.environ.get("TTY_COMPATIBLE", "")
        if compatible in ("0", "1"):
            return compatible == "1"
        force_color = os.environ.get("FORCE_COLOR")
        if force_color is not None:
            return force_color != ""
        isatty = getattr(self._target, "isatty", None)
        try:
            return False if isatty is None else bool(isatty())
        except ValueError:  # a closed file
            return False

    def echo(self, text: str) -> None:
        """Print ``text`` as it is (no markup, no style) and a newline."""
        if self._made is None and text.isprintable():  # rich drops or expands the others
            file = self._target
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
