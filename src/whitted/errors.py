"""Errors a user can cause: each one renders as a single line naming file, place and problem.

Every error whitted raises on purpose is a :class:`WhittedError`; the command line turns one
into a single ``error:`` line and exit status 2. The subclasses:

* :class:`SceneError`: a scene, model or image file (or an in-memory scene) that cannot be
  used; ``file``, ``line`` and ``where`` (the scene key) say where.
* :class:`SceneValidationError`: a value the scene model rejects (``Sphere(radius=-1)``,
  ``Scene.model_validate(...)``). It is a :class:`SceneError` and also pydantic's
  ``ValidationError`` (``.errors()`` lists every problem), so both ``except`` clauses work.
* :class:`ArgumentError`: a bad argument to a public function (``RenderJob(tile_size=0)``);
  also a ``ValueError``.
* :class:`JobStateError`: a render job used out of order (``wait()`` before ``start()``,
  ``start()`` twice); also a ``RuntimeError``.
* :class:`OutputError`: an output file that cannot be written (or would overwrite an input).
* :class:`RenderCancelled`: raised only when asked to; normally a cancelled render returns.
"""

from __future__ import annotations

#: The longest piece of user text (a key, a value) an error message repeats.
ECHO_LIMIT = 80


def shorten(text: str, limit: int = ECHO_LIMIT) -> str:
    """``text`` cut to about ``limit`` characters (middle elided) so one line stays one line."""
    text = str(text)
    if len(text) <= limit:
        return text
    keep = max(8, limit // 2 - 2)
    return f"{text[:keep]}...({len(text) - 2 * keep} more)...{text[-keep:]}"


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


class ArgumentError(WhittedError, ValueError):
    """A bad argument to a public function of the Python API."""


class JobStateError(WhittedError, RuntimeError):
    """A render job used out of order (``wait()`` before ``start()``, ``start()`` twice)."""


class OutputError(WhittedError):
    """An output that cannot be written, or that would overwrite one of the job's inputs."""


class RenderCancelled(WhittedError):  # noqa: N818 - reads as a state, not a failure
    """Raised by :func:`whitted.render` only when asked to; normally a cancelled render returns."""


def _scene_validation_error_class() -> type:
    """:class:`SceneValidationError`, defined on first use: it subclasses pydantic's
    ``ValidationError``, and importing pydantic costs a tenth of a second that a command which
    never reads a scene (``whitted --help``) should not pay."""
    from pydantic import ValidationError

    class SceneValidationError(SceneError, ValidationError):  # type: ignore[misc]
        """A value the scene model rejects, raised by the scene classes themselves
        (``whitted.Sphere(radius=-1)``). ``str()`` is one line; ``errors()`` is pydantic's list."""

        def __init__(self, *args: object, **kwargs: object) -> None:  # built by pydantic-core
            self.message = "invalid value"
            self.file = self.where = None
            self.line = None

        @classmethod
        def wrap(cls, exc: ValidationError, where: str | None,
                 message: str) -> SceneValidationError:
            """The same problems as ``exc`` (a pydantic ValidationError), as this class, with
            the one line ``where: message`` (scene/messages.py words it)."""
            new = cls.from_exception_data(exc.title, exc.errors())  # type: ignore[arg-type]
            new.message = message
            new.file = None
            new.where = where or None
            new.line = None
            return new

        def __str__(self) -> str:
            return self.one_line()

    SceneValidationError.__qualname__ = "SceneValidationError"
    return SceneValidationError


def __getattr__(name: str):
    if name == "SceneValidationError":
        cls = _scene_validation_error_class()
        globals()[name] = cls  # the next look-up is a plain attribute
        return cls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
