"""whitted in Jupyter: renders that show their progress and their picture filling in, films
that play inline, sweeps as contact sheets, a viewer with sliders, Stefan runs that plot.

A client of the library's APIs (render, animation, stefan), as the command line is. The
widgets are ipywidgets (``pip install 'whitted[notebook]'``); without them, or outside a
notebook (:func:`in_notebook`), every function here does what the library's does, silently,
and the objects returned still show themselves (``_repr_png_``, ``_repr_html_``).
Importing this package imports neither ipywidgets nor IPython.
"""

from .detect import in_notebook, widgets_installed
from .film import film_from_frames, render_film, sweep
from .live_render import render, render_async
from .stefan_view import run_stefan
from .viewer import Viewer, viewer

__all__ = ["Viewer", "film_from_frames", "in_notebook", "render", "render_async",
           "render_film", "run_stefan", "sweep", "viewer", "widgets_installed"]
