"""The editor's actions as one table: each row is a menu entry, its shortcuts, what it does and
where it goes, so the menus, the shortcuts and Help > Controls are made from the same rows and
cannot disagree. Rows with no method are controls that are not menu entries (the mouse, the
keys of a running G/R/S move): Help > Controls lists them too.

Every shortcut is the window's: it works wherever the focus is. A text field being typed in
keeps its own keys (letters, digits, Delete, Home, arrows, its undo while a value is typed);
:class:`ShortcutGuard` hands every other menu shortcut (Ctrl+E, Ctrl+S...) on to the window.
A slider keeps its own keys (Home, End, the arrows)."""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QAction, QKeyEvent, QKeySequence
from PySide6.QtWidgets import (
    QAbstractSlider,
    QAbstractSpinBox,
    QComboBox,
    QLineEdit,
    QPlainTextEdit,
    QTextEdit,
    QWidget,
)


@dataclass(frozen=True)
class Row:
    """One action: ``name`` (the window's ``act_<name>``), menu ``text``, ``method`` (a dotted
    path from the window: "files.save"), ``keys`` (portable key texts), the ``menu`` it sits
    in and its ``group`` there (groups are separated), a ``tip``, ``checkable``."""

    name: str
    text: str
    method: str | None
    keys: tuple[str, ...] = ()
    menu: str = ""
    group: int = 0
    tip: str = ""
    checkable: bool = False


MENUS = ("File", "Edit", "Object", "View", "Render", "Animation", "Help")
MENU_TEXT = {"File": "&File", "Edit": "&Edit", "Object": "&Object", "View": "&View",
             "Render": "&Render", "Animation": "A&nimation", "Help": "&Help"}

TOOL_HINT = ("then X, Y or Z keeps to an axis, a typed number is the exact amount, Enter or a "
             "click confirms, Esc or a right-click cancels")

