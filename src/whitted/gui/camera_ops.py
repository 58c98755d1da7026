"""Camera moves for the editor, as pure functions Camera -> Camera (no Qt): orbit, pan, zoom
with the mouse, and a rotation by an angle about the X, Y or Z axis. Results use the
``look_at`` + ``up`` form, which shows the same view as the ``rotate`` form it may replace."""

from __future__ import annotations

import math

import numpy as np

from ..scene import Camera
from ..scene.types import _rotation

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
MIN_DISTANCE = 1e-3


def target_of(camera: Camera) -> np.ndarray:
    """The point the camera turns about: its ``look_at``, else the point of its view ray
    nearest the origin (or 5 units ahead when that is behind or too close)."""
    pos = np.asarray(camera.position, np.float64)
    if camera.look_at is not None:
        return np.asarray(camera.look_at, np.float64)
    _, _, forward = camera.basis()
    d = float(np.dot(-pos, forward))
    if not math.isfinite(d) or d < 0.5:
        d = 5.0
    return pos + d * forward


def _rounded(v: np.ndarray) -> tuple[float, float, float]:
    return tuple(float(round(x, 6)) + 0.0 for x in v)  # + 0.0: no -0.0 in files


def with_view(camera: Camera, position: np.ndarray, target: np.ndarray,
              up: np.ndarray) -> Camera:
    """The camera with a new eye, target and up (validated: raises ValueError if degenerate)."""
    data = camera.model_dump()
    data.update(position=_rounded(position), look_at=_rounded(target), up=_rounded(up),
                rotate=None, axis_angle=None)
    return Camera.model_validate(data)


