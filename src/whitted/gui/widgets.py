"""Field editors for the properties panel. Each one shows a value, and emits ``committed``
with the new value (and whether it is one step of a continuous drag) or ``refused`` with a
one-line reason when the text is not even a number. Range checks are the scene model's job."""

from __future__ import annotations

import itertools
import re

from PySide6.QtCore import QEvent, QObject, QPoint, Qt, Signal
from PySide6.QtGui import QColor, QKeyEvent, QKeySequence, QPainter
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QAbstractSlider,
    QAbstractSpinBox,
    QCheckBox,
    QColorDialog,
    QComboBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..scene.types import srgb_channel_to_linear

ERROR_STYLE = "QLineEdit { border: 1px solid #d22; background: #fff0f0; }"
SLIDER_STEPS = 1000
_sessions = itertools.count(1)


def fmt(value: float) -> str:
    """A number as a short, exact-enough text for a field."""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    text = f"{value:.6g}"
    return "0" if text == "-0" else text


def parse_number(text: str, *, integer: bool = False) -> float | int:
    t = text.strip().replace(",", ".") if text.count(",") == 1 and "." not in text else text.strip()
    if not t:
        raise ValueError("a number is needed here")
    try:
        return int(t) if integer else float(t)
    except ValueError:
        kind = "a whole number" if integer else "a number"
        raise ValueError(f"{text.strip()!r} is not {kind}") from None


def linear_to_srgb(c: float) -> float:
    c = min(max(c, 0.0), 1.0)
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055


def hex_of(colour: tuple[float, float, float] | None) -> str:
    """``#rrggbb`` (sRGB) of a linear colour, as colour pickers show it."""
    if colour is None:
        return "#ffffff"
    return "#" + "".join(f"{round(linear_to_srgb(c) * 255):02x}" for c in colour)


def linear_of_hex(text: str) -> tuple[float, float, float]:
    return tuple(srgb_channel_to_linear(int(text[i:i + 2], 16) / 255) for i in (1, 3, 5))


class FieldEditor(QWidget):
    """Base: ``committed(value, continuous)``, ``refused(message)``."""

    committed = Signal(object, bool)
    refused = Signal(str)
    #: the field holds the scene's value again (typed back): its message goes away
    restored = Signal()
    #: a continuous change (a slider held) started (True) or ended (False)
    dragging = Signal(bool)

    def set_value(self, value: object) -> None:
        raise NotImplementedError

    def set_error(self, bad: bool) -> None:
        for edit in self.findChildren(QLineEdit):
            edit.setStyleSheet(ERROR_STYLE if bad else "")


#: keys a field hands on to the window unless the user is typing a value in it
_SCENE_KEYS = (QKeySequence.StandardKey.Undo, QKeySequence.StandardKey.Redo)


