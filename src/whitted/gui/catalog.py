"""The ready-made objects and lights of the Add menus, placed where the camera looks."""

from __future__ import annotations

import typing
from collections.abc import Callable
from pathlib import Path

import numpy as np
from pydantic import BaseModel

from .. import scene as S
from ..scene import Scene
from ..scene.shapes import Shape
from .camera_ops import project, target_of


def shape_kinds() -> list[str]:
    """The ``type`` of every kind of object a scene accepts, in the scene format's order."""
    union = typing.get_args(Shape)[0]
    return [cls.model_fields["type"].default for cls in typing.get_args(union)]


#: menu texts where the kind's name is not the text
MENU_TEXT = {"csg": "CSG (box minus sphere)"}
#: kinds added otherwise than from the Add Object menu's list (a model: from its file)
ADDED_OTHERWISE = ("mesh",)
#: the Add Object menu, in order: kind -> menu text (every shape of the scene format)
OBJECT_KINDS = {kind: MENU_TEXT.get(kind, kind.capitalize()) for kind in shape_kinds()
                if kind not in ADDED_OTHERWISE}
LIGHT_KINDS = {
    "ambient": "Ambient light", "point": "Point light", "directional": "Directional light",
    "disk": "Disk light (soft shadows)",
}
HAS_MESH = hasattr(S, "Mesh")
#: a model larger or smaller than this (its longest side) is scaled to MODEL_SIZE
MODEL_LARGEST, MODEL_SMALLEST, MODEL_SIZE = 20.0, 0.05, 1.5
#: model formats the mesh loader reads (file dialog filter)
MODEL_SUFFIXES = ("obj", "ply", "stl", "off", "glb", "gltf")


def _v(a: np.ndarray) -> tuple[float, float, float]:
    return (round(float(a[0]), 4), round(float(a[1]), 4), round(float(a[2]), 4))


def ground_height(scene: Scene) -> float | None:
    """The height of the scene's floor: a plane facing up (None when there is none)."""
    for obj in scene.objects:
        if obj.type == "plane" and obj.transform is None:
            n = np.asarray(obj.normal, np.float64)
            if n[1] > 0.99 * np.linalg.norm(n):
                return float(obj.point[1])
    return None


def spot(scene: Scene) -> np.ndarray:
    """Where a new object goes: on the floor where the camera looks (the centre of the view
    meeting the floor, or under the point it looks at), else the point it looks at."""
    target = np.asarray(target_of(scene.camera), dtype=np.float64)
    floor = ground_height(scene)
    if floor is None:
        return target
    pos = np.asarray(scene.camera.position, np.float64)
    d = target - pos
    if d[1] < -1e-6:
        t = (floor - pos[1]) / d[1]
        hit = pos + t * d
        if np.linalg.norm(hit - target) < 2 * np.linalg.norm(d):
            return np.array([hit[0], floor, hit[2]])
    return np.array([target[0], floor, target[2]])


def _overlaps(lo, hi, boxes) -> bool:
    return any(bool(np.all(lo < b_hi) and np.all(b_lo < hi)) for b_lo, b_hi in boxes)


def place_clear(scene: Scene, make: Callable[[np.ndarray], BaseModel]) -> BaseModel:
    """``make(point)`` built at the spot, resting on the floor, moved sideways (along the
    camera's right) until it intersects no other object's bounds."""
    from .transform_tool import item_bounds

    base = spot(scene)
    floor = ground_height(scene)
    boxes = [b for o in scene.objects if (b := item_bounds(o, scene)) is not None]
    right = np.asarray(scene.camera.basis()[0], np.float64)
    right = np.array([right[0], 0.0, right[2]])
    right = right / np.linalg.norm(right) if np.linalg.norm(right) > 1e-9 else np.array(
        [1.0, 0, 0])
    obj = make(base)
    bounds = item_bounds(obj, scene)
    if bounds is None:
        return obj
    lift = np.array([0.0, (floor - bounds[0][1]) if floor is not None else 0.0, 0.0])
    size = float(np.max(bounds[1] - bounds[0])) + 0.1
    toward = np.cross(right, [0.0, 1.0, 0.0])  # toward the camera, along the floor
    clear_outside = None
    for row in range(4):  # further back, where a row in front is full
        for k in range(41):
            step = (k + 1) // 2 * (1 if k % 2 else -1) * size  # 0, +1, -1, +2, -2, ...
            candidate = make(base + lift + step * right - row * size * toward)
            lo, hi = item_bounds(candidate, scene)
            if _overlaps(lo + 1e-6, hi - 1e-6, boxes):
                continue
            if _in_view(scene, lo, hi):  # seen whole, not at the edge of the picture
                return candidate
            if clear_outside is None:
                clear_outside = candidate
    return clear_outside if clear_outside is not None else make(base + lift)


