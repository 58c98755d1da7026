"""What is drawn over the picture, inside it (never in the margin around it): the selected
objects' bounding boxes, the lights (a sun mark with the light's name), the scene camera's
target (a cross), the selection's outline from the object-id image, and which camera the
picture is seen through. Also finds the light mark under the pointer."""

from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QObject, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPen

from . import camera_ops
from .document import label_of
from .picking import outline_image, outline_mask, solo_child
from .transform_tool import item_bounds, light_position, object_bounds

LIGHT_PICK_PX = 12


class Overlays(QObject):
    def __init__(self, window) -> None:
        super().__init__(window)
        self.window_ = window
        self.doc = window.doc
        self._solo_cache: tuple | None = None

    def _camera(self):
        return self.window_.navigation.camera()

    def light_marks(self):
        """(key, picture point (u, v)) of every light with a place in the scene."""
        scene = self.doc.scene
        s = scene.render
        camera = self._camera()
        for i, light in enumerate(scene.lights):
            p = light_position(light)
            uv = camera_ops.project(camera, s.width, s.height, p) if p else None
            if uv is not None:
                yield ("lights", i), uv

    def light_at(self, u: float, v: float):
        """The light whose mark is within a few pixels of (u, v), if any."""
        viewport = self.window_.viewport
        here = viewport.to_widget(u, v)
        best, best_d = None, float(LIGHT_PICK_PX)
        for key, (lu, lv) in self.light_marks():
            p = viewport.to_widget(lu, lv)
            d = math.hypot(p.x() - here.x(), p.y() - here.y())
            if d <= best_d:
                best, best_d = key, d
        return best

    def draw(self, p: QPainter, to_widget) -> None:
        """Over the picture, clipped to it: the selected objects' boxes, the camera's
        target, the lights; and which camera the picture is seen through."""
        viewport = self.window_.viewport
        rect = viewport.picture_rect()
        p.save()
        p.setClipRect(rect)
        self._draw_scene_marks(p, to_widget)
        p.restore()
        label = self.window_.navigation.label()
        p.setPen(QColor(0, 0, 0))
        box = QRectF(rect).adjusted(8, 6, -8, -6)
        flags = Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignTop
        p.drawText(box.translated(1, 1), flags, label)
        p.setPen(QColor(235, 235, 235))
        p.drawText(box, flags, label)

    def _draw_scene_marks(self, p: QPainter, to_widget) -> None:
        scene = self.doc.scene
        s = scene.render
        cam = self._camera()
        selected = self.doc.selected_keys()
        pen = QPen(QColor(255, 150, 20, 170), 1, Qt.PenStyle.DashLine)
        for key in selected:
            if key[0] != "objects":
                continue
            try:  # a CSG child: its own box, in its parents' places
                bounds = object_bounds(scene, key[1]) if len(key) == 2 else item_bounds(
                    solo_child(scene, key).objects[key[1]], scene)
            except (IndexError, AttributeError, ValueError):
                bounds = None
            if bounds is None:
                continue
            lo, hi = bounds
            corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                       for z in (lo[2], hi[2])]
            uvs = [camera_ops.project(cam, s.width, s.height, c) for c in corners]
            p.setPen(pen)
            for a in range(8):
                for b in range(a + 1, 8):
                    if bin(a ^ b).count("1") == 1 and uvs[a] and uvs[b]:
                        p.drawLine(to_widget(*uvs[a]), to_widget(*uvs[b]))
        target = camera_ops.project(cam, s.width, s.height,
                                    camera_ops.target_of(scene.camera))
        if target is not None:
            c = to_widget(*target)
            p.setPen(QPen(QColor(255, 255, 255, 150), 1))
            p.drawLine(c + QPointF(-7, 0), c + QPointF(7, 0))
            p.drawLine(c + QPointF(0, -7), c + QPointF(0, 7))
        for key, uv in self.light_marks():
            c = to_widget(*uv)
            light = scene.lights[key[1]]
            colour = QColor(255, 150, 20) if key in selected else QColor(255, 230, 90)
            p.setPen(QPen(QColor(0, 0, 0, 160), 3))
            p.drawEllipse(c, 5, 5)
            p.setPen(QPen(colour, 1.5))
            p.setBrush(colour)
            p.drawEllipse(c, 4, 4)
            p.setBrush(Qt.BrushStyle.NoBrush)
            for k in range(8):
                a = k * math.pi / 4
                d = QPointF(math.cos(a), math.sin(a))
                p.drawLine(c + d * 6.5, c + d * 10)
            p.setPen(QColor(0, 0, 0))
            p.drawText(c + QPointF(13, 5), label_of(light))
            p.setPen(colour)
            p.drawText(c + QPointF(12, 4), label_of(light))

    def update_outline(self) -> None:
        """The selected objects' outline over the picture (from the current id image); a
        child of a CSG object is outlined itself (from the id image of a scene where it
        stands alone in its parent's place)."""
        window = self.window_
        keys = [k for k in self.doc.selected_keys() if k[0] == "objects"]
        shown = window.shown_scene()
        tops = [k[1] for k in keys if len(k) == 2]
        children = [k for k in keys if len(k) > 2]
        masks = []
        if tops:
            ids = window.ids.ids if window.ids.scene is shown else None
            if ids is None:
                window.ids.request(shown)
                return
            masks.append(outline_mask(ids, tops))
        if children:
            solo = self._solo(shown, children[0])
            ids = window.child_ids.ids if window.child_ids.scene is solo else None
            if ids is None:
                window.child_ids.request(solo)
                return
            masks.append(ids == children[0][1])
        outline = None
        if masks:
            mask = masks[0] if len(masks) == 1 or masks[0].shape != masks[1].shape else \
                masks[0] | masks[1]
            outline = outline_image(mask.astype(np.int32), 1, mask=mask)
        viewport = window.viewport
        if outline is not viewport.outline:
            viewport.outline = outline
            viewport.update()

    def _solo(self, shown, key):
        """The scene whose id image outlines CSG child ``key`` (kept while ``shown`` is)."""
        cached = self._solo_cache
        if cached is not None and cached[0] is shown and cached[1] == key:
            return cached[2]
        try:
            solo = solo_child(shown, key)
        except (IndexError, AttributeError, ValueError):
            solo = shown
        self._solo_cache = (shown, key, solo)
        return solo


__all__ = ["LIGHT_PICK_PX", "Overlays"]
