"""The viewport's own view, as in Blender: orbiting, panning, zooming, framing and the numpad
views move the *view*, not the scene's camera, so looking around never changes the file or the
film. "Camera view" (numpad 0) looks through the scene's camera; "Set camera to view"
(Ctrl+Alt+numpad 0) is the one undoable edit that moves the camera to the view; with "Lock
camera to view" on, navigating in camera view moves the camera (each drag one undo step)."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal

from ..scene import Camera, Scene
from . import camera_ops
from .document import CAMERA, EditRefused
from .transform_tool import object_bounds, object_centre

#: the fields "Set camera to view" writes: where the camera is and where it looks (its
#: lens, its projection and its size stay the camera's own)
PLACEMENT = ("position", "look_at", "up", "rotate", "axis_angle")
VIEWS = {"front": (0.0, 0.0, 1.0), "right": (1.0, 0.0, 0.0), "top": (0.0, 1.0, 0.0)}
OPPOSITE = {"back": "front", "left": "right", "bottom": "top"}


class Navigation(QObject):
    """``changed`` fires when the picture's camera changed without a scene edit (the view
    moved, camera view toggled): the window previews again."""

    changed = Signal()

    def __init__(self, window) -> None:
        super().__init__(window)
        self.window_ = window
        self.doc = window.doc
        self.view: Camera = self.doc.scene.camera
        self.camera_view = True  # a scene opens looking through its camera
        self.locked = False
        self._zoom_serial = 0
        self._zoom_timer = QTimer(self)
        self._zoom_timer.setSingleShot(True)
        self._zoom_timer.setInterval(600)  # wheel notches in a row zoom as one step
        self._zoom_timer.timeout.connect(self._end_zoom)

    # ------------------------------------------------------------------ what is shown

    def reset(self) -> None:
        """A new scene: look through its camera, the view starting there."""
        self.view = self.doc.scene.camera
        self.camera_view = True
        self._sync()

    def camera(self) -> Camera:
        """The camera the picture is seen through."""
        if self.camera_view:
            return self.window_.timeline.still(self.doc.scene).camera
        return self.view

    def shown(self, still: Scene) -> Scene:
        """``still`` as the picture shows it: through the view unless in camera view."""
        if self.camera_view or still.camera == self.view:
            return still
        return still.model_copy(update={"camera": self.view})

    def label(self) -> str:
        camera = self.camera()
        kind = "Orthographic" if camera.projection == "orthographic" else "Perspective"
        if self.camera_view:
            return f"Camera {kind}" + ("  (locked to view)" if self.locked else "")
        return f"User {kind}"

    def _sync(self) -> None:
        acts = getattr(self.window_, "acts", None)
        if acts is not None:
            acts["camera_view"].setCheckable(True)
            acts["camera_view"].setChecked(self.camera_view)
        self.changed.emit()

    # ------------------------------------------------------------------ the actions

    def toggle_camera_view(self) -> bool:
        if self.camera_view:
            self.camera_view = False
            if self.view == self.doc.scene.camera:
                self.view = self.camera()  # (the posed camera of an animated scene)
        else:
            self.camera_view = True
        self._sync()
        return True

    def set_camera_to_view(self) -> bool:
        """Move the scene's camera to the view: one undo step; then look through it."""
        if self.camera_view:
            self._status("Set camera to view: move the view first (the picture is the "
                         "camera's view already)")
            return False
        data = self.doc.scene.camera.model_dump()
        view = self.view.model_dump()
        data.update({name: view[name] for name in PLACEMENT})
        try:
            self.doc.edit_item(CAMERA, data, "Set camera to view", select=False)
        except EditRefused as exc:
            self._status(str(exc))
            return False
        self.view = self.doc.scene.camera
        self.camera_view = True
        self._sync()
        return True

    def set_locked(self, on: bool) -> None:
        self.locked = bool(on)
        self._sync()

    def _status(self, text: str, ms: int = 4000) -> None:
        self.window_.statusBar().showMessage(text, ms)

    # ------------------------------------------------------------------ moving the view

    def _move(self, camera: Camera, text: str, merge) -> None:
        """The picture's camera becomes ``camera``: the scene's camera when locked to the
        view in camera view (an edit), else the view (no edit; camera view ends)."""
        if self.camera_view and self.locked:
            try:  # the selection stays (the camera's panel, if shown, follows)
                self.doc.edit_item(CAMERA, camera.model_dump(), text, merge_key=merge,
                                   select=False)
            except EditRefused as exc:
                self._status(str(exc))
            return
        self.view = camera
        self.camera_view = False
        self._sync()

    def orbit(self, yaw: float, pitch: float, drag: int) -> None:
        try:
            camera = camera_ops.orbit(self.camera(), yaw, pitch)
        except ValueError:
            return
        self._move(camera, "Orbit camera", ("orbit", drag))

    def pan(self, dx: float, dy: float, drag: int) -> None:
        try:
            camera = camera_ops.pan(self.camera(), dx, dy)
        except ValueError:
            return
        self._move(camera, "Pan camera", ("pan", drag))

    def zoom(self, factor: float, u: float = -1.0, v: float = -1.0) -> None:
        s = self.doc.scene.render
        try:
            camera = camera_ops.zoom_to(self.camera(), factor, s.width, s.height, u, v)
        except ValueError:
            return
        self._zoom_timer.start()
        self._move(camera, "Zoom camera", ("zoom", self._zoom_serial))

    def _end_zoom(self) -> None:
        self._zoom_serial += 1

    def view_from(self, name: str) -> bool:
        """The view from the front, the back, the right... at the same distance from the
        point it turns about."""
        sign = -1.0 if name in OPPOSITE else 1.0
        direction = np.asarray(VIEWS[OPPOSITE.get(name, name)]) * sign
        camera = self.camera()
        target = camera_ops.target_of(camera)
        distance = float(np.linalg.norm(np.subtract(camera.position, target)))
        try:
            camera = camera_ops.look_from(camera, direction, target, distance)
        except ValueError:
            return False
        self._move(camera, f"View from the {name}", None)
        return True

    def view_front(self) -> bool:
        return self.view_from("front")

    def view_back(self) -> bool:
        return self.view_from("back")

    def view_right(self) -> bool:
        return self.view_from("right")

    def view_left(self) -> bool:
        return self.view_from("left")

    def view_top(self) -> bool:
        return self.view_from("top")

    def view_bottom(self) -> bool:
        return self.view_from("bottom")

    def frame_selection(self) -> bool:
        """Show the selected objects whole (everything when no object is selected)."""
        scene = self.doc.scene
        keys = [k for k in self.doc.selected_keys() if k[0] == "objects"]
        if not keys:
            return self.frame_all()
        boxes = []
        for _, index in keys:
            bounds = object_bounds(scene, index)
            if bounds is None:
                c = object_centre(scene, index)
                bounds = (c - 1.0, c + 1.0)
            boxes.append(bounds)
        self._frame(boxes, "Frame selection")
        return True

    def frame_all(self) -> bool:
        scene = self.doc.scene
        boxes = [b for i in range(len(scene.objects))
                 if (b := object_bounds(scene, i)) is not None]
        if not boxes:
            return False
        self._frame(boxes, "Frame all")
        return True

    def _frame(self, boxes, text: str) -> None:
        lo = np.min([b[0] for b in boxes], axis=0)
        hi = np.max([b[1] for b in boxes], axis=0)
        s = self.doc.scene.render
        try:
            camera = camera_ops.frame_bounds(self.camera(), s.width, s.height, lo, hi)
        except ValueError:
            return
        self._move(camera, text, None)


__all__ = ["Navigation"]
