"""Small icons for the kinds of items (tree, Add menus, toolbar), drawn with QPainter so the
editor ships no image files, and colour swatches for the material presets."""

from __future__ import annotations

import math
from functools import cache

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import (
    QBrush,
    QColor,
    QIcon,
    QPainter,
    QPainterPath,
    QPen,
    QPixmap,
    QPolygonF,
    QRadialGradient,
)

SIZE = 32
OBJECT = QColor(90, 150, 220)
LIGHT = QColor(245, 200, 60)
OTHER = QColor(150, 150, 160)


def _pixmap() -> tuple[QPixmap, QPainter]:
    pm = QPixmap(SIZE, SIZE)
    pm.fill(Qt.GlobalColor.transparent)
    p = QPainter(pm)
    p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
    p.setPen(QPen(QColor(40, 40, 50), 1.6))
    return pm, p


def _poly(*pts: tuple[float, float]) -> QPolygonF:
    return QPolygonF([QPointF(x, y) for x, y in pts])


def _sun(p: QPainter, c: QPointF, r: float, rays: bool = True) -> None:
    p.setBrush(LIGHT)
    p.drawEllipse(c, r, r)
    if rays:
        for k in range(8):
            a = k * math.pi / 4
            d = QPointF(math.cos(a), math.sin(a))
            p.drawLine(c + d * (r + 3), c + d * (r + 7))


@cache
def icon_for(kind: str) -> QIcon:
    """The icon of an object type ("sphere", "box", ...), a light ("light:point"...), or
    "camera", "render", "background"."""
    pm, p = _pixmap()
    c = QPointF(SIZE / 2, SIZE / 2)
    if kind == "sphere":
        g = QRadialGradient(QPointF(12, 11), 16)
        g.setColorAt(0, QColor(200, 225, 255))
        g.setColorAt(1, OBJECT)
        p.setBrush(QBrush(g))
        p.drawEllipse(c, 12, 12)
    elif kind == "box":
        p.setBrush(OBJECT)
        p.drawPolygon(_poly((6, 11), (20, 11), (20, 26), (6, 26)))
        p.setBrush(OBJECT.lighter(130))
        p.drawPolygon(_poly((6, 11), (12, 5), (26, 5), (20, 11)))
        p.setBrush(OBJECT.darker(120))
        p.drawPolygon(_poly((20, 11), (26, 5), (26, 20), (20, 26)))
    elif kind in ("plane", "rectangle"):
        p.setBrush(OBJECT if kind == "rectangle" else OBJECT.lighter(120))
        p.drawPolygon(_poly((3, 24), (11, 10), (29, 10), (21, 24)) if kind == "plane"
                      else _poly((7, 6), (25, 6), (25, 26), (7, 26)))
    elif kind == "disk":
        p.setBrush(OBJECT)
        p.drawEllipse(c, 13, 7)
    elif kind == "triangle":
        p.setBrush(OBJECT)
        p.drawPolygon(_poly((16, 4), (28, 27), (4, 27)))
    elif kind in ("cylinder", "cone"):
        p.setBrush(OBJECT)
        if kind == "cylinder":
            p.drawRect(QRectF(7, 7, 18, 18))
            p.drawEllipse(QPointF(16, 25), 9, 3.5)
            p.setBrush(OBJECT.lighter(130))
            p.drawEllipse(QPointF(16, 7), 9, 3.5)
        else:
            p.drawPolygon(_poly((16, 3), (26, 25), (6, 25)))
            p.drawEllipse(QPointF(16, 25), 10, 3.5)
    elif kind == "torus":  # a ring seen from above and a little aside: a hole in the middle
        path = QPainterPath()
        path.setFillRule(Qt.FillRule.OddEvenFill)
        path.addEllipse(c, 13, 8)
        path.addEllipse(c, 6, 3)
        p.setBrush(OBJECT)
        p.drawPath(path)
    elif kind == "csg":  # a box with a ball cut out of its corner
        path = QPainterPath()
        path.addRect(QRectF(5, 9, 18, 18))
        hole = QPainterPath()
        hole.addEllipse(QPointF(23, 9), 9, 9)
        p.setBrush(OBJECT)
        p.drawPath(path.subtracted(hole))
    elif kind == "mesh":
        p.setBrush(OBJECT)
        p.drawPolygon(_poly((4, 24), (12, 6), (20, 20)))
        p.setBrush(OBJECT.lighter(125))
        p.drawPolygon(_poly((12, 6), (28, 10), (20, 20)))
        p.setBrush(OBJECT.darker(115))
        p.drawPolygon(_poly((4, 24), (20, 20), (26, 28)))
    elif kind == "light:point":
        _sun(p, c, 6)
    elif kind == "light:ambient":
        p.setBrush(LIGHT.lighter(120))
        p.setPen(QPen(QColor(40, 40, 50), 1.2, Qt.PenStyle.DashLine))
        p.drawEllipse(c, 12, 12)
        p.setPen(QPen(QColor(40, 40, 50), 1.6))
        p.setBrush(LIGHT)
        p.drawEllipse(c, 5, 5)
    elif kind == "light:directional":
        p.setBrush(LIGHT)
        for x in (8, 16, 24):
            p.drawLine(QPointF(x + 4, 4), QPointF(x - 4, 24))
            p.drawPolygon(_poly((x - 4, 28), (x - 7, 21), (x - 1, 23)))
    elif kind == "light:disk":
        p.setBrush(LIGHT)
        p.drawEllipse(QPointF(16, 10), 11, 4)
        for x in (8, 16, 24):
            p.drawLine(QPointF(x, 16), QPointF(x, 27))
    elif kind == "camera":
        p.setBrush(OTHER)
        p.drawRoundedRect(QRectF(3, 9, 19, 15), 2, 2)
        p.drawPolygon(_poly((22, 14), (29, 9), (29, 24), (22, 19)))
    elif kind == "render":
        p.setBrush(OTHER)
        p.drawRect(QRectF(4, 6, 24, 20))
        p.setBrush(QColor(230, 230, 235))
        for i in range(3):
            for j in range(2):
                if (i + j) % 2:
                    p.drawRect(QRectF(4 + 8 * i, 6 + 10 * j, 8, 10))
    elif kind == "background":
        g = QRadialGradient(QPointF(16, 0), 30)
        g.setColorAt(0, QColor(120, 160, 230))
        g.setColorAt(1, QColor(220, 225, 240))
        p.setBrush(QBrush(g))
        p.drawRect(QRectF(4, 6, 24, 20))
    else:
        p.setBrush(OTHER)
        p.drawEllipse(c, 6, 6)
    p.end()
    return QIcon(pm)


def swatch(colour: tuple[float, float, float], *, shiny: bool = False) -> QIcon:
    """A round swatch of a linear colour (``shiny``: a highlight, for reflective presets)."""
    from .widgets import hex_of

    pm, p = _pixmap()
    g = QRadialGradient(QPointF(12, 11), 16)
    base = QColor(hex_of(colour))
    g.setColorAt(0, base.lighter(170) if shiny else base.lighter(115))
    g.setColorAt(1, base)
    p.setBrush(QBrush(g))
    p.drawEllipse(QPointF(SIZE / 2, SIZE / 2), 12, 12)
    p.end()
    return QIcon(pm)
