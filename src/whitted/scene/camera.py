"""The camera: where it is, where it looks, and how it projects."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from .types import AxisAngle, Direction, Strict, Vec3, _rotation


class Camera(Strict):
    """A pinhole (perspective) or orthographic camera.

    Orientation is either ``look_at`` + ``up``, or ``rotate`` (degrees about x, then y, then z,
    applied to a camera that looks down −z with +y up) optionally followed by ``axis_angle``.
    ``fov`` is the full field of view in degrees along ``fov_axis`` (``"y"``: vertical, the
    default; ``"x"``: horizontal). Orthographic cameras see ``ortho_height`` units vertically.
    """

    position: Vec3 = (0.0, 0.0, 5.0)
    look_at: Vec3 | None = None
    up: Direction = (0.0, 1.0, 0.0)
    rotate: Vec3 | None = None
    axis_angle: AxisAngle | None = None
    fov: float = Field(default=45.0, gt=0.0, lt=180.0)
    fov_axis: Literal["x", "y"] = "y"
    projection: Literal["perspective", "orthographic"] = "perspective"
    ortho_height: float = Field(default=2.0, gt=0.0)
    #: focal blur (POV-Ray's ``aperture`` and ``focal_point``): the diameter of the lens in
    #: scene units (0: a pinhole, everything sharp) and where it focuses: ``focal_distance``
    #: along the viewing direction, or the plane through ``focal_point`` facing the camera
    #: (neither: the look_at point, else 1 unit)
    aperture: float = Field(default=0.0, ge=0.0, le=1e6)
    focal_distance: float | None = Field(default=None, gt=0.0, le=1e12)
    focal_point: Vec3 | None = None

    @model_validator(mode="after")
    def _orientation(self) -> Camera:
        if self.look_at is not None and (self.rotate is not None or self.axis_angle is not None):
            raise ValueError("give either look_at or rotate/axis_angle, not both")
        if self.look_at is not None:
            forward = np.subtract(self.look_at, self.position)
            if np.linalg.norm(forward) < 1e-12:
                raise ValueError("look_at coincides with position")
            if np.linalg.norm(np.cross(forward, self.up)) < 1e-9 * np.linalg.norm(forward):
                raise ValueError("up is parallel to the viewing direction")
        if self.focal_distance is not None and self.focal_point is not None:
            raise ValueError("give either focal_distance or focal_point, not both")
        if self.focal_point is not None:
            forward = self.basis()[2]
            if not np.dot(np.subtract(self.focal_point, self.position), forward) > 0.0:
                raise ValueError("focal_point is not in front of the camera")
        return self

    def focus(self) -> float:
        """Distance along the viewing direction of the plane in focus."""
        _, _, forward = self.basis()
        if self.focal_distance is not None:
            return float(self.focal_distance)
        point = self.focal_point if self.focal_point is not None else self.look_at
        if point is None:
            return 1.0
        return float(np.dot(np.subtract(point, self.position), forward))

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit (right, up, forward) vectors of the camera in world space."""
        if self.look_at is not None:
            forward = np.subtract(self.look_at, self.position).astype(np.float64)
            forward /= np.linalg.norm(forward)
            right = np.cross(forward, self.up)
            right /= np.linalg.norm(right)
            up = np.cross(right, forward)
            return right, up, forward
        m = np.eye(4)
        if self.rotate is not None:
            for axis, angle in zip(np.eye(3), self.rotate, strict=True):
                m = _rotation(axis, math.radians(angle)) @ m
        if self.axis_angle is not None:
            m = _rotation(np.array(self.axis_angle.axis), math.radians(self.axis_angle.angle)) @ m
        r = m[:3, :3]
        return r @ np.array([1.0, 0, 0]), r @ np.array([0, 1.0, 0]), r @ np.array([0, 0, -1.0])

    def half_extents(self, width: int, height: int) -> tuple[float, float]:
        """Half width and half height of the image plane at distance 1 (or in world units for
        an orthographic camera)."""
        aspect = width / height
        if self.projection == "orthographic":
            hh = self.ortho_height / 2
            return hh * aspect, hh
        t = math.tan(math.radians(self.fov) / 2)
        if self.fov_axis == "x":
            return t, t / aspect
        return t * aspect, t
