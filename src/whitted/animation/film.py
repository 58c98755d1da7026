"""A film: the frames of an animated scene as numbered PNGs, then one MP4 or GIF.

The one place that knows how a film is laid out and made, for every caller: ``whitted
animate``, the frames of ``whitted stefan film``, the editor's "Render animation…" and the
render farm.

* :func:`frame_name`: ``0007.png``: four digits at least, as many as the last frame needs
  (``12345.png`` in a film of 20,000 frames), so the names sort in frame order.
* :func:`film_paths`: ``-o film.mp4`` -> the film and its frames folder ``film_frames/``;
  ``-o folder`` -> frames only, in that folder.
* :func:`parse_frame_range`: ``A:B`` (both included), ``A:``, ``:B`` or ``K``.
* :func:`prepare_film`: every check made before the first frame renders (one line each):
  the frame rate the format takes, the output place, no output is a file the film reads, and
  no file in the way that whitted did not write (a frame PNG carries whitted's frame record,
  :mod:`whitted.animation.frames`; anything else there is the user's, and is never written
  over).
* :func:`missing_frames`: each frame's still, the hash its PNG records and its file; the
  frames whose PNG already records that hash, made by this renderer
  (:mod:`whitted.fingerprint`), are kept (resume), the others are to render.
* :func:`render_film`: the pipeline: plan (:func:`prepare_film`), the missing frames, render
  them with an *executor*, assemble (encode the film once the whole numbered sequence is on
  disk, in frame order: a temporary file renamed when the encoder succeeded, so a good film
  is never replaced by a failed one). ``progress`` is called as it goes; ``cancel`` stops it
  (the frames finished stay; run it again to resume).

The executor renders the missing frames and writes each one's PNG (atomically, with its
record) as it is finished: :class:`LocalFrames` renders them one after another in this
process, each on the render's own threads; the render farm's
:class:`whitted.farm.DaskFrames` renders them on a Dask cluster. Any object with the same
``render_frames`` method will do (:class:`FrameExecutor`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from ..errors import OutputError, RenderCancelled, SceneError, WhittedError
from .frames import FrameRenderer, FrameResult, frame_digest, frame_is_current, is_whitted_frame

if TYPE_CHECKING:
    from ..render.api import CancelToken, Progress
    from ..scene.scene import Scene

__all__ = ["DEFAULT_FPS", "FRAME_DIGITS", "FilmPaths", "FilmPlan", "FilmProgress",
           "FilmResult", "FrameExecutor", "FrameFailed", "FrameJob", "LocalFrames",
           "check_frame_files", "film_paths", "frame_name", "missing_frames",
           "parse_frame_range", "prepare_film", "render_film"]

#: Digits of a frame's name at least (more when the film has more frames).
FRAME_DIGITS = 4
#: Frames a second of a scene without an [animation] table.
DEFAULT_FPS = 24.0


def frame_name(frame: int, count: int) -> str:
    """The file name of frame ``frame`` of a film of ``count`` frames: ``0007.png``; with
    more digits when ``count - 1`` has more than four (``00007.png`` of 20,000)."""
    return f"{int(frame):0{max(FRAME_DIGITS, len(str(max(1, int(count)) - 1)))}d}.png"


def parse_frame_range(text: str | None, count: int, where: str = "--frames") -> range:
    """``A:B`` (both included), ``A:``, ``:B`` or ``K`` -> the frames (None or blank: all);
    :class:`SceneError` at ``where`` if a frame is outside 0 .. count-1 or the range is
    empty."""
    last = count - 1
    if text is None or not text.strip():
        return range(count)
    text = text.strip()
    try:
        if ":" in text:
            a, b = text.split(":", 1)
            first = int(a) if a.strip() else 0
            final = int(b) if b.strip() else last
        else:
            first = final = int(text)
    except ValueError:
        raise SceneError(f"expected A:B (frame numbers), got {text[:80]!r}",
                         where=where) from None
    for k in (first, final):
        if not 0 <= k <= last:
            raise SceneError(f"frame {k} is outside 0..{last} (the scene has {count} "
                             f"frame{'s' if count != 1 else ''})", where=where)
    if final < first:
        raise SceneError(f"{text!r} is empty (the first frame comes after the last)",
                         where=where)
    return range(first, final + 1)


@dataclass(frozen=True)
class FilmPaths:
    """Where a film goes: the film file (None: frames only) and the folder of its frames."""

    film: Path | None
    frames: Path

    def frame(self, frame: int, count: int) -> Path:
        """The PNG of frame ``frame`` of a film of ``count`` frames."""
        return self.frames / frame_name(frame, count)


def film_paths(output: str | Path) -> FilmPaths:
    """``film.mp4`` or ``film.gif`` -> that film and its frames in ``film_frames/``; a name
    without an extension, or an existing folder -> frames only, in that folder.
    :class:`OutputError` for any other extension."""
    from ..output.video import video_format

    output = Path(output)
    if output.suffix == "" or _is_dir(output):
        return FilmPaths(None, output)
    try:
        video_format(output)
    except ValueError as exc:
        raise OutputError(f"{output}: {exc}") from None
    return FilmPaths(output, output.with_name(f"{output.stem}_frames"))


def _is_dir(path: Path) -> bool:
    try:
        return path.is_dir()
    except (OSError, ValueError):
        return False


def film_fps(scene: Scene, fps: float | None = None) -> float:
    """``fps`` when given, else the scene's ``animation.fps`` (24 without one)."""
    if fps is not None:
        return fps
    return scene.animation.fps if scene.animation is not None else DEFAULT_FPS


