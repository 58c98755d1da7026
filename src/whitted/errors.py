"""Errors a user can cause: each one renders as a single line naming file, place and problem."""

from __future__ import annotations


class WhittedError(Exception):
    """Base class of the errors whitted reports to users (CLI exit status 2)."""


class SceneError(WhittedError):
    """A scene description (file or Python object) that cannot be used.

    ``file`` is the path of the scene file (or None for an in-memory scene), ``where`` the key
    path such as ``objects[3].radius`` and ``line`` the 1-based line number when known.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        where: str | None = None,
        line: int | None = None,
    ) -> None:
        self.message = message
        self.file = file
        self.where = where
        self.line = line
        super().__init__(self.one_line())

    def one_line(self) -> str:
        head = ""
        if self.file:
            head = self.file + (f":{self.line}" if self.line else "") + ": "
        elif self.line:
            head = f"line {self.line}: "
        place = f"{self.where}: " if self.where else ""
        return f"{head}{place}{self.message}"


class RenderCancelled(WhittedError):  # noqa: N818 - reads as a state, not a failure
    """Raised by :func:`whitted.render` only when asked to; normally a cancelled render returns."""