class _Line(QLineEdit):
    """A line edit that remembers what it last showed, so leaving it unchanged commits
    nothing. Its own undo/redo (Ctrl+Z, Ctrl+Shift+Z) works only while a value is being
    typed; once committed (or untouched) those keys undo and redo the scene."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.shown = ""
        self.setMinimumWidth(48)

    def event(self, event) -> bool:  # noqa: D102 - Qt's name
        if event.type() == QEvent.Type.ShortcutOverride and isinstance(event, QKeyEvent) \
                and not self.changed and any(event.matches(k) for k in _SCENE_KEYS):
            event.ignore()  # not ours: the window's shortcut runs
            return True
        return super().event(event)

    def finish(self) -> None:
        """Commit what is typed now (the window calls this before Save, Render...)."""
        if self.changed:
            self.editingFinished.emit()

    def show_text(self, text: str) -> None:
        self.shown = text
        if not self.hasFocus() or self.text() == self.shown:
            self.setText(text)
        else:  # the user is typing here; do not yank the text away
            self.setText(text)
        self.setCursorPosition(0)

    @property
    def changed(self) -> bool:
        return self.text().strip() != self.shown


class TextEditor(FieldEditor):
    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.line = _Line(self)
        _hbox(self, self.line)
        self.line.editingFinished.connect(self._finish)

    def set_value(self, value: object) -> None:
        self.line.show_text("" if value is None else str(value))

    def _finish(self) -> None:
        if self.line.changed:
            self.committed.emit(self.line.text().strip() or None, False)
        else:
            self.restored.emit()


class NumberEditor(FieldEditor):
    def __init__(self, parent=None, *, integer: bool = False, optional: bool = False) -> None:
        super().__init__(parent)
        self.integer = integer
        self.optional = optional
        self.line = _Line(self)
        if optional:
            self.line.setPlaceholderText("default")
        _hbox(self, self.line)
        self.line.editingFinished.connect(self._finish)

    def set_value(self, value: object) -> None:
        self.line.show_text("" if value is None else fmt(value))

    def _finish(self) -> None:
        if not self.line.changed:
            self.restored.emit()
            return
        if self.optional and not self.line.text().strip():
            self.committed.emit(None, False)
            return
        try:
            value = parse_number(self.line.text(), integer=self.integer)
        except ValueError as exc:
            self.refused.emit(str(exc))
            return
        self.committed.emit(value, False)


class VectorEditor(FieldEditor):
    """Three number fields x, y, z (or one per letter of ``axes``: "uv" for texture
    coordinates). ``scalar_ok``: three equal numbers commit one number (a uniform scale)."""

    def __init__(self, parent=None, *, scalar_ok: bool = False, axes: str = "xyz") -> None:
        super().__init__(parent)
        self.scalar_ok = scalar_ok
        self.axes = axes
        self.lines = []
        box = QHBoxLayout(self)
        box.setContentsMargins(0, 0, 0, 0)
        box.setSpacing(2)
        for axis in axes:
            line = _Line(self)
            line.setToolTip(axis)
            line.setPlaceholderText(axis)
            line.editingFinished.connect(self._finish)
            box.addWidget(line)
            self.lines.append(line)

    def set_value(self, value: object) -> None:
        if value is None:
            values = ("",) * len(self.axes)
        elif isinstance(value, int | float):
            values = (fmt(value),) * len(self.axes)
        else:
            values = tuple(fmt(v) for v in value)
        for line, text in zip(self.lines, values, strict=True):
            line.show_text(text)

    def _finish(self) -> None:
        if not any(line.changed for line in self.lines):
            self.restored.emit()
            return
        out = []
        for axis, line in zip(self.axes, self.lines, strict=True):
            try:
                out.append(float(parse_number(line.text())))
            except ValueError as exc:
                self.refused.emit(f"{axis}: {exc}")
                return
        if self.scalar_ok and len(set(out)) == 1:
            self.committed.emit(out[0], False)
        else:
            self.committed.emit(tuple(out), False)


class CoefficientEditor(FieldEditor):
    """A slider "on a scale" from ``lo`` to ``hi`` with a number box beside it; the box also
    takes values beyond the slider's range (the model decides what is valid). ``triple_ok``:
    the box also takes ``r, g, b`` (attenuation)."""

    def __init__(self, lo: float, hi: float, parent=None, *, triple_ok: bool = False) -> None:
        super().__init__(parent)
        self.lo, self.hi = lo, hi
        self.triple_ok = triple_ok
        self.session = 0
        self._setting = False
        self.slider = QSlider(Qt.Orientation.Horizontal, self)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setPageStep(SLIDER_STEPS // 20)
        self.slider.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.line = _Line(self)
        self.line.setMaximumWidth(72 if not triple_ok else 110)
        box = QHBoxLayout(self)
        box.setContentsMargins(0, 0, 0, 0)
        box.addWidget(self.slider, 1)
        box.addWidget(self.line)
        self.slider.sliderPressed.connect(self._new_session)
        self.slider.sliderPressed.connect(lambda: self.dragging.emit(True))
        self.slider.sliderReleased.connect(lambda: self.dragging.emit(False))
        self.slider.valueChanged.connect(self._slid)
        self.line.editingFinished.connect(self._finish)

    def _new_session(self) -> None:
        self.session = next(_sessions)

    def value_at(self, position: int) -> float:
        v = self.lo + (self.hi - self.lo) * position / SLIDER_STEPS
        return float(f"{v:.4g}")

    def set_value(self, value: object) -> None:
        self._setting = True
        try:
            if isinstance(value, tuple):
                self.line.show_text(", ".join(fmt(v) for v in value))
                scalar = max(value)
            else:
                self.line.show_text(fmt(value))
                scalar = float(value)
            span = self.hi - self.lo
            pos = round((scalar - self.lo) / span * SLIDER_STEPS) if span else 0
            if not self.slider.isSliderDown():
                self.slider.setValue(max(0, min(SLIDER_STEPS, pos)))
        finally:
            self._setting = False

    def _slid(self, position: int) -> None:
        if self._setting:
            return
        if not self.slider.isSliderDown():
            self._new_session()  # a click or key press is a step of its own
        self.committed.emit(self.value_at(position), True)

    def _finish(self) -> None:
        if not self.line.changed:
            self.restored.emit()
            return
        text = self.line.text()
        parts = [p for p in re.split(r"[,;\s]+", text.strip()) if p]
        try:
            if self.triple_ok and len(parts) == 3:
                value: object = tuple(float(parse_number(p)) for p in parts)
            else:
                value = parse_number(text)
        except ValueError as exc:
            self.refused.emit(str(exc))
            return
        self._new_session()
        self.committed.emit(value, False)


class ColourEditor(FieldEditor):
    """A swatch that opens a colour picker, and the ``#rrggbb`` text beside it (sRGB, as in
    scene files)."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.button = QToolButton(self)
        self.button.setFixedSize(40, 22)
        self.button.setToolTip("choose a colour")
        self.line = _Line(self)
        self.line.setMaximumWidth(90)
        box = _hbox(self, self.button)
        box.addWidget(self.line)
        box.addStretch(1)
        self.session = 0
        self.dialog: QColorDialog | None = None  # the picker while it is open
        self.button.clicked.connect(self.pick)
        self.line.editingFinished.connect(self._finish)

    def set_value(self, value: object) -> None:
        text = hex_of(value)  # type: ignore[arg-type]
        self.line.show_text(text)
        self.button.setStyleSheet(f"background: {text}; border: 1px solid #666;")

    def pick(self) -> QColorDialog:
        """Open the colour picker; the scene (and so the picture) follows the colour while
        it changes, as one undo step; Cancel puts the colour back."""
        original = self.line.shown
        self.session = next(_sessions)
        dialog = QColorDialog(QColor(original), self)
        dialog.setWindowTitle("Colour")
        dialog.setOption(QColorDialog.ColorDialogOption.NoButtons, False)
        dialog.currentColorChanged.connect(
            lambda c: self.committed.emit(c.name().lower(), True))

        def done(result: int) -> None:
            if result == QColorDialog.DialogCode.Accepted:
                self.committed.emit(dialog.selectedColor().name().lower(), True)
            else:
                self.committed.emit(original, True)  # merges away: nothing to undo
            self.dialog = None
            dialog.deleteLater()

        dialog.finished.connect(done)
        self.dialog = dialog
        dialog.open()
        return dialog

    def choose(self, text: str) -> None:
        """Commit ``#rrggbb`` (what the picker gives)."""
        if text.lower() != self.line.shown:
            self.committed.emit(text.lower(), False)

    def _finish(self) -> None:
        if not self.line.changed:
            self.restored.emit()
            return
        text = self.line.text().strip()
        if not text.startswith("#"):
            text = "#" + text
        if not re.fullmatch(r"#[0-9a-fA-F]{6}", text):
            self.refused.emit(f"{self.line.text().strip()!r} is not a colour like #ff8800")
            return
        self.committed.emit(text.lower(), False)


