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