ROWS: tuple[Row, ...] = (
    # File
    Row("new", "&New", "files.new_scene", ("Ctrl+N",), "File", 0),
    Row("open", "&Open…", "files.open_dialog", ("Ctrl+O",), "File", 0),
    Row("save", "&Save", "files.save", ("Ctrl+S",), "File", 1),
    Row("save_as", "Save &As…", "files.save_as", ("Ctrl+Shift+S",), "File", 1),
    Row("save_image", "Save &Image…", "files.save_image", ("Ctrl+E",), "File", 2,
        "save the picture as PNG or EXR"),
    Row("quit", "&Quit", "close", ("Ctrl+Q",), "File", 3),
    # Edit (undo and redo come from the undo stack: their rows name the keys)
    Row("undo", "&Undo", None, ("Ctrl+Z",), "Edit", 0, "undo the last edit"),
    Row("redo", "&Redo", None, ("Ctrl+Shift+Z", "Ctrl+Y"), "Edit", 0, "redo the edit undone"),
    Row("duplicate", "D&uplicate", "editing.duplicate_and_grab", ("Shift+D", "Ctrl+D"),
        "Edit", 1, "duplicate the selected lights and objects (named X.001) and move the "
        "copies with the mouse, as G does; Esc keeps them where the originals are"),
    Row("select_all", "Select &all", "editing.select_all", ("A",), "Edit", 1,
        "select every light and object"),
    Row("add_menu", "&Add…", "show_add_menu", ("Shift+A",), "Edit", 1,
        "the Add menu (objects and lights) at the pointer"),
    Row("rename", "Re&name", "editing.rename_selected", ("F2",), "Edit", 1,
        "rename the selection in the scene tree (also a double-click there)"),
    Row("delete", "&Delete", "editing.delete_selected", ("Del", "X"), "Edit", 1,
        "delete the selected lights and objects"),
    Row("escape", "Cancel, stop or &deselect", "escape", ("Esc",), "Edit", 2,
        "Esc: cancels a G/R/S move, else stops a running render, else deselects"),
    # Object: the selection's placement
    Row("move", "&Move", "editing.move", ("G",), "Object", 0,
        "G: move the selection on the ground; " + TOOL_HINT),
    Row("rotate", "&Rotate", "editing.rotate", ("R",), "Object", 0,
        "R: rotate the selection about Y; " + TOOL_HINT),
    Row("scale", "&Scale", "editing.scale", ("S",), "Object", 0,
        "S: scale the selection; " + TOOL_HINT),
    Row("insert_key", "&Insert key", "timeline.insert_key", ("I",), "Animation", 0,
        "key the selected item's placement (or the camera) at this frame"),
    Row("delete_key", "&Delete key", "timeline.delete_key", ("Alt+I",), "Animation", 0,
        "remove the selection's keys at this frame"),
    # View: the viewport's own view, and the picture
    Row("camera_view", "&Camera view", "navigation.toggle_camera_view", ("Num+0", "0"),
        "View", 0, "look through the scene's camera (again: back to the view)"),
    Row("camera_to_view", "Set camera to &view", "navigation.set_camera_to_view",
        ("Ctrl+Alt+Num+0", "Ctrl+Alt+0"), "View", 0,
        "move the scene's camera to the view (one undoable edit)"),
    Row("lock_camera", "&Lock camera to view", "navigation.set_locked", (), "View", 0,
        "in camera view, orbiting, panning and zooming move the scene's camera",
        checkable=True),
    Row("view_front", "&Front", "navigation.view_front", ("Num+1", "1"), "View", 1),
    Row("view_back", "&Back", "navigation.view_back", ("Ctrl+Num+1",), "View", 1),
    Row("view_right", "&Right", "navigation.view_right", ("Num+3", "3"), "View", 1),
    Row("view_left", "L&eft", "navigation.view_left", ("Ctrl+Num+3",), "View", 1),
    Row("view_top", "&Top", "navigation.view_top", ("Num+7", "7"), "View", 1),
    Row("view_bottom", "B&ottom", "navigation.view_bottom", ("Ctrl+Num+7",), "View", 1),
    Row("frame_selected", "Frame &selected", "navigation.frame_selection", ("F",), "View", 2,
        "turn and move the view to show the selection whole"),
    Row("frame_all", "Frame &all", "navigation.frame_all", ("Home",), "View", 2,
        "show every object"),
    Row("fit", "&Fit the picture", "viewport.fit_picture", ("Ctrl+0",), "View", 3,
        "show the whole picture, as large as fits"),
    Row("one_to_one", "&Actual pixels (1:1)", "viewport.actual_pixels", ("Ctrl+1",),
        "View", 3, "one render pixel per screen pixel"),
    Row("zoom_in", "Zoom the picture &in", "viewport.zoom_in", ("Ctrl+=", "Ctrl++"), "View",
        3, "also Ctrl+wheel; Ctrl+drag moves the zoomed picture"),
    Row("zoom_out", "Zoom the picture &out", "viewport.zoom_out", ("Ctrl+-",), "View", 3),
    # Render
    Row("render", "&Render", "render_control.start_render", ("Ctrl+R",), "Render", 0,
        "render the full picture through the scene's camera, tile by tile"),
    Row("stop", "&Stop", "render_control.stop_render", (), "Render", 0,
        "stop the render and keep the picture so far (Esc)"),
    Row("preview", "Interactive &preview", "render_control.toggle_preview", (), "Render", 1,
        checkable=True),
    Row("settings", "Render &settings…", "select_render_settings", (), "Render", 1),
    Row("controls", "&Controls", "show_controls", ("F1",), "Help", 0,
        "every key and mouse control"),
)

#: controls that are not menu entries: (what, keys)
MOUSE_CONTROLS = (
    ("Select what is under the pointer", "click the picture or a row of the tree"),
    ("Add to / remove from the selection", "Shift+click or Ctrl+click"),
    ("Orbit the view", "drag (left or middle button)"),
    ("Pan the view", "right-drag or Shift+drag"),
    ("Zoom the view toward the pointer", "wheel"),
    ("Zoom / move the picture itself", "Ctrl+wheel / Ctrl+drag"),
)
TOOL_CONTROLS = (
    ("Keep a move, rotation or scale to an axis", "X, Y, Z (again: free)"),
    ("The exact amount", "type a number (- and . too), Backspace"),
    ("Confirm / cancel the move", "Enter or click / Esc or right-click"),
)


def key_text(keys: tuple[str, ...]) -> str:
    """The keys as the menus show them (native text: Ctrl+S, Num+0...)."""
    return ", ".join(QKeySequence(k).toString(QKeySequence.SequenceFormat.NativeText)
                     for k in keys)


def controls_html() -> str:
    """Help > Controls: every row of the table with its keys, then the mouse and the keys
    of a running move."""

    def table(title: str, rows) -> str:
        cells = "".join(f"<tr><td>{what}</td><td>&nbsp;&nbsp;<b>{keys}</b></td></tr>"
                        for what, keys in rows)
        return f"<h4>{title}</h4><table>{cells}</table>"

    parts = []
    for menu in MENUS:
        rows = [(r.text.replace("&", "").rstrip("…"), key_text(r.keys))
                for r in ROWS if r.menu == menu and r.keys]
        if rows:
            parts.append(table(menu, rows))
    parts.append(table("Mouse", MOUSE_CONTROLS))
    parts.append(table("While moving, rotating or scaling (G, R, S)", TOOL_CONTROLS))
    return "".join(parts)


