"""whitted: a fast Whitted ray tracer.

>>> import whitted
>>> scene = whitted.load_scene("examples/transparent_sphere.toml")   # doctest: +SKIP
>>> image = whitted.render(scene, width=320, height=240)             # doctest: +SKIP
>>> image.save("out.png")                                            # doctest: +SKIP

The public names are imported on first use (a module-level ``__getattr__``), so
``import whitted`` costs a few milliseconds and a command that never renders never imports
Numba, and one that never reads a scene never imports pydantic.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING

from . import marks as _marks

_marks.mark("interpreter")  # the interpreter has started and reached whitted

from .jit import lean_numba as _lean_numba  # noqa: E402

_lean_numba.install()  # Numba's import without its SciPy, PyYAML and coverage probes

#: public name -> the module that defines it
_LAZY = {
    "Animation": ".animation", "Track": ".animation",
    "SceneError": ".errors", "WhittedError": ".errors",
    "Image": ".output",
    "CancelToken": ".render", "JobState": ".render", "Progress": ".render",
    "RenderJob": ".render", "RenderStats": ".render", "render_aovs": ".render",
    # shown live in a notebook, unchanged elsewhere (whitted.notebook)
    "render": ".notebook", "render_async": ".notebook", "render_film": ".notebook",
    "film_from_frames": ".notebook", "sweep": ".notebook", "viewer": ".notebook",
    "run_stefan": ".notebook",
    "Film": ".output.inline_film", "ContactSheet": ".animation.sheet",
    "default_scene": ".scene.default",
    "framed": ".studio", "model_scene": ".studio", "turntable": ".studio",
    **dict.fromkeys((
        "CSG", "PRESETS", "AmbientLight", "AxisAngle", "Background", "Box", "Camera",
        "CheckerTexture", "Cone", "Cylinder", "DirectionalLight", "Disk", "DiskLight",
        "Gradient", "GradientTexture", "ImageTexture", "Material", "Mesh", "Plane",
        "PointLight", "Rectangle", "RenderSettings", "Scene", "Sphere", "Torus",
        "Transform", "Triangle", "load_scene", "save_scene"), ".scene"),
}

__all__ = [
    "Animation", "Track",
    "CSG", "PRESETS", "AmbientLight", "AxisAngle", "Background", "Box", "Camera", "CancelToken",
    "CheckerTexture", "Cone", "ContactSheet", "Cylinder", "DirectionalLight", "Disk",
    "DiskLight", "Film", "Gradient", "GradientTexture", "Image", "ImageTexture", "JobState",
    "Material", "Mesh", "Plane", "PointLight", "Progress", "Rectangle", "RenderJob",
    "RenderSettings", "RenderStats", "Scene", "SceneError", "Sphere", "Torus", "Transform",
    "Triangle", "WhittedError", "__version__", "default_scene", "film_from_frames", "framed",
    "load_scene", "model_scene", "render", "render_aovs", "render_async", "render_film",
    "run_stefan", "save_scene", "sweep", "turntable", "viewer",
]


def _version() -> str:
    from .fingerprint import whitted_version

    return whitted_version()


def __getattr__(name: str):
    if name == "__version__":
        value = _version()
    elif name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    else:
        raise AttributeError(f"module 'whitted' has no attribute {name!r}")
    globals()[name] = value  # the next look-up is a plain attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


class _Package(types.ModuleType):
    """The ``whitted`` module itself. Importing the subpackage ``whitted.render`` makes Python
    set the attribute ``render`` of this module to that subpackage, which would hide the
    function ``whitted.render``; the function keeps the name (the subpackage stays reachable
    through ``sys.modules`` and ``from whitted.render import ...``)."""

    def __setattr__(self, name: str, value) -> None:
        if name in _LAZY and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


if TYPE_CHECKING:  # for type checkers and IDEs: the same names, imported eagerly
    from .animation import Animation, Track
    from .animation.sheet import ContactSheet
    from .errors import SceneError, WhittedError
    from .notebook import (
        film_from_frames,
        render,
        render_async,
        render_film,
        run_stefan,
        sweep,
        viewer,
    )
    from .output import Image
    from .output.inline_film import Film
    from .render import CancelToken, JobState, Progress, RenderJob, RenderStats, render_aovs
    from .scene import (
        CSG,
        PRESETS,
        AmbientLight,
        AxisAngle,
        Background,
        Box,
        Camera,
        CheckerTexture,
        Cone,
        Cylinder,
        DirectionalLight,
        Disk,
        DiskLight,
        Gradient,
        GradientTexture,
        ImageTexture,
        Material,
        Mesh,
        Plane,
        PointLight,
        Rectangle,
        RenderSettings,
        Scene,
        Sphere,
        Torus,
        Transform,
        Triangle,
        load_scene,
        save_scene,
    )
    from .scene.default import default_scene
