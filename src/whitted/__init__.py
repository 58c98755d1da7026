"""whitted: a fast Whitted ray tracer.

>>> import whitted
>>> scene = whitted.load_scene("examples/transparent_sphere.toml")   # doctest: +SKIP
>>> image = whitted.render(scene, width=320, height=240)             # doctest: +SKIP
>>> image.save("out.png")                                            # doctest: +SKIP
"""

from importlib.metadata import PackageNotFoundError, version

from ._cache import configure_kernel_cache

configure_kernel_cache()  # before any kernel module imports numba

from .animation import Animation, Track
from .errors import SceneError, WhittedError
from .output import Image
from .render import CancelToken, Progress, RenderJob, RenderStats, render, render_aovs
from .scene import (
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
    Transform,
    Triangle,
    load_scene,
    save_scene,
)
from .scene.default import default_scene

try:
    __version__ = version("whitted")
except PackageNotFoundError:  # running from a source tree without installing
    __version__ = "0+unknown"

__all__ = [
    "Animation", "Track",
    "PRESETS", "AmbientLight", "AxisAngle", "Background", "Box", "Camera", "CancelToken",
    "CheckerTexture", "Cone", "Cylinder", "DirectionalLight", "Disk", "DiskLight", "Gradient",
    "GradientTexture", "Image", "ImageTexture", "Material", "Mesh", "Plane",
    "PointLight", "Progress", "Rectangle", "RenderJob", "RenderSettings", "RenderStats", "Scene",
    "SceneError", "Sphere", "Transform", "Triangle", "WhittedError", "__version__",
    "default_scene", "load_scene", "render", "render_aovs", "save_scene",
]
