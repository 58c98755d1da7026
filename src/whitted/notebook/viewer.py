"""A small live viewer of a scene: sliders for chosen scene values (the paths of ``--set``:
``objects[ball].radius``, ``camera.aperture``, ``render.caustics.photons``), and the picture,
re-rendered when a slider moves.

Each change renders twice, as the editor's preview does: first at a quarter of the size (a
picture within a fraction of a second, scaled up), then at full size; a newer change cancels
the render in progress, so dragging a slider never queues renders. A value the scene rejects
(``radius = -1``, a path that names nothing) shows its one-line message under the picture,
the last good picture stays, and nothing is raised into the notebook.

>>> v = whitted.viewer(scene, {"camera.aperture": (0.0, 0.5, 0.01),
...                            "objects[glass sphere].material.ior": (1.0, 2.0)})  # doctest: +SKIP
"""

from __future__ import annotations

import io
import os
import threading
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import WhittedError, shorten

if TYPE_CHECKING:
    from ..output.image import Image
    from ..render.api import RenderJob
    from ..scene.scene import Scene

__all__ = ["COARSE", "Viewer", "one_line", "viewer"]

#: The first render of a change is this many times smaller on each side.
COARSE = 4


def one_line(exc: BaseException) -> str:
    """What a bad value or a failed render says, as one line."""
    from pydantic import ValidationError

    if isinstance(exc, ValidationError):
        from ..scene.messages import validation_message

        return shorten(validation_message(exc), 300)
    if isinstance(exc, WhittedError):
        text = str(exc)
        # a value set here is no command-line option: its path alone says where
        return shorten(text.removeprefix("--set: "), 300)
    return shorten(f"{type(exc).__name__}: {exc}", 300)


def _slider(path: str, spec: Any, value: Any):
    """An ipywidgets slider for ``path``: ``(min, max)`` or ``(min, max, step)`` (whole
    numbers give an IntSlider), or a list of values (a SelectionSlider)."""
    import ipywidgets as w

    short = path if len(path) <= 28 else "…" + path[-27:]
    style = {"description_width": "initial"}
    layout = w.Layout(width="460px", max_width="100%")
    if isinstance(spec, Mapping):
        if "min" not in spec or "max" not in spec:
            raise WhittedError(f"{path}: a slider given as a dict needs min and max, got "
                               f"{spec!r}")
        spec = (spec["min"], spec["max"]) + ((spec["step"],) if "step" in spec else ())
    if isinstance(spec, list):
        from ..animation.sweep import format_value

        values = list(spec)
        if not values:
            raise WhittedError(f"{path}: a slider of values needs at least one value")
        labels = [shorten(format_value(v), 24) for v in values]
        start = values.index(value) if _among(value, values) else 0
        # the slider's value is the index: any value (None, a list) can be one of them
        slider = w.SelectionSlider(options=[(label, k) for k, label in enumerate(labels)],
                                   value=start, description=short, style=style,
                                   layout=layout, continuous_update=False)
        slider.whitted_values = values
        return slider
    if not isinstance(spec, tuple) or len(spec) not in (2, 3):
        raise WhittedError(f"{path}: a slider is (min, max), (min, max, step) or a list of "
                           f"values, got {spec!r}")
    low, high = spec[0], spec[1]
    step = spec[2] if len(spec) == 3 else None
    numbers = (low, high) if step is None else (low, high, step)
    if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in numbers):
        raise WhittedError(f"{path}: a slider's bounds are numbers, got {spec!r}")
    if not all(np.isfinite(float(x)) for x in numbers) or not low < high:
        raise WhittedError(f"{path}: a slider needs finite min < max, got {spec!r}")
    whole = all(isinstance(x, int) for x in numbers)
    if whole:
        start = int(value) if isinstance(value, int | float) else low
        return w.IntSlider(value=min(max(start, low), high), min=low, max=high,
                           step=step or 1, description=short, style=style, layout=layout,
                           continuous_update=True)
    start = float(value) if isinstance(value, int | float) else float(low)
    return w.FloatSlider(value=min(max(start, low), high), min=low, max=high,
                         step=step or (high - low) / 100, description=short, style=style,
                         layout=layout, continuous_update=True, readout_format=".3g")


def _among(value: Any, values: list) -> bool:
    try:
        return value in values
    except Exception:  # noqa: BLE001 - a value that cannot be compared is not among them
        return False


def _slider_value(slider) -> Any:
    """The scene value a slider shows (a slider of values holds its index)."""
    values = getattr(slider, "whitted_values", None)
    return slider.value if values is None else values[slider.value]


def _fits(slider, value: Any) -> bool:
    """``value`` is one the slider can show as it is (sliders clamp what is outside)."""
    values = getattr(slider, "whitted_values", None)
    if values is not None:
        return _among(value, values)
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    return slider.min <= value <= slider.max and (
        not isinstance(slider.value, int) or float(value).is_integer())


