"""Real input for the editor's tests: mouse clicks, key presses and wheel turns delivered to
the widget under the pointer, as a person's hand would (pytest-qt's ``qtbot`` and Qt events
sent through the application), never the window's own methods."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest  # noqa: E402
from PySide6.QtCore import (  # noqa: E402
    QPoint,
    QPointF,
    QSettings,  # noqa: E402
    Qt,
)
from PySide6.QtGui import QMouseEvent, QWheelEvent  # noqa: E402
from PySide6.QtWidgets import QApplication, QLineEdit, QWidget  # noqa: E402

from whitted.gui.main_window import MainWindow, starter_scene  # noqa: E402

SLOW = 120_000  # ms: the first render in a fresh process compiles or loads the kernels


def small_scene(width: int = 64, height: int = 48):
    return starter_scene().with_settings(width=width, height=height)


@pytest.fixture
def make_window(qtbot, tmp_path):
    """A factory of editor windows with their own settings file and autosave folder; the
    close prompt answers "discard" and errors are collected in ``window.errors``."""

    def make(scene=None, path=None, **options) -> MainWindow:
        settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
        options.setdefault("autosave_folder", tmp_path / "autosave")
        window = MainWindow(scene if scene is not None or path is not None else small_scene(),
                            path, settings=settings, **options)
        window.ask_unsaved = lambda: "discard"
        window.properties.ask_keep_colour = lambda preset: "replace"
        window.show_error = lambda title, message: errors.append((title, message))
        window.errors = errors = []
        qtbot.addWidget(window)
        window.show()
        qtbot.waitExposed(window)
        window.activateWindow()
        qtbot.waitUntil(window.isActiveWindow, timeout=5000)  # the keys go to it
        return window

    return make

LEFT = Qt.MouseButton.LeftButton
NO_MOD = Qt.KeyboardModifier.NoModifier
CTRL = Qt.KeyboardModifier.ControlModifier
SHIFT = Qt.KeyboardModifier.ShiftModifier


def click_tree(qtbot, tree, key) -> None:
    """Click the scene tree's row of ``key``."""
    item = tree.item_for(key)
    assert item is not None, key
    tree.scrollToItem(item)
    rect = tree.visualItemRect(item)
    qtbot.mouseClick(tree.viewport(), LEFT, NO_MOD, rect.center())


def type_into(qtbot, line: QLineEdit, text: str, *, finish: bool = True) -> None:
    """Click into ``line``, select what it holds, type ``text`` and (``finish``) press Enter."""
    line.window().activateWindow()
    qtbot.mouseClick(line, LEFT, NO_MOD, line.rect().center())
    line.setFocus()
    qtbot.keyClick(line, Qt.Key.Key_A, CTRL)
    qtbot.keyClicks(line, text)
    if finish:
        qtbot.keyClick(line, Qt.Key.Key_Return)


def wheel(widget: QWidget, notches: float = -1.0, pos: QPoint | None = None,
          modifiers=NO_MOD) -> bool:
    """Turn the mouse wheel over ``widget`` at ``pos`` (its centre). Qt gives a real wheel
    turn to the widget under the pointer and, while nobody accepts it, to its parents (for
    spontaneous events only, which a test cannot make): this does the same walk. Returns
    whether someone accepted it."""
    pos = widget.rect().center() if pos is None else pos
    glob = QPointF(widget.mapToGlobal(pos))
    w = widget
    while w is not None:
        local = QPointF(w.mapFromGlobal(glob.toPoint()))
        event = QWheelEvent(local, glob, QPoint(0, 0), QPoint(0, round(120 * notches)),
                            Qt.MouseButton.NoButton, modifiers, Qt.ScrollPhase.NoScrollPhase,
                            False)
        event.setAccepted(True)
        handled = QApplication.sendEvent(w, event)
        if handled and event.isAccepted():
            return True
        if w.isWindow():
            return False
        w = w.parentWidget()
    return False


def mouse(widget: QWidget, kind: str, pos, button=LEFT, modifiers=NO_MOD) -> None:
    """One mouse event (``press``, ``move`` or ``release``) at ``pos`` in ``widget``, through
    the application (a drag needs the button held during the moves, which qtbot lacks)."""
    types = {"press": QMouseEvent.Type.MouseButtonPress, "move": QMouseEvent.Type.MouseMove,
             "release": QMouseEvent.Type.MouseButtonRelease}
    pos = QPointF(pos)
    buttons = button if kind != "release" else Qt.MouseButton.NoButton
    event = QMouseEvent(types[kind], pos, QPointF(widget.mapToGlobal(pos)),
                        button if kind != "move" else Qt.MouseButton.NoButton, buttons, modifiers)
    QApplication.sendEvent(widget, event)


def drag(widget: QWidget, start, steps, button=LEFT, modifiers=NO_MOD) -> None:
    """Press at ``start``, move through ``steps`` (points), release at the last one."""
    mouse(widget, "press", start, button, modifiers)
    last = start
    for p in steps:
        mouse(widget, "move", p, button, modifiers)
        last = p
    mouse(widget, "release", last, button, modifiers)
