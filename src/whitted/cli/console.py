"""The command line's consoles and rich text, made on first use.

Importing rich costs tens of milliseconds; `whitted --help` and the import of the CLI never pay
it (tests/test_startup.py). User text is printed literally: no markup, no emoji codes (a
":100:" on an error line stays ":100:").
"""

from __future__ import annotations


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