class Viewer:
    """The viewer's state and widgets (``widget``). :meth:`set` changes a value as a slider
    does; :meth:`wait` waits for the renders of the last change; ``image`` is the last full
    picture, ``error`` the last message (None when the last change was good)."""

    def __init__(self, scene: Scene | str | os.PathLike[str],
                 sliders: Mapping[str, Any], *, threads: int | None = None,
                 coarse: int = COARSE, **settings: Any) -> None:
        import ipywidgets as w

        from ..scene.paths import get_value
        from .film import _scene

        base, _ = _scene(scene, settings)
        self.base = base.at_frame(0) if base.is_animated else base
        self.threads = threads
        self.coarse = max(1, int(coarse))
        self.values: dict[str, Any] = {}
        self.image: Image | None = None
        self.error: str | None = None
        self.renders = 0  # renders finished (coarse and full)
        self._cond = threading.Condition()
        self._pending: Scene | None = None
        self._job: RenderJob | None = None
        self._busy = False
        self._closed = False
        self._quiet = False
        self.sliders = {}
        for path, spec in sliders.items():
            try:
                value = get_value(self.base, path)
            except WhittedError as exc:
                raise WhittedError(f"{path}: {exc}") from None
            slider = _slider(path, spec, value)
            self.values[path] = _slider_value(slider)
            slider.observe(lambda change, p=path: self._moved(p, change["new"]), names="value")
            self.sliders[path] = slider
        r = self.base.render
        self.picture = w.Image(format="png", layout=w.Layout(width=f"{r.width}px",
                                                             max_width="100%", height="auto"))
        self.status = w.Label(value="rendering")
        view = self

        class ViewerBox(w.VBox):
            def __repr__(self) -> str:
                return f"whitted viewer ({', '.join(view.values)}): {view.status.value}"

        self.widget = ViewerBox([*self.sliders.values(), self.picture, self.status])
        self._thread = threading.Thread(target=self._work, name="whitted-viewer", daemon=True)
        self._thread.start()
        self._request()

    # ------------------------------------------------------------------ changes
    def set(self, path: str, value: Any) -> None:
        """Set ``path`` to ``value`` and re-render (a bad value: its message, no render).
        A slider of ``path`` follows when the value is one it can show."""
        self.values[path] = value
        slider = self.sliders.get(path)
        if slider is not None and _fits(slider, value):
            values = getattr(slider, "whitted_values", None)
            self._quiet = True  # its observer would come back here
            try:
                slider.value = value if values is None else values.index(value)
            finally:
                self._quiet = False
        self._request()

    def _moved(self, path: str, _index_or_value: Any) -> None:
        if not self._quiet:
            self.values[path] = _slider_value(self.sliders[path])
            self._request()

    def _request(self) -> None:
        from ..animation.overrides import apply_overrides

        try:
            scene = apply_overrides(self.base, list(self.values.items()))
        except Exception as exc:  # noqa: BLE001 - every bad value is one line, never raised
            self._show_error(one_line(exc))
            return
        with self._cond:
            self._pending = scene
            self._busy = True
            if self._job is not None:
                self._job.cancel()
            self._cond.notify_all()

    def _show_error(self, text: str) -> None:
        self.error = text
        self.status.value = f"⚠ {text}"

    # ------------------------------------------------------------------ the renders
    def _work(self) -> None:
        from ..render.api import RenderJob

        while True:
            with self._cond:
                while self._pending is None and not self._closed:
                    self._busy = False
                    self._cond.notify_all()
                    self._cond.wait()
                if self._closed:
                    return
                scene, self._pending = self._pending, None
            r = scene.render
            levels = [self.coarse, 1] if self.coarse > 1 and min(r.width, r.height) >= \
                2 * self.coarse else [1]
            for level in levels:
                small = scene if level == 1 else scene.with_settings(
                    width=max(1, r.width // level), height=max(1, r.height // level))
                job = RenderJob(small, threads=self.threads)
                with self._cond:
                    if self._pending is not None or self._closed:
                        break  # a newer change: render that one
                    self._job = job
                self.status.value = "rendering" if level == 1 else "rendering (preview)"
                try:
                    image = job.run()
                except Exception as exc:  # noqa: BLE001 - shown, never raised
                    self._show_error(one_line(exc))
                    break
                finally:
                    with self._cond:
                        self._job = None
                if job.cancelled:
                    break
                self.renders += 1
                self._show(image, (r.width, r.height), final=level == 1)

    def _show(self, image: Image, size: tuple[int, int], final: bool) -> None:
        from PIL import Image as PILImage

        picture = PILImage.fromarray(image.to_srgb8())
        if picture.size != size:
            picture = picture.resize(size, PILImage.Resampling.NEAREST)
        buf = io.BytesIO()
        picture.save(buf, format="PNG", compress_level=3)
        self.picture.value = buf.getvalue()
        if final:
            self.image = image
            self.error = None
            stats = image.meta.get("stats")
            self.status.value = stats.summary() if stats is not None else "done"

    # ------------------------------------------------------------------ for callers
    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the renders of the last change are done; False after ``timeout``."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._busy, timeout)

    def close(self) -> None:
        """Stop the viewer's thread (the render in progress is cancelled)."""
        with self._cond:
            self._closed = True
            if self._job is not None:
                self._job.cancel()
            self._cond.notify_all()
        self.widget.close()

    def _repr_mimebundle_(self, **kwargs):
        return self.widget._repr_mimebundle_(**kwargs)

    def __repr__(self) -> str:
        return repr(self.widget)


def viewer(scene: Scene | str | os.PathLike[str],
           sliders: Mapping[str, Any] | Sequence[str], *, threads: int | None = None,
           **settings: Any) -> Viewer:
    """A live viewer of ``scene`` with a slider for each path of ``sliders``: ``{path:
    (min, max)}``, ``(min, max, step)`` or a list of values; whole-number bounds give whole
    values. Keyword ``settings`` replace render settings (``width``, ``height``, ...). Moving
    a slider re-renders, coarse first; a bad value shows its one-line message. Needs the
    ``notebook`` extra (ipywidgets)."""
    from .detect import widgets_installed

    if not widgets_installed():
        raise WhittedError("whitted.viewer needs ipywidgets: pip install 'whitted[notebook]'")
    if not isinstance(sliders, Mapping):
        raise WhittedError("sliders: give {path: (min, max)}, e.g. "
                           "{'camera.aperture': (0.0, 0.5)}")
    return Viewer(scene, sliders, threads=threads, **settings)
