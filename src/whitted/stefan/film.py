"""The film of a Stefan run: one frame per saved time, rendered through the film pipeline
(:mod:`whitted.animation.film`), then each film stamped with the simulated time and encoded.

While the cavity lasts the frames are one animated still life (``film.toml`` in the run
folder: the piece on a table, backlit; its surfaces a mesh sequence, the void's bubble and the
meltwater's disc keyed per frame) rendered by :func:`~whitted.animation.film.render_film` with
any executor (this process's threads, or a Dask cluster: :class:`whitted.farm.DaskFrames`).
After a breach in drain mode there is no cavity: each saved time's own scene
(``scenes/frame_NNNN.toml``, written by the run) is a frame, rendered here. Either way each
frame is a PNG that records what it shows (:mod:`whitted.animation.frames`): a run stopped part
way keeps its finished frames and the next one renders only what is missing.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import RenderCancelled, WhittedError

if TYPE_CHECKING:
    import numpy as np

    from ..animation.film import FilmProgress, FrameExecutor
    from ..render.api import CancelToken
    from .case import Case

__all__ = ["MeltFilm", "render_melt_film", "stamp"]


@dataclass
class MeltFilm:
    """What :func:`render_melt_film` did."""

    frames: list[Path] = field(default_factory=list)  # the finished frames, in time order
    times: list[float] = field(default_factory=list)  # each frame's simulated time (s)
    count: int = 0  # frames the film has
    films: list[Path] = field(default_factory=list)  # the films encoded
    cancelled: bool = False  # stopped: the frames finished stay, no film was written
    render_seconds: float = 0.0


def stamp(path: Path, text: str) -> np.ndarray:
    """The frame ``path`` as an array with ``text`` written in its top-left corner."""
    import numpy as np
    from PIL import Image, ImageDraw

    with Image.open(path) as frame:
        image = frame.convert("RGB")
    draw = ImageDraw.Draw(image)
    size = max(12, image.height // 18)
    try:
        from PIL import ImageFont

        font = ImageFont.load_default(size=size)
    except (TypeError, OSError):  # an old Pillow: its bitmap font
        font = None
    x, y = size // 2, size // 2
    draw.text((x + 1, y + 1), text, fill=(0, 0, 0), font=font)
    draw.text((x, y), text, fill=(255, 255, 255), font=font)
    return np.asarray(image)


def render_melt_film(
    work: Path,
    case: Case,
    films: Sequence[Path],
    *,
    width: int,
    height: int,
    fps: float,
    progress: Callable[[FilmProgress], None] | None = None,
    cancel: CancelToken | None = None,
    executor: FrameExecutor | None = None,
) -> MeltFilm:
    """Render the film of the solved run in ``work`` into ``work/frames`` (resuming), then
    encode each of ``films`` (.mp4, .gif) with the simulated time stamped in every frame.
    ``progress`` and ``cancel`` as :func:`~whitted.animation.film.render_film`'s;
    ``executor`` renders the frames of the still life (default: here). Raises a one-line
    :class:`~whitted.WhittedError` (no saved time to film, a frame or an encoder that
    failed)."""
    import time

    from ..animation.film import FilmPaths, render_film
    from ..output.video import encode_film
    from ..scene import load_scene
    from .run import film_bubbles, film_frames, film_puddles, film_tracers
    from .scene import ABSORPTION_BOOST, still_life_scene, write_scene

    work = Path(work)
    shown = film_frames(work)  # to the end of the run (drain: the outer surface alone)
    result = MeltFilm(times=[f.time for f in shown], count=len(shown))
    if not shown:
        raise WhittedError(f"{work}: no saved time has a surface to film")
    started = time.perf_counter()
    if all(f.inner is not None for f in shown):  # one animated still life
        scene_path = work / "film.toml"
        write_scene(scene_path, still_life_scene(
            "surfaces/outer_{frame:04d}.ply", "surfaces/inner_{frame:04d}.ply", None,
            width=width, height=height, size_cm=100 * max(case.block.size),
            frames=len(shown), fps=fps, bubbles=film_bubbles(work, shown),
            puddles=film_puddles(work, shown, case), tracers=film_tracers(work, shown)))
        frames = render_film(load_scene(scene_path), FilmPaths(None, work / "frames"),
                             fps=fps, scene_path=scene_path, cancel=cancel,
                             progress=progress, executor=executor)
        result.frames, result.cancelled = list(frames.files), frames.cancelled
    else:  # after the breach (drain) there is no cavity: each saved time's own still life
        result.frames, result.cancelled = _saved_time_frames(work, shown, width, height,
                                                             progress, cancel)
    result.render_seconds = time.perf_counter() - started
    if result.cancelled:
        return result
    label = ("measured absorption" if ABSORPTION_BOOST == 1.0
             else f"absorption x{ABSORPTION_BOOST:g}")
    stamped = [stamp(path, f"t = {result.times[k] / 60:5.1f} min   ({label})")
               for k, path in enumerate(result.frames)]
    for path in films:
        try:
            encode_film(stamped, path, fps, cancel=cancel)
        except RenderCancelled:  # ffmpeg stopped, the film as it was
            result.cancelled = True
            return result
        except (ValueError, OSError) as exc:
            raise WhittedError(f"{path}: cannot encode: "
                               f"{getattr(exc, 'strerror', None) or exc}") from None
        result.films.append(Path(path))
    return result


def _saved_time_frames(work: Path, shown: list[Any], width: int, height: int,
                       progress: Callable[[FilmProgress], None] | None,
                       cancel: CancelToken | None) -> tuple[list[Path], bool]:
    """Each saved time's own scene (``scenes/frame_NNNN.toml``) as frame ``k`` of
    ``work/frames``, through the film pipeline's local executor (frames that record what they
    show: those already there are kept); (the frames finished, whether it was stopped)."""
    from ..animation.film import FilmProgress, FrameJob, LocalFrames, frame_name
    from ..animation.frames import frame_digest, frame_is_current
    from ..scene import load_scene

    folder = work / "frames"
    folder.mkdir(exist_ok=True)
    total = len(shown)
    done: dict[int, Path] = {}

    def tell(event: str, frame: int | None, **extra: Any) -> None:
        if progress is not None:
            progress(FilmProgress(event, frame, len(done), total, **extra))

    todo = []
    for k, f in enumerate(shown):
        still = load_scene(work / "scenes" / f"frame_{f.index:04d}.toml").with_settings(
            width=width, height=height)
        job = FrameJob(k, still, frame_digest(still, k), folder / frame_name(k, total))
        if frame_is_current(job.path, job.digest):
            done[k] = job.path
        else:
            todo.append(job)

    def finished(job: FrameJob, result: Any, warnings: list[str]) -> None:
        done[job.frame] = job.path
        tell("done", job.frame, result=result, warnings=warnings)

    complete = LocalFrames().render_frames(None, todo, finished=finished,  # type: ignore[arg-type]
                                           tell=tell if progress is not None else None,
                                           cancel=cancel)
    return [done[k] for k in range(total) if k in done], not complete