def check_frame_files(folder: Path, files: Sequence[Path], inputs: Sequence[Path] = ()) -> None:
    """Before anything is written into ``folder``: it is a folder (or can be made in a folder
    that takes new files), none of ``files`` is one of the job's ``inputs``, and each of
    ``files`` that exists is a frame PNG whitted wrote (it carries the frame record). Any
    other file in the way is an :class:`OutputError` naming it: a film or a sweep never
    writes over a file it did not write."""
    from ..files import same_file
    from ..output.safety import check_output_place

    try:
        exists = folder.exists()
        if exists and not folder.is_dir():
            raise OutputError(f"{folder}: is a file, not a folder for the frames: move it or "
                              "choose another output name")
    except (OSError, ValueError) as exc:
        raise OutputError(f"{folder}: cannot use as the frames folder: "
                          f"{getattr(exc, 'strerror', None) or exc}") from None
    if not exists:
        check_output_place(folder)  # its parent exists and takes new entries
        return
    check_output_place(folder / files[0].name if files else folder / "0000.png")
    in_folder = []
    for source in inputs:
        try:
            if source.resolve().parent == folder.resolve():
                in_folder.append(source)
        except (OSError, RuntimeError, ValueError):
            in_folder.append(source)
    for path in files:
        for source in in_folder:
            if same_file(path, source):
                raise OutputError(f"{path}: is an input of this job ({source}): choose "
                                  "another output name")
        if _exists(path) and not is_whitted_frame(path):
            raise OutputError(f"{path}: is in the way and whitted did not write it (it has "
                              "no frame record): move it or choose another output name")


def _exists(path: Path) -> bool:
    try:
        return path.exists() or path.is_symlink()
    except (OSError, ValueError):
        return True


@dataclass
class FilmPlan:
    """A film checked and ready to render (:func:`prepare_film`)."""

    paths: FilmPaths
    frames: list[int]  # the frames asked for, in order
    files: list[Path]  # their PNGs
    count: int  # frames of the whole film (the names' width)
    fps: float
    crf: int


