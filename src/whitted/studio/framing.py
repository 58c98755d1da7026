"""A camera that frames a scene's objects: the three-quarter view from above that a
photographer would start from, every point of the objects inside the picture with a margin,
and a turntable film around them."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from ..errors import ArgumentError
from ..scene import Camera, Scene
from .bounds import world_points

#: the view: degrees around the up axis from the front (+z) towards +x, and above the horizon
AZIMUTH = 35.0
ELEVATION = 25.0
#: the fraction of the picture's half width and half height left free on each side
MARGIN = 0.1


def _targets(scene: Scene, target) -> list:
    if target is None:
        return list(scene.objects)
    items = [target] if isinstance(target, str | int) or hasattr(target, "type") else target
    if not isinstance(items, Iterable):
        raise ArgumentError(f"framed: target must be an object, its name or index, or a list of "
                            f"them, got {type(target).__name__}")
    chosen = []
    for item in items:
        if isinstance(item, bool):
            raise ArgumentError("framed: target must name objects, got a bool")
        if isinstance(item, int):
            if not -len(scene.objects) <= item < len(scene.objects):
                raise ArgumentError(f"framed: no object {item} (the scene has "
                                    f"{len(scene.objects)})")
            chosen.append(scene.objects[item])
        elif isinstance(item, str):
            found = [o for o in scene.objects if o.name == item]
            if not found:
                raise ArgumentError(f"framed: no object named {item!r}")
            chosen.extend(found)
        elif hasattr(item, "type"):
            chosen.append(item)
        else:
            raise ArgumentError(f"framed: target must name objects, got "
                                f"{type(item).__name__}")
    return chosen


def framing_points(scene: Scene, target=None) -> np.ndarray:
    """World-space points spanning the objects to frame (planes, which are unbounded, and
    unreadable models left out). ArgumentError when nothing bounded is left."""
    parts = [p for o in _targets(scene, target) if (p := world_points(o, scene)) is not None]
    if not parts:
        raise ArgumentError("framed: the scene has no bounded object to frame (only planes, "
                            "or no objects)")
    return np.concatenate(parts)


def view_direction(azimuth: float, elevation: float, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """Unit vector from the objects towards the camera."""
    a, e = math.radians(azimuth), math.radians(elevation)
    local = np.array([math.sin(a) * math.cos(e), math.sin(e), math.cos(a) * math.cos(e)])
    return _up_frame(up) @ local


def _up_frame(up) -> np.ndarray:
    """Columns: the world directions of local x, y (up) and z (front)."""
    u = np.asarray(up, np.float64)
    u = u / np.linalg.norm(u)
    front = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([0.0, -1.0, 0.0])
    front = front - u * (front @ u)
    front /= np.linalg.norm(front)
    return np.column_stack([np.cross(u, front), u, front])


def camera_for(points: np.ndarray, camera: Camera, width: int, height: int,
               azimuth: float = AZIMUTH, elevation: float = ELEVATION,
               margin: float = MARGIN, up=(0.0, 1.0, 0.0), all_around: bool = False) -> Camera:
    """``camera`` (its lens kept) moved to look at ``points`` from (azimuth, elevation), as
    close as it can while every point lies inside the picture with ``margin`` free. With
    ``all_around`` (a turntable), it aims at the points' vertical axis and stays far enough
    for them to be inside from every azimuth at that elevation."""
    if not 0.0 <= margin < 0.9:
        raise ArgumentError(f"framed: margin must be 0..0.9 of the picture, got {margin!r}")
    if not (math.isfinite(azimuth) and math.isfinite(elevation)) or abs(elevation) >= 90:
        raise ArgumentError(f"framed: azimuth must be finite and elevation within -90..90 "
                            f"degrees, got {azimuth!r}, {elevation!r}")
    pts = np.asarray(points, np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = (lo + hi) / 2
    size = float(np.max(hi - lo))
    radius = max(float(np.max(np.linalg.norm(pts - centre, axis=1))), 1e-9 * max(1.0, size))
    back = view_direction(azimuth, elevation, up)  # from the objects towards the camera
    world_up = np.asarray(up, np.float64) / np.linalg.norm(up)
    right = np.cross(world_up, back)
    right /= np.linalg.norm(right)
    upward = np.cross(back, right)
    data = camera.model_dump()
    data.update(up=tuple(world_up), rotate=None, axis_angle=None, focal_point=None,
                focal_distance=None)
    if camera.projection == "orthographic":
        rel = pts - centre
        x, y = rel @ right, rel @ upward
        aim = centre + right * (x.max() + x.min()) / 2 + upward * (y.max() + y.min()) / 2
        half_w, half_h = (x.max() - x.min()) / 2, (y.max() - y.min()) / 2
        data["ortho_height"] = max(2 * max(half_h, half_w * height / width) / (1 - margin),
                                   1e-9 * radius)
        data.update(look_at=tuple(aim), position=tuple(aim + back * 4 * radius))
        return Camera.model_validate(data)
    tx, ty = Camera.model_validate(data).half_extents(width, height)
    # no nearer than a millionth of the coordinates' size (a lone point: the camera stays
    # far enough from it for the ray offsets)
    floor = 1e-6 * max(1.0, float(np.max(np.abs(pts))))
    if all_around:
        aim, distance = _around(pts, centre, world_up, azimuth, elevation, tx, ty, margin,
                                floor)
        data.update(look_at=tuple(aim), position=tuple(aim + back * distance))
        return Camera.model_validate(data)
    aim = centre
    for _ in range(6):  # aim at the middle of the picture the points make, then come near
        distance, u, v = _fit(pts - aim, right, upward, back, tx, ty, margin, floor)
        aim = aim + (right * (u.max() + u.min()) * tx + upward * (v.max() + v.min()) * ty) \
            * distance / 2
    distance, _, _ = _fit(pts - aim, right, upward, back, tx, ty, margin, floor)
    data.update(look_at=tuple(aim), position=tuple(aim + back * distance))
    return Camera.model_validate(data)


def _around(pts, centre, world_up, azimuth, elevation, tx, ty, margin, floor, steps=24):
    """The aim on the vertical axis through ``centre`` (moved up or down to the middle of
    the pictures) and the distance that keeps every point in frame from each of ``steps``
    azimuths."""
    views = []
    for k in range(steps):
        back = view_direction(azimuth + 360.0 * k / steps, elevation, world_up)
        right = np.cross(world_up, back)
        right /= np.linalg.norm(right)
        views.append((right, np.cross(back, right), back))
    aim = centre
    for _ in range(4):
        fits = [_fit(pts - aim, *view, tx, ty, margin, floor) for view in views]
        distance = max(f[0] for f in fits)
        middle = (max(float(f[2].max()) for f in fits) + min(float(f[2].min()) for f in fits)) / 2
        aim = aim + world_up * middle * ty * distance / math.cos(math.radians(elevation))
    distance = max(_fit(pts - aim, *view, tx, ty, margin, floor)[0] for view in views)
    return aim, distance


def _fit(rel, right, upward, back, tx, ty, margin, floor):
    """The nearest distance from the aim point at which every point is inside the picture
    with the margin, and the points' places in it (fractions of the half width, height)."""
    x, y, z = rel @ right, rel @ upward, rel @ back  # z: towards the camera
    # a point at depth d - z from the camera is inside when |x| <= tx (1 - margin) (d - z)
    need = np.maximum(np.abs(x) / (tx * (1 - margin)), np.abs(y) / (ty * (1 - margin))) + z
    radius = float(np.max(np.linalg.norm(rel, axis=1)))
    distance = max(float(np.max(need)), 1.05 * radius, floor)
    depth = distance - z
    return distance, x / depth / tx, y / depth / ty