def resolve(root: object, dotted: str):
    target = root
    for part in dotted.split("."):
        target = getattr(target, part)
    return target


def make_actions(window) -> dict[str, QAction]:
    """The table's actions, on ``window`` (their shortcuts work wherever the focus is in
    it): ``{name: action}``. A row's method is looked up when the action runs, so a
    collaborator made later (the timeline) can own it."""
    actions: dict[str, QAction] = {}
    stack = window.doc.undo_stack
    for row in ROWS:
        if row.name == "undo":
            action = stack.createUndoAction(window, row.text)
        elif row.name == "redo":
            action = stack.createRedoAction(window, row.text)
        else:
            action = QAction(row.text, window)
            action.setCheckable(row.checkable)
            if row.checkable:
                action.toggled.connect(
                    lambda on, m=row.method: resolve(window, m)(on))
            else:
                action.triggered.connect(
                    lambda checked=False, m=row.method: resolve(window, m)())
        action.setObjectName(row.name)
        action.setShortcuts([QKeySequence(k) for k in row.keys])
        action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        if row.tip:
            shown = f"{row.tip} ({key_text(row.keys)})" if row.keys else row.tip
            action.setToolTip(shown)
            action.setStatusTip(row.tip)
        window.addAction(action)
        actions[row.name] = action
    return actions


def fill_menus(window, actions: dict[str, QAction], menus: dict) -> None:
    """Put each row's action into ``menus[row.menu]`` (a QMenu), a separator between groups."""
    last: dict[str, int] = {}
    for row in ROWS:
        menu = menus.get(row.menu)
        if menu is None:
            continue
        if row.menu in last and last[row.menu] != row.group:
            menu.addSeparator()
        last[row.menu] = row.group
        menu.addAction(actions[row.name])


# ---------------------------------------------------------------------- text fields


_TEXT_WIDGETS = (QLineEdit, QAbstractSpinBox, QTextEdit, QPlainTextEdit, QComboBox)
#: what a text field keeps even though a menu might want it
_FIELD_KEYS = (QKeySequence.StandardKey.Undo, QKeySequence.StandardKey.Redo,
               QKeySequence.StandardKey.Cut, QKeySequence.StandardKey.Copy,
               QKeySequence.StandardKey.Paste, QKeySequence.StandardKey.SelectAll)
_SLIDER_KEYS = (Qt.Key.Key_Home, Qt.Key.Key_End, Qt.Key.Key_Left, Qt.Key.Key_Right,
                Qt.Key.Key_Up, Qt.Key.Key_Down, Qt.Key.Key_PageUp, Qt.Key.Key_PageDown)
_COMMAND_MODIFIERS = (Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier
                      | Qt.KeyboardModifier.MetaModifier)


class ShortcutGuard(QObject):
    """Installed on the application: in a text field of ``window``, a key with Ctrl, Alt
    or Meta (or a function key) that is a shortcut of the window's goes to the window (a
    line edit takes Ctrl+E as "end of line", and the menu's Save image would never run). The
    field keeps its editing keys (undo, redo, cut, copy, paste, select all: those it hands
    on itself when no value is being typed)."""

    def __init__(self, window: QWidget) -> None:
        super().__init__(window)
        self.window_ = window

    def eventFilter(self, watched, event) -> bool:  # noqa: N802 - Qt's name
        if event.type() != QEvent.Type.ShortcutOverride or not isinstance(event, QKeyEvent):
            return False
        if isinstance(watched, QAbstractSlider) and event.key() in _SLIDER_KEYS and \
                not event.modifiers() & _COMMAND_MODIFIERS and self.window_.isAncestorOf(watched):
            event.accept()  # a slider's own keys (Home: its first value, not Frame all)
            return True
        if not isinstance(watched, _TEXT_WIDGETS) or not self.window_.isAncestorOf(watched):
            return False
        function_key = Qt.Key.Key_F1 <= event.key() <= Qt.Key.Key_F35
        if not (event.modifiers() & _COMMAND_MODIFIERS) and not function_key:
            return False
        if any(event.matches(k) for k in _FIELD_KEYS):
            return False
        pressed = QKeySequence(event.keyCombination())
        for action in self.window_.actions():
            if action.isEnabled() and any(s.matches(pressed) ==
                                          QKeySequence.SequenceMatch.ExactMatch
                                          for s in action.shortcuts()):
                event.ignore()  # not the field's: the window's shortcut runs
                return True
        return False


__all__ = ["MOUSE_CONTROLS", "ROWS", "TOOL_CONTROLS", "Row", "ShortcutGuard",
           "controls_html", "fill_menus", "key_text", "make_actions"]