class ChoiceEditor(FieldEditor):
    def __init__(self, choices: tuple, parent=None) -> None:
        super().__init__(parent)
        self.combo = QComboBox(self)
        self.combo.addItems([str(c) for c in choices])
        self.choices = choices
        _hbox(self, self.combo)
        self.combo.activated.connect(lambda i: self.committed.emit(self.choices[i], False))

    def set_value(self, value: object) -> None:
        i = self.choices.index(value) if value in self.choices else -1
        self.combo.setCurrentIndex(i)


class BoolEditor(FieldEditor):
    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.box = QCheckBox(self)
        _hbox(self, self.box)
        self.box.clicked.connect(lambda checked: self.committed.emit(bool(checked), False))

    def set_value(self, value: object) -> None:
        self.box.setChecked(bool(value))


class FileEditor(FieldEditor):
    """A file name (relative to the scene's folder) and a Browse button; ``browse`` asks the
    window for a file (a dialog) and gets the chosen name back through :meth:`choose`."""

    browse = Signal()

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.line = _Line(self)
        self.button = QPushButton("Browse…", self)
        box = _hbox(self, self.line)
        box.addWidget(self.button)
        self.button.clicked.connect(self.browse.emit)
        self.line.editingFinished.connect(self._finish)

    def set_value(self, value: object) -> None:
        self.line.show_text("" if value is None else str(value))

    def choose(self, name: str) -> None:
        self.committed.emit(name, False)

    def _finish(self) -> None:
        if self.line.changed:
            self.committed.emit(self.line.text().strip(), False)
        else:
            self.restored.emit()


