"""Blender's G / R / S in the picture: move, rotate or scale the selected object with the mouse,
an optional X / Y / Z axis constraint and a typed value; a click or Enter confirms, Esc or a
right-click cancels. G moves on the ground plane (the horizontal plane through the object)
unless an axis is chosen. Edits go through the object's ``transform`` (about its centre), so
every kind of object moves the same way; the whole move is one undo step.

Also the geometry the viewport needs: an object's centre and bounds."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QKeyEvent

from ..scene import Scene, Transform
from ..studio.bounds import item_bounds
from . import camera_ops

AXES = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}
DEG_PER_PX = 0.5
SCALE_PX = 200.0  # pixels of pointer travel for a factor e
_serials = itertools.count(1)


# ---------------------------------------------------------------------- geometry


def object_bounds(scene: Scene, index: int) -> tuple[np.ndarray, np.ndarray] | None:
    """World-space box (lo, hi) around object ``index``; None for an unbounded plane."""
    return item_bounds(scene.objects[index], scene)


def object_centre(scene: Scene, index: int) -> np.ndarray:
    b = object_bounds(scene, index)
    if b is not None:
        return (b[0] + b[1]) / 2
    obj = scene.objects[index]
    p = np.asarray(getattr(obj, "point", (0.0, 0.0, 0.0)), np.float64)
    return obj.transform.matrix()[:3, :3] @ p + obj.transform.matrix()[:3, 3] \
        if obj.transform is not None else p


def light_position(light) -> tuple[float, float, float] | None:
    """Where a light is drawn and moved from: a point light's position, a disk light's
    centre (None for ambient and directional lights)."""
    return getattr(light, "position", None) or getattr(light, "center", None)


def euler_xyz(r: np.ndarray) -> tuple[float, float, float]:
    """Degrees about x, then y, then z (R = Rz·Ry·Rx), as ``Transform.rotate`` takes them."""
    ry = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    if abs(r[2, 0]) < 1 - 1e-9:
        rx = math.atan2(r[2, 1], r[2, 2])
        rz = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: put it all in x
        rx = math.atan2(-r[1, 2], r[1, 1])
        rz = 0.0
    return tuple(round(math.degrees(a), 6) + 0.0 for a in (rx, ry, rz))


def _rot(axis: np.ndarray, deg: float) -> np.ndarray:
    from ..scene.types import _rotation

    return _rotation(axis, math.radians(deg))[:3, :3]


def moved(obj, delta) -> Transform:
    t = obj.transform or Transform()
    return t.model_copy(update={"translate": tuple(
        round(float(a + b), 6) + 0.0 for a, b in zip(t.translate, delta, strict=True))})


def rotated(obj, centre: np.ndarray, axis: np.ndarray, deg: float) -> Transform:
    """The transform turned by ``deg`` about ``axis`` through ``centre`` (world space)."""
    t = obj.transform or Transform()
    m = t.matrix()
    r = _rot(axis, deg)
    rot_old = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)  # the rotation, scale removed
    new_rot = r @ rot_old
    translate = centre + r @ (np.asarray(t.translate) - centre)
    return t.model_copy(update={"rotate": euler_xyz(new_rot), "translate": tuple(
        round(float(v), 6) + 0.0 for v in translate)})


def scaled(obj, centre: np.ndarray, factor: float, axis: str | None) -> Transform:
    """The transform scaled by ``factor`` about ``centre`` (along one of the object's own
    axes when ``axis`` is given)."""
    t = obj.transform or Transform()
    s = np.broadcast_to(np.asarray(t.scale, np.float64), (3,)).copy()
    f = np.ones(3)
    if axis is None:
        f[:] = factor
    else:
        f["xyz".index(axis)] = factor
    s *= f
    translate = centre + f * (np.asarray(t.translate) - centre) if axis is None else \
        centre + (np.asarray(t.translate) - centre)
    scale = float(s[0]) if s[0] == s[1] == s[2] else tuple(float(v) for v in s)
    return t.model_copy(update={"scale": scale, "translate": tuple(
        round(float(v), 6) + 0.0 for v in translate)})


# ---------------------------------------------------------------------- the modal tool


class TransformTool:
    """One G/R/S operation on object ``index``. ``apply(transform, merge_key)`` writes the
    object's new transform; ``finish(confirmed)`` ends it; ``status(text)`` tells the user."""

    NAMES = {"move": "Move", "rotate": "Rotate", "scale": "Scale"}

    def __init__(self, mode: str, scene: Scene, index: int, start: QPointF,
                 picture_size: tuple[float, float], apply: Callable, finish: Callable,
                 status: Callable[[str], None], kind: str = "objects",
                 path: tuple[int, ...] = ()) -> None:
        self.mode = mode
        self.scene = scene
        self.index = index
        self.kind = kind  # "objects", or "lights" (G only: ``apply`` gets the move's vector)
        #: a child of CSG object ``index`` (its place among the children, to any depth): its
        #: transform is in its parent's space, so the move's vector, the centre and the axes
        #: are taken there (the parent's space: ``parent``, its object-to-world matrix)
        self.path = tuple(path)
        self.obj = getattr(scene, kind)[index]
        self.parent = np.eye(4)
        for k in self.path:
            if self.obj.transform is not None:
                self.parent = self.parent @ self.obj.transform.matrix()
            self.obj = self.obj.objects[k]
        if kind != "objects":
            self.centre = np.asarray(light_position(self.obj), np.float64)
        elif self.path:
            b = item_bounds(self.obj, scene)
            local = (b[0] + b[1]) / 2 if b is not None else np.zeros(3)
            self.centre = self.parent[:3, :3] @ local + self.parent[:3, 3]
        else:
            self.centre = object_centre(scene, index)
        #: the centre in the space the object's transform is in
        self.own_centre = np.linalg.solve(self.parent[:3, :3], self.centre - self.parent[:3, 3])
        self.start = start
        self.pointer = start
        self.start_uv: tuple[float, float] | None = None
        self.uv: tuple[float, float] | None = None
        self.picture_size = picture_size
        self.axis: str | None = None
        self.typed = ""
        self.done = False
        self.merge_key = ("transform tool", next(_serials))
        self._apply, self._finish, self._status = apply, finish, status
        self.show_status()

    # -------------------------------------------------------------- input

    def move(self, pos: QPointF, uv) -> None:
        if self.start_uv is None and uv is not None:
            self.start_uv = uv
        self.pointer, self.uv = pos, uv
        if not self.typed:
            self.update()

    def key(self, event: QKeyEvent) -> bool:
        k = event.key()
        text = event.text()
        if k in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.confirm()
        elif k in (Qt.Key.Key_X, Qt.Key.Key_Y, Qt.Key.Key_Z):
            axis = "xyz"[k - Qt.Key.Key_X]
            self.axis = None if self.axis == axis else axis
            self.update()
        elif k == Qt.Key.Key_Backspace:
            self.typed = self.typed[:-1]
            self.update()
        elif text and (text.isdigit() or text in ".-"):
            self.typed += text
            self.update()
        else:
            return False
        return True

    # -------------------------------------------------------------- the edit

    def _typed_value(self) -> float | None:
        try:
            return float(self.typed) if self.typed not in ("", "-", ".", "-.") else None
        except ValueError:
            return None

    def _ground_delta(self) -> np.ndarray:
        """Where the pointer's ray meets the plane through the centre (horizontal, or for
        the Y axis vertical and facing the camera), minus where it met it at the start."""
        cam = self.scene.camera
        w, h = self.scene.render.width, self.scene.render.height
        if self.uv is None or self.start_uv is None:
            return np.zeros(3)
        if self.axis == "y":
            _, _, fwd = cam.basis()
            normal = np.array([fwd[0], 0.0, fwd[2]])
            if np.linalg.norm(normal) < 1e-6:
                normal = np.array([0.0, 0.0, 1.0])
        else:
            normal = AXES["y"]
        normal = normal / np.linalg.norm(normal)

        def hit(uv):
            o = camera_ops.ray_origin(cam, w, h, *uv)
            d = camera_ops.ray_direction(cam, w, h, *uv)
            den = float(d @ normal)
            if abs(den) < 1e-9:
                return None
            t = float((self.centre - o) @ normal) / den
            return o + t * d if t > 0 else None

        a, b = hit(self.start_uv), hit(self.uv)
        if a is None or b is None:
            return np.zeros(3)
        delta = b - a
        if self.axis is not None:
            delta = AXES[self.axis] * float(delta @ AXES[self.axis])
        return delta

    def transform(self) -> Transform:
        """The object's new transform (in its parent's space for a CSG child: a typed move
        and the axes are the parent's, a move by the pointer follows it on the ground)."""
        typed = self._typed_value()
        dx = self.pointer.x() - self.start.x()
        if self.mode == "move":
            if typed is not None:
                delta = AXES[self.axis or "x"] * typed
            else:
                delta = np.linalg.solve(self.parent[:3, :3], self._ground_delta())
            return moved(self.obj, delta)
        if self.mode == "rotate":
            deg = typed if typed is not None else dx * DEG_PER_PX
            return rotated(self.obj, self.own_centre, AXES[self.axis or "y"], deg)
        factor = typed if typed is not None else math.exp(dx / SCALE_PX)
        if factor == 0:
            factor = 1e-3
        return scaled(self.obj, self.own_centre, factor, self.axis)

    def delta(self) -> np.ndarray:
        typed = self._typed_value()
        return AXES[self.axis or "x"] * typed if typed is not None else self._ground_delta()

    def update(self) -> None:
        self.show_status()
        try:
            self._apply(self.transform() if self.kind == "objects" else self.delta(),
                        self.merge_key)
        except ValueError as exc:
            self._status(f"{self.NAMES[self.mode]}: {exc}")

    def show_status(self) -> None:
        along = "about" if self.mode == "rotate" else "along"
        axis = f" {along} {self.axis.upper()}" if self.axis else (
            " on the ground" if self.mode == "move" else " about Y" if self.mode == "rotate"
            else "")
        typed = f" {self.typed}" if self.typed else ""
        self._status(f"{self.NAMES[self.mode]}{axis}{typed}   — X/Y/Z: axis, type a value, "
                     "Enter or click: done, Esc or right-click: cancel")

    def confirm(self) -> None:
        if self.typed:
            self.update()
        self.done = True
        self._finish(True, self)

    def cancel(self) -> None:
        self.done = True
        self._finish(False, self)