def framed(scene: Scene, target=None, *, azimuth: float = AZIMUTH,
           elevation: float = ELEVATION, margin: float = MARGIN) -> Scene:
    """The scene with its camera moved to frame ``target`` (default: every bounded object;
    or an object, its name or index, or a list of them): a three-quarter view from above
    (``azimuth`` degrees around the up axis from the front, ``elevation`` above the
    horizon), as near as it can be with every point inside the picture and ``margin`` of the
    half width and half height free. The lens (field of view, projection) is kept; the
    scene's other values are unchanged. A scene built in Python: ``whitted.framed(scene)``."""
    if not isinstance(scene, Scene):
        raise ArgumentError(f"framed needs a whitted.Scene, got {type(scene).__name__}")
    points = framing_points(scene, target)
    camera = camera_for(points, scene.camera, scene.render.width, scene.render.height,
                        azimuth, elevation, margin, up=scene.camera.up)
    scene = scene.model_copy()
    scene.camera = camera  # validated against the scene
    return scene


def turntable(scene: Scene, frames: int, fps: float = 24.0) -> Scene:
    """The scene with an ``[animation]`` of ``frames`` frames whose camera goes once around
    its look-at point about the camera's up axis (every frame keyed, so the path is a true
    circle), at the camera's height; the last frame leads back to the first (cyclic)."""
    from ..scene.animation import MAX_FRAMES, Animation

    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_FRAMES:
        raise ArgumentError(f"turntable: the number of frames must be 1..{MAX_FRAMES}, got "
                            f"{frames!r}")
    cam = scene.camera
    if cam.look_at is None:
        raise ArgumentError("turntable: the camera needs a look_at point to turn around")
    centre = np.asarray(cam.look_at, np.float64)
    axis = np.asarray(cam.up, np.float64) / np.linalg.norm(cam.up)
    offset = np.asarray(cam.position, np.float64) - centre
    keys = []
    for k in range(frames):
        a = 2 * math.pi * k / frames
        # Rodrigues: the offset turned by a about the axis
        turned = (offset * math.cos(a) + np.cross(axis, offset) * math.sin(a)
                  + axis * (axis @ offset) * (1 - math.cos(a)))
        keys.append([k, [float(v) for v in centre + turned]])
    animation = Animation.model_validate({
        "frames": frames, "fps": fps, "cyclic": True,
        "tracks": [{"path": "camera.position", "interpolation": "linear", "keys": keys}],
    })
    scene = scene.model_copy()
    scene.animation = animation  # validated against the scene
    return scene