def _frame(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    pos = np.asarray(camera.position, np.float64)
    target = target_of(camera)
    right, up, forward = camera.basis()
    return pos, target, np.asarray(right), np.asarray(up)


def orbit(camera: Camera, yaw_deg: float, pitch_deg: float) -> Camera:
    """Turn the eye about the target: ``yaw`` about the world's vertical (the camera's ``up``
    setting), ``pitch`` about the camera's right axis; the view never flips over the pole."""
    pos, target, right, _ = _frame(camera)
    world_up = np.asarray(camera.up, np.float64)
    world_up /= np.linalg.norm(world_up)
    offset = pos - target
    dist = np.linalg.norm(offset)
    if dist < MIN_DISTANCE:
        return camera
    # limit the pitch so the view stays away from straight up/down
    elevation = math.degrees(math.asin(np.clip(np.dot(offset / dist, world_up), -1, 1)))
    pitch_deg = float(np.clip(pitch_deg, -85 - elevation, 85 - elevation))
    r = _rotation(world_up, math.radians(-yaw_deg))[:3, :3]
    offset, right = r @ offset, r @ right
    r = _rotation(right, math.radians(-pitch_deg))[:3, :3]
    offset = r @ offset
    return with_view(camera, target + offset, target, world_up)


def pan(camera: Camera, dx: float, dy: float) -> Camera:
    """Slide eye and target sideways: ``dx``, ``dy`` in fractions of the view's height (so
    the scene follows the mouse at the target's distance)."""
    pos, target, right, up = _frame(camera)
    if camera.projection == "orthographic":
        extent = camera.ortho_height
    else:
        extent = 2.0 * np.linalg.norm(target - pos) * math.tan(math.radians(camera.fov) / 2)
    shift = (-dx * right + dy * up) * extent
    return with_view(camera, pos + shift, target + shift, np.asarray(camera.up))


def zoom(camera: Camera, factor: float) -> Camera:
    """Move the eye toward (factor < 1) or away from (> 1) the target; orthographic cameras
    change their visible height instead."""
    pos, target, _, _ = _frame(camera)
    if camera.projection == "orthographic":
        data = camera.model_dump()
        data["ortho_height"] = max(camera.ortho_height * factor, 1e-6)
        return Camera.model_validate(data)
    offset = (pos - target) * factor
    if np.linalg.norm(offset) < MIN_DISTANCE:
        return camera
    return with_view(camera, target + offset, target, np.asarray(camera.up))


def rotate_about_axis(camera: Camera, axis: str, angle_deg: float, *,
                      pivot: str = "camera") -> Camera:
    """Rotate the camera by ``angle_deg`` about the world axis ``axis`` (X, Y or Z) through
    the camera itself (it turns its head) or through its target (``pivot="target"``: it
    circles the target)."""
    pos, target, _, up = _frame(camera)
    r = _rotation(np.asarray(AXES[axis.upper()]), math.radians(angle_deg))[:3, :3]
    if pivot == "target":
        pos = target + r @ (pos - target)
    else:
        target = pos + r @ (target - pos)
    return with_view(camera, pos, target, r @ up)


def move_to(camera: Camera, position: tuple[float, float, float]) -> Camera:
    """The camera at ``position``, still looking at its target."""
    target = target_of(camera)
    return with_view(camera, np.asarray(position, np.float64), target, np.asarray(camera.up))


def ray_direction(camera: Camera, width: int, height: int, u: float, v: float) -> np.ndarray:
    """The unit direction of the view ray through the picture point (u, v) (0..1 from the
    top-left corner) of a ``width`` x ``height`` render (perspective cameras; orthographic
    ones look straight ahead)."""
    right, up, forward = (np.asarray(a, np.float64) for a in camera.basis())
    if camera.projection == "orthographic":
        return forward
    hx, hy = camera.half_extents(width, height)
    d = forward + (2 * u - 1) * hx * right + (1 - 2 * v) * hy * up
    return d / np.linalg.norm(d)


def ray_origin(camera: Camera, width: int, height: int, u: float, v: float) -> np.ndarray:
    pos = np.asarray(camera.position, np.float64)
    if camera.projection != "orthographic":
        return pos
    right, up, _ = (np.asarray(a, np.float64) for a in camera.basis())
    hx, hy = camera.half_extents(width, height)
    return pos + (2 * u - 1) * hx * right + (1 - 2 * v) * hy * up


def project(camera: Camera, width: int, height: int,
            point) -> tuple[float, float] | None:
    """The picture point (u, v) where ``point`` appears; None behind the camera."""
    right, up, forward = (np.asarray(a, np.float64) for a in camera.basis())
    d = np.asarray(point, np.float64) - np.asarray(camera.position, np.float64)
    z = float(d @ forward)
    hx, hy = camera.half_extents(width, height)
    if camera.projection == "orthographic":
        x, y = float(d @ right) / hx, float(d @ up) / hy
    else:
        if z <= 1e-6:
            return None
        x, y = float(d @ right) / (z * hx), float(d @ up) / (z * hy)
    return (x + 1) / 2, (1 - y) / 2


def zoom_to(camera: Camera, factor: float, width: int, height: int, u: float,
            v: float) -> Camera:
    """Zoom toward the picture point (u, v): the scene point under it, at the target's
    depth, stays under the pointer (eye and target move toward it by ``factor``)."""
    if camera.projection == "orthographic" or not (0 <= u <= 1 and 0 <= v <= 1):
        return zoom(camera, factor)
    pos, target, _, _ = _frame(camera)
    _, _, forward = camera.basis()
    depth = float((target - pos) @ np.asarray(forward))
    d = ray_direction(camera, width, height, u, v)
    p = pos + d * depth / max(float(d @ np.asarray(forward)), 1e-6)
    new_pos = p + (pos - p) * factor
    if np.linalg.norm(new_pos - (p + (target - p) * factor)) < MIN_DISTANCE:
        return camera
    return with_view(camera, new_pos, p + (target - p) * factor, np.asarray(camera.up))


def look_from(camera: Camera, direction, target, distance: float) -> Camera:
    """The camera looking at ``target`` from ``distance`` along ``direction`` (a view from
    the front, the side, the top...), with the world's up (+y) as its up: a view from
    straight above is tilted by a hair toward the front so that up stays +y (and a later
    orbit still turns about the vertical)."""
    d = np.asarray(direction, np.float64)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0])
    if abs(float(d @ up)) > 0.9999:
        d = d + np.array([0.0, 0.0, 1e-3])
        d /= np.linalg.norm(d)
    target = np.asarray(target, np.float64)
    return with_view(camera, target + distance * d, target, up)


def frame_bounds(camera: Camera, width: int, height: int, lo, hi,
                 margin: float = 1.15) -> Camera:
    """The camera moved along its view direction so that the box lo..hi fills the view."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3) * margin
    pos, target, _, _ = _frame(camera)
    view = pos - target
    n = float(np.linalg.norm(view))
    direction = view / n if n > MIN_DISTANCE else np.array([0.0, 0.0, 1.0])
    if camera.projection == "orthographic":
        data = camera.model_dump()
        data["ortho_height"] = 2 * radius
        camera = Camera.model_validate(data)
        return with_view(camera, centre + direction * max(n, 4 * radius), centre,
                         np.asarray(camera.up))
    hx, hy = camera.half_extents(width, height)
    distance = radius / math.sin(math.atan(min(hx, hy)))
    return with_view(camera, centre + direction * distance, centre, np.asarray(camera.up))
