"""The properties panel: every property of the selected item with a fitting editor. An edit
builds the item anew through the scene model; a value the model refuses stays in its field,
marked red, with the model's message under it, and never reaches the scene."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from pydantic import BaseModel
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from ..scene import PRESETS, Material, Transform
from ..scene.types import Gradient
from . import camera_ops
from . import fields as F
from .document import (
    BACKGROUND,
    CAMERA,
    RENDER,
    EditRefused,
    SceneDocument,
    get_path,
    label_of,
    set_path,
)
from .icons import swatch
from .messages import friendly_message
from .widgets import (
    BoolEditor,
    ChoiceEditor,
    CoefficientEditor,
    ColourEditor,
    ElidedLabel,
    FieldEditor,
    FieldRow,
    FileEditor,
    NumberEditor,
    TextEditor,
    VectorEditor,
    guard_wheel,
)

SMOOTH = {None: "auto", True: "on", False: "off"}
#: what the Outside medium field shows for a material given inline in the file
INLINE = "(inline material)"


def make_editor(spec: F.Spec) -> FieldEditor:
    k = spec.kind
    if k == F.TEXT:
        return TextEditor()
    if k in (F.NUMBER, F.INT, F.OPT_INT):
        return NumberEditor(integer=k != F.NUMBER, optional=k == F.OPT_INT)
    if k in (F.VEC3, F.ANGLES):
        return VectorEditor()
    if k == F.SCALE:
        return VectorEditor(scalar_ok=True)
    if k == F.UV:
        return VectorEditor(axes="uv")
    if k in (F.COEF, F.ATTEN):
        return CoefficientEditor(spec.lo, spec.hi, triple_ok=k == F.ATTEN)
    if k == F.COLOUR:
        return ColourEditor()
    if k == F.CHOICE:
        return ChoiceEditor(spec.choices)
    if k == F.BOOL:
        return BoolEditor()
    if k == F.FILE:
        return FileEditor()
    raise ValueError(k)


class PropertyPanel(QWidget):
    """Shows the document's selected item. ``choose_file(title, filters)`` (set by the window)
    asks for a file and returns its path or None. ``interacting(bool)``: a slider is held
    (the preview goes coarse and fast) or let go."""

    interacting = Signal(bool)

    def __init__(self, doc: SceneDocument, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.choose_file: Callable[[str, str], str | None] = lambda title, filters: None
        #: choosing a preset over a custom colour: "keep" it, "replace" it or "cancel"
        self.ask_keep_colour: Callable[[str], str] = lambda preset: "keep"
        self.rows: dict[tuple, FieldRow] = {}
        self.specs: dict[tuple, F.Spec] = {}
        self.material_combo: QComboBox | None = None
        self.material_row: FieldRow | None = None
        self._signature: object = None
        #: the item this panel shows, and the only one its edits go to
        self.key: tuple | None = None
        self.title = ElidedLabel("", self)
        self.title.setStyleSheet("font-weight: bold; font-size: 11pt;")
        self.scroll = QScrollArea(self)
        self.scroll.setWidgetResizable(True)
        self.scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        box = QVBoxLayout(self)
        box.setContentsMargins(4, 4, 4, 4)
        box.addWidget(self.title)
        #: with several items selected: how many, and that the panel edits the active one
        self.selection_note = ElidedLabel("", self)
        self.selection_note.setStyleSheet("color: #555;")
        self.selection_note.hide()
        box.addWidget(self.selection_note)
        box.addWidget(self.scroll, 1)
        self.form: QWidget | None = None
        doc.changed.connect(self.refresh)
        doc.selection_changed.connect(self.refresh)
        self.refresh()

    # ------------------------------------------------------------------ building

    def specs_for(self, key: tuple, item: BaseModel) -> list[F.Spec]:
        if key == CAMERA:
            return F.camera_specs(item)
        if key == RENDER:
            return F.render_specs(item)
        if key == BACKGROUND:
            return F.background_specs(item)
        if key[0] == "lights":
            return F.light_specs(item)
        specs = F.object_specs(item)
        geometry = [s for s in specs if s.group != F.TRANSFORM]
        placement = [s for s in specs if s.group == F.TRANSFORM]
        return geometry + F.material_specs(self.shown_material(key)) + placement

    def file_materials(self, key: tuple) -> list[Material] | None:
        """The materials of a model file (its MTL...) when the object uses them (no
        ``material`` of its own); None otherwise or when the file cannot be read."""
        if key is None or key[0] != "objects":
            return None
        obj = self.doc.item(key)
        if getattr(obj, "type", None) != "mesh" or obj.file is None or obj.material is not None:
            return None
        try:
            from ..assets import load_mesh

            return list(load_mesh(self.doc.scene.resolve_path(obj.file)).materials)
        except Exception:  # noqa: BLE001 - an unreadable file shows the default instead
            return None

    def inherited(self, key: tuple, *, even_if_own: bool = False
                  ) -> tuple[BaseModel, Any] | None:
        """For a CSG child without a material of its own (``even_if_own``: with or without):
        the nearest CSG object above it that has one, and that material (what the child is
        made of); else None."""
        if key is None or key[0] != "objects" or len(key) < 3:
            return None
        chain = [self.doc.item(key[:n]) for n in range(2, len(key) + 1)]
        if any(item is None for item in chain) or (
                chain[-1].material is not None and not even_if_own):
            return None
        for ancestor in reversed(chain[:-1]):
            if ancestor.material is not None:
                return ancestor, ancestor.material
        return None

    def shown_material(self, key: tuple) -> Material:
        """The material the panel shows for an object: its own, its model file's first, or
        (a CSG child without one) the one it inherits from its CSG object."""
        from_file = self.file_materials(key)
        if from_file:
            return from_file[0]
        item = self.doc.item(key)
        inherited = self.inherited(key)
        ref = inherited[1] if inherited is not None else getattr(item, "material", None)
        return self.doc.scene.resolve_material(ref)

    def refresh(self, *_: object) -> None:
        key = self.doc.selection
        item = self.doc.item(key)
        self.key = key if item is not None else None
        if item is None:
            self.selection_note.hide()
            self.title.setText("Nothing selected")
            self._signature = None
            self._rebuild(key, [])
            return
        specs = self.specs_for(key, item)
        self.title.setText(self.describe(key, item))
        note = self.selection_text()
        self.selection_note.setText(note)
        self.selection_note.setVisible(bool(note))
        signature = (key[0], key[1] if len(key) > 1 else None, getattr(item, "type", None),
                     tuple(specs))
        if signature != self._signature:
            self._signature = signature
            self._rebuild(key, specs)
        self._update_values(key, item)

    def describe(self, key: tuple, item: BaseModel) -> str:
        if key == CAMERA:
            return "Camera"
        if key == RENDER:
            return "Render settings"
        if key == BACKGROUND:
            return "Background"
        kind = "Light" if key[0] == "lights" else "Object"
        return f"{kind}: {label_of(item)} ({item.type})"

    def selection_text(self) -> str:
        """"3 objects and 2 lights selected" (the panel shows the active one); "" for one."""
        keys = self.doc.selected_keys()
        if len(keys) < 2:
            return ""
        counts = [(sum(k[0] == kind for k in keys), word) for kind, word in
                  (("objects", "object"), ("lights", "light"))]
        parts = [f"{n} {word}{'s' if n > 1 else ''}" for n, word in counts if n]
        return f"{' and '.join(parts)} selected (this panel edits the one above)"

    def _rebuild(self, key: tuple, specs: list[F.Spec]) -> None:
        # the focus must not stay in the old form (a window of its own once taken out of
        # the scroll area, where the window's shortcuts would no longer reach)
        focus = QApplication.focusWidget()
        had_focus = self.form is not None and focus is not None and self.form.isAncestorOf(focus)
        focused_path = next((p for p, r in self.rows.items()
                             if had_focus and r.isAncestorOf(focus)), None)
        if self.form is not None:  # deleted later: its editor may be emitting right now
            old = self.scroll.takeWidget()
            if old is not None:
                old.hide()
                old.deleteLater()
        self.rows, self.specs = {}, {}
        self.material_combo = None
        self.form = QWidget()
        outer = QVBoxLayout(self.form)
        outer.setContentsMargins(0, 0, 0, 0)
        groups: dict[str, QFormLayout] = {}
        for spec in specs:
            group = spec.group or "General"
            if group not in groups:
                box = QGroupBox(group, self.form)
                form = QFormLayout(box)
                form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
                groups[group] = form
                outer.addWidget(box)
                if group == F.MATERIAL:
                    self._add_material_source(form)
            editor = make_editor(spec)
            row = FieldRow(editor)
            label = QLabel(spec.label)
            if spec.tip:
                label.setToolTip(spec.tip)
                editor.setToolTip(spec.tip)
            groups[group].addRow(label, row)
            self.rows[spec.path] = row
            self.specs[spec.path] = spec
            editor.committed.connect(
                lambda value, continuous, s=spec: self.commit(s, value, continuous))
            editor.dragging.connect(self.interacting)
            if isinstance(editor, FileEditor):
                editor.browse.connect(lambda s=spec, e=editor: self._browse(s, e))
        if key == CAMERA:
            outer.addWidget(self._camera_tools())
        outer.addStretch(1)
        guard_wheel(self.form)
        self.scroll.setWidget(self.form)
        if had_focus:
            row = self.rows.get(focused_path) if focused_path is not None else None
            inputs = [w for w in row.editor.findChildren(QWidget)
                      if w.focusPolicy() != Qt.FocusPolicy.NoFocus] if row is not None else []
            (inputs[0] if inputs else self.scroll).setFocus()

    def _add_material_source(self, form: QFormLayout) -> None:
        combo = QComboBox()
        combo.setToolTip("a preset copies its values into this object's material; "
                         "a scene material is shared with the objects that use it")
        row = FieldRow(FieldEditor())
        row.layout().insertWidget(0, combo)
        form.addRow(QLabel("Preset"), row)
        self.material_combo = combo
        self.material_row = row
        # after the drop-down's own signal has finished (the edit refreshes the panel)
        combo.activated.connect(lambda i: QTimer.singleShot(
            0, lambda d=combo.itemData(i): self.choose_material(d)))

    def _camera_tools(self) -> QGroupBox:
        box = QGroupBox("Rotate the camera")
        form = QFormLayout(box)
        self.rotate_axis = QComboBox()
        self.rotate_axis.addItems(["X", "Y", "Z"])
        self.rotate_axis.setToolTip("the world's X, Y or Z axis (not the camera's own), "
                                    "through the camera or through its target")
        self.rotate_axis.setCurrentIndex(1)
        self.rotate_angle = NumberEditor()
        self.rotate_angle.set_value(15.0)
        self.rotate_pivot = QComboBox()
        self.rotate_pivot.addItem("about the camera (turn the view)", "camera")
        self.rotate_pivot.addItem("about the target (circle it)", "target")
        self.rotate_row = FieldRow(self.rotate_angle)
        button = QPushButton("Rotate")
        button.clicked.connect(self.rotate_camera)
        self.rotate_button = button
        line = QWidget()
        h = QHBoxLayout(line)
        h.setContentsMargins(0, 0, 0, 0)
        h.addWidget(self.rotate_axis)
        h.addWidget(self.rotate_row, 1)
        h.addWidget(button)
        form.addRow("World axis, angle (°)", line)
        form.addRow("Pivot", self.rotate_pivot)
        hint = QLabel("In the picture: drag to orbit, right- or Shift-drag to pan, wheel to zoom.")
        hint.setWordWrap(True)
        hint.setStyleSheet("color: #555;")
        form.addRow(hint)
        return box

    # ------------------------------------------------------------------ values

    def value_of(self, key: tuple, item: BaseModel, spec: F.Spec) -> Any:
        path = spec.path
        if path[0] == "material" and key[0] == "objects":
            material = self.shown_material(key)
            if path[1:] == ("texture", "type"):
                return getattr(material.texture, "type", "none")
            if path[1] == "specular_color" and material.specular_color is None:
                return (1.0, 1.0, 1.0)
            return get_path(material, path[1:])
        if path[0] == "transform" and item.transform is None:
            return get_path(Transform(), path[1:])
        if key == BACKGROUND and path == ("mode",):
            return "colour" if item.gradient is None else "gradient"
        if key == CAMERA and path == ("focus_mode",):
            return F.focus_mode(item)
        if path == ("smooth",):
            return SMOOTH[item.smooth]
        if path == ("outside",):  # a material's name; an inline one is shown, kept as it is
            if isinstance(item.outside, BaseModel):
                return INLINE
            return item.outside or ""
        value = get_path(item, path)
        if path == ("transform", "rotate") and value is None:
            return (0.0, 0.0, 0.0)
        return value

    def _update_values(self, key: tuple, item: BaseModel) -> None:
        for path, row in self.rows.items():
            row.clear_error()
            row.editor.set_value(self.value_of(key, item, self.specs[path]))
        if self.material_combo is not None:
            self._fill_material_combo(key, item)

    def _fill_material_combo(self, key: tuple, item: BaseModel) -> None:
        combo = self.material_combo
        assert combo is not None
        obj_file = getattr(item, "file", None) if getattr(item, "type", None) == "mesh" else None
        entries: list[tuple[str, str]] = []
        if obj_file:
            count = len(self.file_materials(key) or []) if item.material is None else 0
            name = Path(obj_file).name
            entries.append((f"From the model file ({name})" if not count or count == 1 else
                            f"From the model file ({name}, {count} materials)", "file:"))
        inherited = self.inherited(key, even_if_own=True)
        if inherited is not None:
            parent, ref = inherited
            what = ref if isinstance(ref, str) else (ref.preset or "its own")
            entries.append((f"Inherited from {label_of(parent)} ({what})", "inherit:"))
        entries.append(("Default (grey)", "default:"))
        entries += [(f"{name} (scene material)", f"named:{name}")
                    for name in self.doc.scene.materials]
        entries += [(f"{name} (preset)", f"preset:{name}") for name in PRESETS]
        entries.append(("Custom", "custom:"))
        shown = [(combo.itemText(i), combo.itemData(i)) for i in range(combo.count())]
        if shown != entries:  # (refilled only when the list changes: never under the user)
            combo.clear()
            for text, data in entries:
                kind, _, name = data.partition(":")
                if kind == "preset":
                    preset = Material(preset=name)
                    combo.addItem(swatch(preset.color, shiny=preset.kr > 0 or preset.ks > 0.3),
                                  text, data)
                else:
                    combo.addItem(text, data)
            if obj_file:
                combo.setItemData(0, "the materials the model's own file gives (its MTL, "
                                     "glTF...); editing a value overrides them all with this "
                                     "one", Qt.ItemDataRole.ToolTipRole)
        ref = item.material
        if ref is None and inherited is not None:
            current = "inherit:"
        elif ref is None and obj_file:
            current = "file:"
        elif ref is None:
            current = "default:"
        elif isinstance(ref, str):
            current = f"named:{ref}" if ref in self.doc.scene.materials else f"preset:{ref}"
        elif not isinstance(ref, str) and ref == Material() and (
                obj_file or self.inherited(key, even_if_own=True)):
            current = "default:"
        elif ref.preset is not None and ref == Material(preset=ref.preset):
            current = f"preset:{ref.preset}"
        else:
            current = "custom:"
        index = combo.findData(current)
        combo.setCurrentIndex(index if index >= 0 else combo.count() - 1)

    # ------------------------------------------------------------------ edits

    def commit(self, spec: F.Spec, value: Any, continuous: bool = False) -> bool:
        """Apply one field's new value to the item this panel shows; False (and a message at
        the field) if refused."""
        key = self.key
        item = self.doc.item(key) if key is not None else None
        row = self.rows.get(spec.path)
        if item is None:
            return False
        editor = row.editor if row else None
        merge = (key, spec.path, getattr(editor, "session", None)) if continuous else None
        try:
            data = self._data_with(key, item, spec, value)
            self.doc.edit_item(key, data, f"Change {spec.label.lower()}", merge_key=merge)
        except EditRefused as exc:
            if row is not None:
                row.show_error(self._message(exc, spec))
            return False
        row = self.rows.get(spec.path)  # the form may have been rebuilt by the edit
        if row is not None:
            row.clear_error()
        return True

    @staticmethod
    def _message(exc: EditRefused, spec: F.Spec) -> str:
        """The refusal in the user's words, naming the field as its label does."""
        if exc.validation is None:
            return str(exc)
        label = spec.label.split(" (")[0].lower()
        field = next((p for p in reversed(spec.path) if isinstance(p, str)), None)
        return friendly_message(exc.validation, label, field)

    def _data_with(self, key: tuple, item: BaseModel, spec: F.Spec, value: Any) -> dict:
        path = spec.path
        data = item.model_dump()
        if path[0] == "material" and key[0] == "objects":
            material = self.shown_material(key).model_dump()
            if path[1:] == ("texture", "type"):
                material["texture"] = self._new_texture(value, material.get("texture"))
            else:
                material = set_path(material, path[1:], value)
            data["material"] = material
            return data
        if path[0] == "transform" and data.get("transform") is None:
            data["transform"] = Transform().model_dump()
        if key == BACKGROUND and path == ("mode",):
            if value == "colour":
                data["gradient"] = None
            elif data.get("gradient") is None:
                c = data["color"]
                data["gradient"] = Gradient(top=c, bottom=c).model_dump()
            return data
        if key == CAMERA and path == ("focus_mode",):
            return self._focus_data(item, data, value)
        if path == ("smooth",):
            value = {v: k for k, v in SMOOTH.items()}[value]
        if path == ("outside",):
            value = (value or "").strip() or None
        return set_path(data, path, value)

    @staticmethod
    def _focus_data(camera: Any, data: dict, mode: str) -> dict:
        """The camera focusing as ``mode`` says, on the plane it focuses on now (a distance
        along the view, or the point on the view's axis at that distance)."""
        distance = round(camera.focus(), 4)
        data["focal_distance"] = data["focal_point"] = None
        if mode == "distance":
            data["focal_distance"] = distance if distance > 0 else 1.0
        elif mode == "point":
            forward = camera.basis()[2]
            point = [float(p + max(distance, 1e-3) * f)
                     for p, f in zip(camera.position, forward, strict=True)]
            data["focal_point"] = tuple(round(c, 4) for c in point)
        return data

    def _new_texture(self, kind: str, old: dict | None) -> dict | None:
        if kind == "none":
            return None
        if old is not None and old.get("type") == kind:
            return old
        if kind == "image":
            name = self.choose_file("Texture image", F.IMAGE_FILTER)
            if not name:
                raise EditRefused("choose an image file for the texture")
            return {"type": "image", "file": self._relative(name)}
        return {"type": kind}

    def choose_material(self, choice: str) -> None:
        """``default:``, ``named:NAME``, ``preset:NAME`` or ``custom:`` (the drop-down)."""
        kind, _, name = choice.partition(":")
        key = self.key
        item = self.doc.item(key) if key is not None else None
        if item is None or key[0] != "objects":
            return
        data = item.model_dump()
        if kind in ("file", "inherit"):  # a model's file's materials; a CSG parent's
            data["material"] = None
        elif kind == "default":  # (a model's "none" is its file's, a CSG child's its
            # parent's: grey is an override there)
            data["material"] = {} if getattr(item, "file", None) or self.inherited(key) \
                else None
        elif kind == "named":
            data["material"] = name
        elif kind == "preset":
            data["material"] = {"preset": name}
            mine = self.shown_material(key)
            custom = isinstance(item.material, Material) and item.material != Material(
                preset=item.material.preset) if item.material is not None else False
            if custom and mine.color not in (Material(preset=name).color, Material().color):
                answer = self.ask_keep_colour(name)
                if answer == "cancel":
                    self._fill_material_combo(key, item)
                    return
                if answer == "keep":
                    data["material"] = {"preset": name, "color": mine.color}
        else:  # custom: this object's own copy of what it shows now
            data["material"] = self.shown_material(key).model_dump()
        try:
            self.doc.edit_item(key, data, "Change material")
        except EditRefused as exc:
            if self.material_row is not None:
                self.material_row.show_error(str(exc))

    def _browse(self, spec: F.Spec, editor: FileEditor) -> None:
        name = self.choose_file(spec.label, spec.filters)
        if name:
            editor.choose(self._relative(name))

    def _relative(self, name: str) -> str:
        from pathlib import Path

        p = Path(name)
        try:
            return str(p.resolve().relative_to(self.doc.scene.base_dir.resolve()))
        except ValueError:
            return str(p)

    def rotate_camera(self) -> bool:
        """The Rotate button: turn the camera by the angle about the chosen axis."""
        try:
            from .widgets import parse_number

            angle = float(parse_number(self.rotate_angle.line.text()))
        except ValueError as exc:
            self.rotate_row.show_error(str(exc))
            return False
        axis = self.rotate_axis.currentText()
        pivot = self.rotate_pivot.currentData()
        try:
            camera = camera_ops.rotate_about_axis(self.doc.scene.camera, axis, angle, pivot=pivot)
            self.doc.edit_item(CAMERA, camera.model_dump(),
                               f"Rotate camera {angle:g}° about {axis}")
        except (ValueError, EditRefused) as exc:
            self.rotate_row.show_error(str(exc).splitlines()[0])
            return False
        self.rotate_row.clear_error()
        return True

    # ------------------------------------------------------------------ for tests and the window

    def row(self, *path: object) -> FieldRow:
        return self.rows[tuple(path)]
