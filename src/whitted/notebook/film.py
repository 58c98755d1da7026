"""``whitted.render_film``, ``whitted.film_from_frames`` and ``whitted.sweep``: films and
sweeps that show themselves in a notebook (a :class:`~whitted.Film` plays as an HTML5 video,
a :class:`~whitted.animation.sheet.ContactSheet` is a picture), with their progress shown
while they render (in a notebook; nothing is printed elsewhere)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .detect import live_view

if TYPE_CHECKING:
    from ..animation.sheet import ContactSheet
    from ..output.inline_film import Film
    from ..render.api import CancelToken
    from ..scene.scene import Scene

__all__ = ["film_from_frames", "render_film", "sweep"]


def _scene(scene, settings) -> tuple[Scene, Path | None]:
    from ..render.api import _as_scene

    path = Path(scene) if isinstance(scene, str | os.PathLike) else None
    scene = _as_scene(scene)
    if settings:
        scene = scene.with_settings(**settings)
    return scene, path


def _show(widget) -> None:
    from IPython.display import display

    display(widget)


def render_film(
    scene: Scene | str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    *,
    frames: Sequence[int] | range | None = None,
    fps: float | None = None,
    crf: int | None = None,
    force: bool = False,
    threads: int | None = None,
    cancel: CancelToken | None = None,
    live: bool | None = None,
    **settings: Any,
) -> Film:
    """Render the frames of an animated ``scene`` (a Scene or a scene file) and encode the
    film; return a :class:`~whitted.Film`, which plays inline in a notebook. ``output``:
    ``film.mp4`` or ``film.gif`` (frames in ``film_frames/``, kept: run it again to
    resume), or a folder (frames only; the film is then made in memory); None: a new
    temporary folder, MP4 (GIF where no MP4 encoder is installed). Keyword ``settings``
    replace render settings (``width``, ``samples``, ...). In a notebook a bar shows the
    frames and the latest one; the interrupt stops after the tiles in flight and returns the
    film of the frames finished (``film.result.cancelled``). One-line
    :class:`~whitted.WhittedError` for what cannot work, before any frame renders
    (:func:`whitted.animation.film.prepare_film`)."""
    from ..animation.film import prepare_film
    from ..animation.film import render_film as library_render_film
    from ..output.inline_film import Film, mp4_encoder
    from ..render.api import CancelToken

    scene, scene_path = _scene(scene, settings)
    if output is None:
        folder = Path(tempfile.mkdtemp(prefix="whitted-film-"))
        output = folder / ("film.mp4" if mp4_encoder() else "film.gif")
    plan = prepare_film(scene, output, frames=frames, fps=fps, crf=crf, scene_path=scene_path)
    cancel = cancel or CancelToken()
    live = live_view(live)
    view = None
    progress = None
    if live:
        from .task import TaskView

        view = TaskView("film", picture=True)
        total = len(plan.frames)
        size = f"{scene.render.width}x{scene.render.height}"

        def progress(p) -> None:
            if p.event == "tiles" and p.tiles is not None:
                view.fraction = (p.done + p.tiles.fraction) / total
            elif p.event == "done":
                view.fraction = p.done / total
                if p.result is not None and p.result.path is not None:
                    with contextlib.suppress(OSError):
                        view.png = Path(p.result.path).read_bytes()
            elif p.event == "encoding":
                view.fraction = 1.0
            view.text = (f"encoding {plan.paths.film.name}" if p.event == "encoding" else
                         f"frame {p.frame} ({p.done}/{total} done), {size}")

        _show(view.widget)

    def work():
        return library_render_film(scene, plan, force=force, threads=threads,
                                   progress=progress, cancel=cancel)

    from .task import run_in_view

    result = run_in_view(work, view, cancel)
    if result is None or not result.files:
        from ..errors import RenderCancelled

        if view is not None:
            view.end("stopped before the first frame was finished", "warning")
        raise RenderCancelled("the film was stopped before its first frame was finished")
    if result.film is not None:
        film = Film(result.film, frames=len(result.files), fps=plan.fps, size=result.size,
                    result=result, frames_folder=plan.paths.frames)
    else:  # frames only, or stopped: the frames finished, made into a film in memory
        film = Film.from_frames(list(result.files), plan.fps)
        film.result = result
        film.frames_folder = plan.paths.frames
    if view is not None:
        if result.cancelled:
            view.end(f"stopped: {len(result.files)} of {len(plan.frames)} frames in "
                     f"{plan.paths.frames} (run it again to continue)", "warning")
        else:
            view.end(f"{film!r}: {len(result.rendered)} rendered, {len(result.kept)} kept, "
                     f"{result.wall_seconds:.1f} s", "success", 1.0)
        view.picture.layout.display = "none"  # the film shows itself
    return film


def film_from_frames(folder: str | os.PathLike[str], fps: float = 24.0, *,
                     kind: str | None = None) -> Film:
    """The film of a folder of frames already rendered (``0000.png``, ``0001.png``, ...),
    made in memory: it plays inline in a notebook; ``.save("film.mp4")`` writes it."""
    from ..output.inline_film import Film

    return Film.from_frames(folder, fps, kind=kind)


def sweep(
    scene: Scene | str | os.PathLike[str],
    values: Mapping[str, Sequence[Any] | str] | Sequence[tuple[str, Sequence[Any] | str]],
    *,
    columns: int | None = None,
    title: str | None = None,
    threads: int | None = None,
    cancel: CancelToken | None = None,
    live: bool | None = None,
    **settings: Any,
) -> ContactSheet:
    """Render ``scene`` once per swept value (``{"objects[glass sphere].material.kt":
    [1, 0.5, 0]}``, one or two paths, the same paths as ``--set``; values as a list or as
    text, ``"0:1:0.25"``) and return the labelled contact sheet, which shows itself in a
    notebook. Keyword ``settings`` replace render settings of every cell (``width``, ...).
    In a notebook a bar shows the cells; the interrupt stops and returns the sheet of the
    cells finished (``complete`` False)."""
    from ..animation.sheet import render_sweep
    from ..render.api import CancelToken

    scene, _ = _scene(scene, settings)
    cancel = cancel or CancelToken()
    live = live_view(live)
    if not live:
        return render_sweep(scene, values, columns=columns, title=title, threads=threads,
                            cancel=cancel)
    from .task import TaskView, run_in_view

    view = TaskView("sweep")

    def progress(p) -> None:
        view.fraction = (p.done + (p.tiles.fraction if p.tiles is not None else 0.0)) / p.total
        view.text = f"{p.cell.label} ({p.done + 1}/{p.total})"

    _show(view.widget)
    sheet = run_in_view(lambda: render_sweep(scene, values, columns=columns, title=title,
                                             threads=threads, progress=progress,
                                             cancel=cancel), view, cancel)
    if sheet is None:
        from ..errors import RenderCancelled

        view.end("stopped", "warning")
        raise RenderCancelled("the sweep was stopped")
    if sheet.complete:
        view.end(f"{len(sheet.images)} images, sheet {sheet.width}x{sheet.height}, "
                 f"{sheet.seconds:.1f} s", "success", 1.0)
    else:
        view.end(f"stopped: {len(sheet.images)} of {_count(sheet)} images", "warning")
    return sheet


def _count(sheet) -> int:
    n = 1
    for _, values in sheet.axes:
        n *= len(values)
    return n
