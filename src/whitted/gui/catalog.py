"""The ready-made objects and lights of the Add menus, placed where the camera looks."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from pydantic import BaseModel

from .. import scene as S
from ..scene import Scene
from .camera_ops import target_of

#: the Add Object menu, in order: kind -> menu text
OBJECT_KINDS = {
    "sphere": "Sphere", "box": "Box", "plane": "Plane", "rectangle": "Rectangle",
    "disk": "Disk", "triangle": "Triangle", "cylinder": "Cylinder", "cone": "Cone",
}
LIGHT_KINDS = {
    "ambient": "Ambient light", "point": "Point light", "directional": "Directional light",
    "disk": "Disk light (soft shadows)",
}
HAS_MESH = hasattr(S, "Mesh")
#: model formats the mesh loader reads (file dialog filter)
MODEL_SUFFIXES = ("obj", "ply", "stl", "off", "glb", "gltf")


def _v(a: np.ndarray) -> tuple[float, float, float]:
    return (round(float(a[0]), 4), round(float(a[1]), 4), round(float(a[2]), 4))


def spot(scene: Scene) -> np.ndarray:
    """Where a new object goes: the point the camera looks at, or 5 units ahead."""
    return np.asarray(target_of(scene.camera), dtype=np.float64)


def unique_name(scene: Scene, base: str) -> str:
    names = {getattr(i, "name", None) for i in [*scene.objects, *scene.lights]}
    n = 1
    while f"{base} {n}" in names:
        n += 1
    return f"{base} {n}"


def _objects(t: np.ndarray) -> dict[str, Callable[[], BaseModel]]:
    up = np.array([0.0, 1.0, 0.0])
    return {
        "sphere": lambda: S.Sphere(center=_v(t), radius=0.5, material="plastic"),
        "box": lambda: S.Box(min=_v(t - 0.5), max=_v(t + 0.5), material="matte"),
        "plane": lambda: S.Plane(point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0)),
        "rectangle": lambda: S.Rectangle(corner=_v(t - [0.5, 0.5, 0.0]), edge1=(1.0, 0.0, 0.0),
                                         edge2=(0.0, 1.0, 0.0)),
        "disk": lambda: S.Disk(center=_v(t), normal=(0.0, 0.0, 1.0), radius=0.5),
        "triangle": lambda: S.Triangle(vertices=(_v(t + [-0.5, -0.4, 0]), _v(t + [0.5, -0.4, 0]),
                                                 _v(t + [0.0, 0.5, 0]))),
        "cylinder": lambda: S.Cylinder(base=_v(t - 0.5 * up), top=_v(t + 0.5 * up), radius=0.4),
        "cone": lambda: S.Cone(base=_v(t - 0.5 * up), top=_v(t + 0.5 * up), radius=0.45),
    }


def new_object(scene: Scene, kind: str) -> BaseModel:
    obj = _objects(spot(scene))[kind]()
    return obj.model_copy(update={"name": unique_name(scene, kind)})


def new_light(scene: Scene, kind: str) -> BaseModel:
    t = spot(scene)
    name = unique_name(scene, f"{kind} light")
    if kind == "ambient":
        return S.AmbientLight(name=name, intensity=0.2)
    if kind == "point":
        return S.PointLight(name=name, position=_v(t + [2.0, 4.0, 3.0]), intensity=0.8)
    if kind == "directional":
        return S.DirectionalLight(name=name, direction=(-1.0, -2.0, -1.0), intensity=0.6)
    if kind == "disk":
        return S.DiskLight(name=name, center=_v(t + [0.0, 4.0, 1.0]), radius=0.5,
                           normal=(0.0, -1.0, 0.0), intensity=0.8)
    raise KeyError(kind)


def check_model_file(path: Path) -> None:
    """Raise ValueError with one line if the mesh loader cannot read ``path``."""
    try:
        from ..assets import load_mesh  # type: ignore[attr-defined]
    except ImportError:
        load_mesh = None
    try:
        if load_mesh is not None:
            data = load_mesh(path)
            if len(getattr(data, "faces", (0,))) == 0:
                raise ValueError("no triangles in the file")
        else:  # the loader is not there yet: at least check that trimesh reads it
            import trimesh

            loaded = trimesh.load(str(path), force="mesh")
            if len(getattr(loaded, "faces", ())) == 0:
                raise ValueError("no triangles in the file")
    except Exception as exc:  # noqa: BLE001 - any reader failure is one line for the user
        raise ValueError(f"{path.name}: cannot read the model ({exc})") from None


def new_model(scene: Scene, path: Path) -> BaseModel:
    """A mesh object for the model at ``path`` (relative to the scene's folder if inside it)."""
    check_model_file(path)
    path = path.resolve()
    try:
        name = str(path.relative_to(scene.base_dir.resolve()))
    except ValueError:
        name = str(path)
    t = spot(scene)
    return S.Mesh(file=name, name=unique_name(scene, path.stem),
                  transform=S.Transform(translate=_v(t)))