def prepare_film(
    scene: Scene,
    output: str | Path | FilmPaths,
    *,
    frames: Sequence[int] | range | None = None,
    fps: float | None = None,
    crf: int | None = None,
    scene_path: str | Path | None = None,
    fps_where: str | None = None,
) -> FilmPlan:
    """Every check :func:`render_film` makes before its first frame (nothing is written):
    the frames asked for exist, the frame rate is one the film's format takes (``fps_where``
    names where it came from: ``--fps`` or ``animation.fps``), the film and the frames can
    be written where they go, none of them is a file the film reads (``scene_path``, its
    models, their MTL files and textures, every file of a mesh sequence), and no file in the
    frames' way was written by anyone but whitted. One-line :class:`~whitted.WhittedError`
    otherwise."""
    from ..output.safety import check_memory, check_outputs, input_files
    from ..output.video import DEFAULT_CRF, check_crf, check_fps, ffmpeg_exe, video_format

    paths = output if isinstance(output, FilmPaths) else film_paths(output)
    count = scene.frame_count
    chosen = list(range(count) if frames is None else frames)
    for k in chosen:
        if not 0 <= k < count:
            raise SceneError(f"frame {k} is outside 0..{count - 1}", where="frames")
    rate = film_fps(scene, fps)
    if fps_where is None:
        fps_where = "--fps" if fps is not None else "animation.fps"
    crf = DEFAULT_CRF if crf is None else crf
    try:
        check_crf(crf)
    except ValueError as exc:
        raise OutputError(f"--crf: {exc}") from None
    if paths.film is not None or fps is not None:  # frames only: no encoder, any rate
        try:
            rate = check_fps(rate, video_format(paths.film) if paths.film else "mp4")
        except ValueError as exc:
            raise OutputError(f"{fps_where}: {exc}") from None
    inputs = input_files(scene, scene_path)
    if paths.film is not None:
        check_outputs([paths.film], inputs=inputs)
        if video_format(paths.film) == "mp4":
            ffmpeg_exe()  # before the first frame: an encoder is there (whitted[film])
    files = [paths.frame(k, count) for k in chosen]
    check_frame_files(paths.frames, files, inputs)
    r = scene.render
    check_memory(r.width, r.height, "png")
    return FilmPlan(paths, chosen, files, count, rate, crf)


@dataclass
class FrameJob:
    """One frame of a film: its number, its still (``scene.at_frame(frame)``), the hash its
    PNG records (:func:`~whitted.animation.frames.frame_digest`) and its file."""

    frame: int
    still: Scene
    digest: str
    path: Path


def missing_frames(scene: Scene, plan: FilmPlan,
                   force: bool = False) -> tuple[list[FrameJob], list[FrameJob]]:
    """(the frames to render, the frames kept) of ``plan``, in frame order: a frame whose
    PNG already records its hash, made by this renderer, is kept unless ``force``."""
    todo, kept = [], []
    for frame, path in zip(plan.frames, plan.files, strict=True):
        still = scene.at_frame(frame)
        job = FrameJob(frame, still, frame_digest(still, frame), path)
        (kept if not force and frame_is_current(path, job.digest) else todo).append(job)
    return todo, kept


class FrameFailed(WhittedError):
    """A frame could not be rendered: ``frame`` and the reason, in one line."""

    def __init__(self, frame: int, reason: str) -> None:
        prefix = f"frame {frame}:"  # a reason that names its frame already is not told twice
        super().__init__(reason if reason.startswith(prefix) else f"{prefix} {reason}")
        self.frame = frame
        self.reason = reason


#: ``tell(event, frame, **extra)``: an executor's progress (events of :class:`FilmProgress`)
Tell = Callable[..., None]
#: ``finished(job, result, warnings)``: an executor wrote ``job``'s PNG
Finished = Callable[[FrameJob, FrameResult, list[str]], None]


