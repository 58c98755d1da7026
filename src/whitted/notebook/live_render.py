"""``whitted.render`` and ``whitted.render_async``: the render API's ``render``, shown live
in a notebook (:mod:`whitted.notebook.live`), unchanged everywhere else.

>>> image = whitted.render(scene, width=320, height=240)        # doctest: +SKIP
>>> image = await whitted.render_async(scene)                   # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING

from .detect import live_view

if TYPE_CHECKING:
    from ..output.image import Image
    from ..render.api import CancelToken, Progress
    from ..scene.scene import Scene

__all__ = ["render", "render_async"]

_STOP_HINT = "interrupt the kernel (■, or I I) to stop: the picture so far is kept"


def _job(scene, progress, cancel, overrides):
    from ..render.api import RenderJob, _as_scene

    scene = _as_scene(scene)
    if overrides:
        scene = scene.with_settings(**overrides)
    return RenderJob(scene, progress=progress, cancel=cancel)


def _show(widget) -> None:
    from IPython.display import display

    display(widget)


def render(
    scene: Scene | str | os.PathLike[str],
    *,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    live: bool | None = None,
    **overrides: object,
) -> Image:
    """Render ``scene`` (a Scene, or the path of a scene file) and return the
    :class:`~whitted.Image` (float32 linear HDR); keyword overrides replace render settings
    for this call (``width``, ``height``, ``samples``, ``threads``, ...).

    In a notebook (:func:`~whitted.notebook.in_notebook`), and unless ``live=False``, the
    render shows a progress bar and its picture filling in as tiles finish; interrupting the
    kernel stops it and the tiles finished are returned (``image.meta["stats"].cancelled``).
    Everywhere else (``live=False``, a terminal, a script, no ``notebook`` extra) it is
    :func:`whitted.render.api.render`."""
    live = live_view(live)
    if not live:
        from ..render.api import render as plain

        return plain(scene, progress=progress, cancel=cancel, **overrides)
    from .live import LiveRender, watch

    job = _job(scene, progress, cancel, overrides)
    view = LiveRender(job, stop=False)
    view.status.value = f"{job.settings.width}x{job.settings.height}: {_STOP_HINT}"
    _show(view.widget)
    return watch(job, view)


async def render_async(
    scene: Scene | str | os.PathLike[str],
    *,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    live: bool | None = None,
    **overrides: object,
) -> Image:
    """:func:`render` as a coroutine (``await whitted.render_async(scene)`` in a notebook
    cell): the kernel stays free while it renders, so the view has a Stop button that
    cancels the render and keeps the picture so far. Outside a notebook it renders on a
    thread and awaits it."""
    import asyncio

    live = live_view(live)
    job = _job(scene, progress, cancel, overrides)
    if not live:
        job.start()
        while not job.join(0):
            await asyncio.sleep(0.05)
        return job.wait()  # type: ignore[return-value]
    from .live import LiveRender, watch_async

    view = LiveRender(job, stop=True)
    _show(view.widget)
    return await watch_async(job, view)