#: a new object's whole box is seen within this margin of the picture's edges
VIEW_MARGIN = 0.08


def _in_view(scene: Scene, lo, hi) -> bool:
    """Whether the box lo..hi is seen whole, clear of the picture's edges."""
    s = scene.render
    for corner in ((x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                   for z in (lo[2], hi[2])):
        uv = project(scene.camera, s.width, s.height, corner)
        if uv is None or not all(VIEW_MARGIN <= c <= 1 - VIEW_MARGIN for c in uv):
            return False
    return True


def backdrop_plane(scene: Scene) -> BaseModel:
    """A new plane in a scene that has a floor: a wall behind everything the camera sees,
    facing it (a second floor would coincide with the first and never be seen)."""
    from .transform_tool import item_bounds

    pos = np.asarray(scene.camera.position, np.float64)
    forward = np.asarray(scene.camera.basis()[2], np.float64)
    forward = np.array([forward[0], 0.0, forward[2]])
    n = float(np.linalg.norm(forward))
    forward = forward / n if n > 1e-9 else np.array([0.0, 0.0, -1.0])
    depths = [float((np.asarray(c) - pos) @ forward)
              for o in scene.objects if (b := item_bounds(o, scene)) is not None
              for c in ((x, y, z) for x in (b[0][0], b[1][0]) for y in (b[0][1], b[1][1])
                        for z in (b[0][2], b[1][2]))]
    depth = max([float((spot(scene) - pos) @ forward), *depths]) + 1.0
    point = pos + depth * forward
    point[1] = ground_height(scene) or 0.0
    return S.Plane(point=_v(point), normal=_v(-forward), material="matte")


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
        # a ring lying on the floor: centred by its transform (a torus is about its origin)
        "torus": lambda: S.Torus(major_radius=0.5, minor_radius=0.15,
                                 transform=S.Transform(translate=_v(t))),
        "csg": lambda: S.CSG(operation="difference", material="plastic", objects=[
            S.Box(min=(-0.5, -0.5, -0.5), max=(0.5, 0.5, 0.5)),
            S.Sphere(center=(0.5, 0.5, 0.5), radius=0.55)],
            transform=S.Transform(translate=_v(t))),
    }


def new_object(scene: Scene, kind: str) -> BaseModel:
    """A new object of ``kind``: on the floor in front of the camera, clear of the others
    (a plane is the floor y = 0, or, when there is a floor, a wall behind the scene)."""
    if kind == "plane":
        obj = backdrop_plane(scene) if ground_height(scene) is not None else \
            _objects(spot(scene))[kind]()
    else:
        obj = place_clear(scene, lambda t: _objects(t)[kind]())
    return obj.model_copy(update={"name": unique_name(scene, kind)})


def light_name(scene: Scene, kind: str) -> str:
    """Lights are named by their type and number: "point 2" is the second point light."""
    n = sum(1 for li in scene.lights if li.type == kind) + 1
    names = {getattr(li, "name", None) for li in scene.lights}
    while f"{kind} {n}" in names:
        n += 1
    return f"{kind} {n}"


def new_light(scene: Scene, kind: str) -> BaseModel:
    t = np.asarray(target_of(scene.camera), dtype=np.float64)
    name = light_name(scene, kind)
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
    mesh = S.Mesh(file=name, name=unique_name(scene, path.stem))
    from .transform_tool import item_bounds

    bounds = item_bounds(mesh.model_copy(update={"file": str(path)}), scene)
    scale = 1.0
    if bounds is not None:
        extent = float(np.max(bounds[1] - bounds[0]))
        if extent > MODEL_LARGEST or extent < MODEL_SMALLEST:  # a sensible size: 1.5 units
            scale = float(f"{MODEL_SIZE / extent:.3g}")
    centre = (bounds[0] + bounds[1]) / 2 * scale if bounds is not None else np.zeros(3)
    bottom = bounds[0][1] * scale if bounds is not None else 0.0

    def make(t: np.ndarray) -> BaseModel:
        shift = np.array([t[0] - centre[0], t[1] - bottom, t[2] - centre[2]])
        return mesh.model_copy(update={"transform": S.Transform(
            scale=scale, translate=_v(shift))})

    obj = place_clear(scene, lambda t: make(t).model_copy(update={"file": str(path)}))
    return obj.model_copy(update={"file": name})