class FrameExecutor(Protocol):
    """Renders the missing frames of a film: writes each frame's PNG (atomically, its record
    included) and calls ``finished`` for it, in any order; ``tell`` (may be None) gets the
    ``frame`` and ``tiles`` events it can give. Returns False when ``cancel`` stopped it (the
    frames finished stay). Raises :class:`FrameFailed` (after every other frame is written)
    or another one-line :class:`~whitted.WhittedError`."""

    def render_frames(self, scene: Scene, jobs: list[FrameJob], *, finished: Finished,
                      tell: Tell | None, cancel: CancelToken | None) -> bool: ...


class LocalFrames:
    """The frames one after another in this process, each on ``threads`` render threads
    (None: the scene's); ``renderer`` keeps compiled geometry between consecutive frames."""

    def __init__(self, threads: int | None = None,
                 renderer: FrameRenderer | None = None) -> None:
        self.renderer = renderer or FrameRenderer(threads)
        self.report = None

    def render_frames(self, scene: Scene, jobs: list[FrameJob], *, finished: Finished,
                      tell: Tell | None, cancel: CancelToken | None) -> bool:
        for job in jobs:
            if cancel is not None and cancel.cancelled:
                return False
            if tell is not None:
                tell("frame", job.frame)
            tiles = None if tell is None else (
                lambda p, k=job.frame: tell("tiles", k, tiles=p))
            try:
                done = self.renderer.render(job.still, job.frame, job.path, force=True,
                                            progress=tiles, cancel=cancel, digest=job.digest)
            except OSError as exc:
                raise OutputError(f"{job.path}: cannot write: {exc.strerror or exc}") from None
            if done.cancelled:
                return False
            finished(job, done, list(done.stats.warnings) if done.stats else [])
        return True

    def compiles(self) -> str:
        """What the compiles between frames reused."""
        return self.renderer.cache.stats.summary() if self.renderer.frames_rendered else ""


@dataclass
class FilmProgress:
    """What :func:`render_film`'s ``progress`` receives. ``event``: ``frame`` (frame
    ``frame`` starts), ``tiles`` (``tiles`` of it are done), ``done`` (it is finished:
    ``result``), ``encoding`` (every frame is there; the film is being encoded)."""

    event: str
    frame: int | None
    done: int  # frames finished so far (rendered or kept)
    total: int  # frames asked for
    result: FrameResult | None = None
    tiles: Progress | None = None
    warnings: list[str] = field(default_factory=list)  # new warnings of this frame


@dataclass
class FilmResult:
    """What :func:`render_film` did."""

    plan: FilmPlan
    files: list[Path] = field(default_factory=list)  # the finished frames, in frame order
    rendered: list[int] = field(default_factory=list)  # in the order they were finished
    kept: list[int] = field(default_factory=list)  # already on disk and current (resume)
    cancelled: bool = False  # stopped by ``cancel``: the frames finished are kept
    film: Path | None = None  # the film encoded (None: frames only, or not finished)
    size: tuple[int, int] = (0, 0)  # of the film's pictures (MP4: odd sides + 1)
    render_seconds: float = 0.0  # each rendered frame's time where it was rendered, summed
    encode_seconds: float = 0.0
    wall_seconds: float = 0.0
    warnings: list[str] = field(default_factory=list)
    compiles: str = ""  # what the compiles between frames reused (reuse.CompileStats.summary)
    #: what the executor says of its run (the farm's: tasks, workers, ...; None locally)
    report: Any = None

    @property
    def complete(self) -> bool:
        """Every frame asked for is on disk (and the film encoded, when one was asked for)."""
        return (len(self.files) == len(self.plan.frames)
                and (self.plan.paths.film is None or self.film is not None))