class FieldRow(QWidget):
    """An editor with its error message. The message floats just under the field, over what
    follows (never moving the form, so the next click lands where the user aimed), and goes
    away when the field holds a valid value again."""

    def __init__(self, editor: FieldEditor, parent=None) -> None:
        super().__init__(parent)
        self.editor = editor
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.message.setStyleSheet(
            "QLabel { color: #a00000; background: #fff3f3; border: 1px solid #d88;"
            " padding: 1px 4px; }")
        self.message.hide()
        box = QVBoxLayout(self)
        box.setContentsMargins(0, 0, 0, 0)
        box.setSpacing(1)
        box.addWidget(editor)
        editor.refused.connect(self.show_error)
        editor.restored.connect(self.clear_error)

    def _host(self) -> QWidget:
        """The widget the message floats in: the scroll area's page (or the window)."""
        host: QWidget = self
        while host.parentWidget() is not None and not host.isWindow():
            parent = host.parentWidget()
            if parent.parentWidget() is not None and isinstance(
                    parent.parentWidget(), QAbstractScrollArea):
                return host
            host = parent
        return host

    def _place(self) -> None:
        host = self._host()
        if self.message.parentWidget() is not host:
            self.message.setParent(host)
        width = max(self.width(), 120)
        self.message.setFixedWidth(width)
        self.message.adjustSize()
        self.message.move(self.mapTo(host, QPoint(0, self.height())))
        self.message.raise_()

    def show_error(self, message: str) -> None:
        self.message.setText(message)
        self._place()
        self.message.show()
        self.editor.set_error(True)

    def clear_error(self) -> None:
        if not self.message.isHidden() or self.message.text():
            self.message.clear()
            self.message.hide()
            self.editor.set_error(False)

    def resizeEvent(self, event) -> None:  # noqa: N802
        super().resizeEvent(event)
        if not self.message.isHidden():
            self._place()

    def moveEvent(self, event) -> None:  # noqa: N802
        super().moveEvent(event)
        if not self.message.isHidden():
            self._place()

    @property
    def error(self) -> str:
        return self.message.text()


class WheelGuard(QObject):
    """Lets the mouse wheel change a drop-down, slider or number box only while it has the
    keyboard focus; otherwise the turn goes on to the scroll area under it (scrolling the
    panel never changes a value that passes under the pointer)."""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if event.type() == QEvent.Type.Wheel and isinstance(watched, QWidget) \
                and not watched.hasFocus():
            event.ignore()  # not accepted: Qt hands it to the parents (the scroll area)
            return True
        return False


_wheel_guard: WheelGuard | None = None
WHEEL_GUARDED = (QComboBox, QAbstractSlider, QAbstractSpinBox)


def guard_wheel(root: QWidget) -> None:
    """Install the :class:`WheelGuard` on every drop-down, slider and number box in ``root``
    (and take away their wheel focus: a wheel turn does not focus them either)."""
    global _wheel_guard
    if _wheel_guard is None:
        _wheel_guard = WheelGuard()
    widgets = [root, *root.findChildren(QWidget)]
    for w in widgets:
        if isinstance(w, WHEEL_GUARDED):
            w.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
            w.installEventFilter(_wheel_guard)


def _hbox(widget: QWidget, child: QWidget) -> QHBoxLayout:
    box = QHBoxLayout(widget)
    box.setContentsMargins(0, 0, 0, 0)
    box.setSpacing(4)
    box.addWidget(child)
    return box


class ElidedLabel(QLabel):
    """A one-line label that never widens its panel: a text longer than the room it has is
    shown cut with "…" (the whole text in its tooltip)."""

    def __init__(self, text: str = "", parent=None) -> None:
        super().__init__(parent)
        self.full_text = ""
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.setText(text)

    def setText(self, text: str) -> None:  # noqa: N802 - Qt's name
        self.full_text = text
        super().setText(text)
        self.setToolTip(text if self.fontMetrics().horizontalAdvance(text) > self.width()
                        else "")
        self.update()

    def shown_text(self) -> str:
        return self.fontMetrics().elidedText(self.full_text, Qt.TextElideMode.ElideMiddle,
                                             max(self.contentsRect().width(), 0))

    def minimumSizeHint(self):  # noqa: N802 - Qt's name
        hint = super().minimumSizeHint()
        hint.setWidth(10)
        return hint

    def sizeHint(self):  # noqa: N802 - Qt's name
        hint = super().sizeHint()
        hint.setWidth(min(hint.width(), 200))
        return hint

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        self.setToolTip(self.full_text if self.shown_text() != self.full_text else "")

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt's name
        painter = QPainter(self)
        painter.setFont(self.font())
        painter.setPen(self.palette().color(self.foregroundRole()))
        painter.drawText(self.contentsRect(), int(self.alignment() | Qt.AlignmentFlag.AlignVCenter),
                         self.shown_text())

