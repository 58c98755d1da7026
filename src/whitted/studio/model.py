"""A quick look at a model file: ``whitted render model.obj`` (also ``gui``, ``animate``,
``export``, ``--turntable``). The model stands on a ground that catches its shadow, lit by a
studio rig (a big soft key light, a soft fill, a rim light from behind, a little ambient),
seen by the framed camera of :mod:`.framing`; it keeps the file's own materials (MTL, glTF) or
gets a neutral clay when the file has none."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, SceneError
from ..scene import (
    AmbientLight,
    Background,
    DiskLight,
    Material,
    Mesh,
    Plane,
    RenderSettings,
    Scene,
    Transform,
)
from .framing import AZIMUTH, ELEVATION, camera_for, view_direction

#: the model files whitted reads (assets/): what ``whitted render FILE`` takes as a model
MODEL_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")

#: the model's material when its file gives none: a light warm clay with a soft highlight
CLAY = Material(color=(0.86, 0.8, 0.7), ka=0.25, kd=0.8, ks=0.18, shininess=60.0)
GROUND = Material(color=(0.6, 0.62, 0.65), ka=0.3, kd=0.75)
SKY = Background.model_validate({"gradient": {"top": (0.55, 0.6, 0.68),
                                              "bottom": (0.86, 0.87, 0.88)}})
UP_AXES = {"y": None, "z": (-90.0, 0.0, 0.0), "x": (0.0, 0.0, 90.0)}


def is_model_file(path: str | Path) -> bool:
    return Path(path).suffix.lower() in MODEL_SUFFIXES


def _has_own_materials(data) -> bool:
    return any(m != Material() for m in data.materials)


def studio_lights(centre: np.ndarray, radius: float, up=(0.0, 1.0, 0.0),
                  azimuth: float = AZIMUTH) -> list:
    """The rig around a model at ``centre`` of size ``radius``, placed relative to the
    camera's side (``azimuth``): key light above and to the left of the camera, fill from
    the right at eye level, rim light behind; each a disk light for soft shadows."""
    def place(az: float, el: float, distance: float) -> np.ndarray:
        return centre + view_direction(az, el, up) * distance * radius

    def disk(position: np.ndarray, size: float, intensity: float, name: str) -> DiskLight:
        normal = centre - position
        return DiskLight(name=name, center=tuple(position),
                         normal=tuple(normal / np.linalg.norm(normal)),
                         radius=size * radius, intensity=intensity, samples=16)

    return [
        disk(place(azimuth - 55.0, 50.0, 6.0), 1.2, 0.85, "key"),
        disk(place(azimuth + 70.0, 15.0, 6.0), 2.0, 0.3, "fill"),
        disk(place(azimuth + 180.0, 40.0, 6.0), 1.0, 0.35, "rim"),
        AmbientLight(name="ambient", intensity=0.35),
    ]


def model_scene(model: str | Path, *, up: str = "y", width: int = 800, height: int = 600,
                azimuth: float = AZIMUTH, elevation: float = ELEVATION,
                all_around: bool = False) -> Scene:
    """A scene showing the model file ``model``: the model (its own materials, or clay) on a
    ground plane under its lowest point, the studio lights, a sky gradient and a framed
    three-quarter view (with ``all_around``, far enough to stay in frame from every side, for
    :func:`~whitted.turntable`). ``up``: the model's up axis (``y``, as glTF and most OBJ files;
    ``z``, as many CAD and scan files; ``x``). One-line SceneError for a model that cannot
    be read or has nothing to show."""
    from ..assets import load_mesh

    if up not in UP_AXES:
        raise ArgumentError(f"up axis must be one of {', '.join(UP_AXES)}, got {up!r}")
    path = Path(model)
    data = load_mesh(path)  # reads and checks the file now: one-line SceneError
    vertices = np.asarray(data.vertices, np.float64)
    if len(data.faces) == 0 or len(vertices) == 0:
        raise SceneError("the model has no triangles to show", file=str(path))
    used = vertices[np.unique(np.asarray(data.faces).ravel())]
    finite = used[np.all(np.isfinite(used), axis=1)]
    if len(finite) == 0:
        raise SceneError("the model has no vertex with finite coordinates", file=str(path))
    transform = None if UP_AXES[up] is None else Transform(rotate=UP_AXES[up])
    if transform is not None:
        m = transform.matrix()
        finite = finite @ m[:3, :3].T
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    extent = float(np.max(hi - lo))
    if not math.isfinite(extent) or extent > 1e12:
        raise SceneError(f"the model is {extent:.3g} units across, beyond what whitted renders "
                         "(1e12)", file=str(path))
    centre = (lo + hi) / 2
    radius = float(np.max(np.linalg.norm(finite - centre, axis=1)))
    if radius <= 1e-12 * max(1.0, float(np.max(np.abs(centre)))):
        raise SceneError("the model has no extent (all its vertices at one point)",
                         file=str(path))
    mesh = Mesh.from_file(path, name=path.stem, transform=transform,
                          material=None if _has_own_materials(data) else CLAY,
                          solid=False)
    ground = Plane(name="ground", point=(0.0, float(lo[1]) - 1e-4 * radius, 0.0),
                   normal=(0.0, 1.0, 0.0), material=GROUND)
    scene = Scene(render=RenderSettings(width=width, height=height, samples=1),
                  background=SKY, objects=[mesh, ground],
                  lights=studio_lights(centre, radius, azimuth=azimuth))
    camera = camera_for(finite, scene.camera, width, height, azimuth, elevation,
                        all_around=all_around)
    scene.camera = camera
    return scene