def render_film(
    scene: Scene,
    output: str | Path | FilmPaths | FilmPlan,
    *,
    frames: Sequence[int] | range | None = None,
    fps: float | None = None,
    crf: int | None = None,
    force: bool = False,
    threads: int | None = None,
    scene_path: str | Path | None = None,
    progress: Callable[[FilmProgress], None] | None = None,
    cancel: CancelToken | None = None,
    renderer: FrameRenderer | None = None,
    executor: FrameExecutor | None = None,
) -> FilmResult:
    """Render ``frames`` (default: all) of ``scene`` to numbered PNGs and encode the film.

    ``output``: ``film.mp4`` / ``film.gif`` (frames in ``film_frames/``), a folder (frames
    only), or a :class:`FilmPlan` from :func:`prepare_film` (checked already). A frame already
    on disk from the same scene, settings, files and renderer is kept (``force``: rendered
    anyway). ``executor`` renders the missing frames (default :class:`LocalFrames` with
    ``threads`` and ``renderer``; the farm's :class:`whitted.farm.DaskFrames` on a cluster).
    ``progress(FilmProgress)`` is called as frames start, progress and finish (kept frames
    first). ``cancel`` (a :class:`~whitted.render.api.CancelToken`) stops the film: the frames
    finished stay, no film is encoded (an encode in progress is stopped and its temporary
    file removed) and the result says ``cancelled``. Run it again to continue. Raises a
    one-line :class:`~whitted.WhittedError` for what cannot work (see :func:`prepare_film`), a
    frame that failed (:class:`FrameFailed`, after the executor wrote what it could), or an
    encoder that failed (``OutputError``; the frames stay)."""
    from ..output.video import encode_film, even_size

    started = time.perf_counter()
    plan = output if isinstance(output, FilmPlan) else prepare_film(
        scene, output, frames=frames, fps=fps, crf=crf, scene_path=scene_path)
    result = FilmResult(plan)
    folder = plan.paths.frames
    try:
        folder.mkdir(exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{folder}: cannot make the frames folder: "
                          f"{exc.strerror or exc}") from None
    executor = executor or LocalFrames(threads, renderer)
    total = len(plan.frames)
    on_disk: dict[int, Path] = {}

    def tell(event: str, frame: int | None, **extra: Any) -> None:
        if progress is not None:
            progress(FilmProgress(event, frame, len(on_disk), total, **extra))

    todo, kept = missing_frames(scene, plan, force)
    for job in kept:
        on_disk[job.frame] = job.path
        result.kept.append(job.frame)
        tell("done", job.frame, result=FrameResult(job.frame, job.path, job.digest,
                                                   rendered=False))

    def finished(job: FrameJob, done: FrameResult, warnings: list[str]) -> None:
        on_disk[job.frame] = job.path
        result.rendered.append(job.frame)
        result.render_seconds += done.seconds
        new = [w for w in warnings if w not in result.warnings]
        result.warnings.extend(new)
        tell("done", job.frame, result=done, warnings=new)

    try:
        if todo and not (cancel is not None and cancel.cancelled):
            result.cancelled = not executor.render_frames(
                scene, todo, finished=finished, tell=tell if progress is not None else None,
                cancel=cancel)
        elif todo:
            result.cancelled = True
    finally:
        result.files = [on_disk[k] for k in plan.frames if k in on_disk]
        result.report = getattr(executor, "report", None)
        compiles = getattr(executor, "compiles", None)
        result.compiles = compiles() if callable(compiles) else ""
    film = plan.paths.film
    if film is not None and not result.cancelled and len(result.files) == total:
        tell("encoding", None)
        encode_start = time.perf_counter()
        try:
            encode_film(result.files, film, plan.fps, crf=plan.crf, cancel=cancel)
        except RenderCancelled:
            result.cancelled = True
        except (ValueError, OSError) as exc:
            text = getattr(exc, "strerror", None) or str(exc)
            raise OutputError(f"{film}: cannot encode: {text}") from None
        else:
            result.film = film
            r = scene.render
            result.size = (even_size(r.width, r.height) if film.suffix.lower() == ".mp4"
                           else (r.width, r.height))
        result.encode_seconds = time.perf_counter() - encode_start
    result.wall_seconds = time.perf_counter() - started
    return result
