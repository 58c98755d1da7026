"""The film pipeline (whitted.animation.film.render_film) with the farm's executor, as the
farm's tests call it."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from whitted.animation.film import FilmResult, render_film
from whitted.farm import DaskFrames

SETTINGS = ("width", "height", "samples", "max_depth", "seed")


def farm_film(client: Any, scene: Any, folder: Path, *,
              progress: Callable[[int, int, int | None], None] | None = None,
              force: bool = False, cancel: Any = None, **options: Any) -> FilmResult:
    """The frames of ``scene`` into ``folder`` on the cluster behind ``client``: render
    settings among ``options`` replace the scene's, the rest go to :class:`DaskFrames`;
    ``progress(done, total, frame)`` for each frame finished (frame None: kept)."""
    settings = {k: options.pop(k) for k in SETTINGS if k in options}
    if settings:
        scene = scene.with_settings(**settings)

    def tell(p) -> None:
        if progress is not None and p.event == "done":
            progress(p.done, p.total, p.frame if p.result.rendered else None)

    return render_film(scene, folder, force=force, cancel=cancel, progress=tell,
                       executor=DaskFrames(client, **options))
