"""The edited scene: the current :class:`~whitted.Scene` snapshot, its file, the selection and
the undo stack. Every edit builds a new validated scene; nothing invalid is ever stored."""

from __future__ import annotations

import copy
import re
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from ..scene import Scene
from .commands import SceneEdit
from .keyframes import tracks_following_items
from .messages import friendly_message

#: what is selected: ("camera",), ("render",), ("background",), ("lights", i), ("objects", i)
SelectionKey = tuple
CAMERA: SelectionKey = ("camera",)
RENDER: SelectionKey = ("render",)
BACKGROUND: SelectionKey = ("background",)
SINGLETONS = (CAMERA, RENDER, BACKGROUND)


class EditRefused(ValueError):
    """An edit the scene model rejects; the message is one short line for the field.
    ``validation`` keeps the model's error, so the panel can name the field its way."""

    def __init__(self, message: str, validation: ValidationError | None = None) -> None:
        super().__init__(message)
        self.validation = validation


def scene_fields(scene: Scene) -> dict[str, Any]:
    return {name: getattr(scene, name) for name in Scene.model_fields}


def rebuild_scene(scene: Scene, **update: Any) -> Scene:
    """A new validated scene with some top-level fields replaced; same base folder."""
    fields = scene_fields(scene)
    if "animation" not in update:  # tracks follow renamed, moved and deleted items
        update["animation"] = tracks_following_items(scene, update) or scene.animation
    fields.update(update)
    try:
        new = Scene(**fields)
    except ValidationError as exc:
        raise EditRefused(friendly_message(exc), exc) from None
    return new.with_base_dir(getattr(scene, "_base_dir", None))


def item_of(scene: Scene, key: SelectionKey | None) -> BaseModel | None:
    if key is None:
        return None
    if key in SINGLETONS:
        return getattr(scene, key[0])
    if len(key) >= 2 and key[0] in ("lights", "objects"):
        items = getattr(scene, key[0])
        if not 0 <= key[1] < len(items):
            return None
        item = items[key[1]]
        for k in key[2:]:  # ("objects", i, k, ...): a child of a CSG object, to any depth
            children = getattr(item, "objects", None)
            if children is None or not 0 <= k < len(children):
                return None
            item = children[k]
        return item
    return None


def _with_child(parent: BaseModel, path: tuple, item: BaseModel) -> BaseModel:
    """CSG object ``parent`` with its descendant at ``path`` replaced by ``item``."""
    if not path:
        return item
    children = list(parent.objects)
    children[path[0]] = _with_child(children[path[0]], path[1:], item)
    data = parent.model_dump()
    data["objects"] = [c.model_dump() for c in children]
    return type(parent).model_validate(data)


def with_item(scene: Scene, key: SelectionKey, item: BaseModel) -> Scene:
    """``scene`` with the item at ``key`` replaced by ``item``."""
    if key in SINGLETONS:
        return rebuild_scene(scene, **{key[0]: item})
    kind, index, *path = key
    items = list(getattr(scene, kind))
    items[index] = _with_child(items[index], tuple(path), item)
    return rebuild_scene(scene, **{kind: items})


def validate_like(model: BaseModel, data: dict[str, Any]) -> BaseModel:
    """A new model of ``model``'s class from ``data``; EditRefused with one line if invalid."""
    try:
        return type(model).model_validate(data)
    except ValidationError as exc:
        raise EditRefused(friendly_message(exc), exc) from None


def set_path(data: Any, path: tuple, value: Any) -> Any:
    """A deep copy of nested dicts/lists/tuples ``data`` with ``path`` set to ``value``
    (missing dicts on the way are created)."""
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(data, tuple):
        data = list(data)
    elif isinstance(data, dict | list):
        data = copy.copy(data)
    elif data is None:
        data = {}
    else:
        raise TypeError(f"cannot set {path} in {data!r}")
    child = data[head] if (isinstance(data, dict) and head in data) or isinstance(data, list) \
        else None
    data[head] = set_path(child, rest, value)
    return data


def get_path(data: Any, path: tuple) -> Any:
    for key in path:
        if data is None:
            return None
        if isinstance(data, BaseModel):
            data = getattr(data, key, None)
        elif isinstance(data, dict):
            data = data.get(key)
        else:
            data = data[key]
    return data


class SceneDocument(QObject):
    """The scene being edited. ``changed`` fires after every replacement (edit, undo, redo,
    open) with the key to select; ``reset`` after New/Open."""

    changed = Signal(object)  # selection key
    #: the one selection of the tree, the properties panel and the picture changed
    selection_changed = Signal(object)
    reset = Signal()
    path_changed = Signal()

    def __init__(self, scene: Scene | None = None, path: Path | None = None, parent=None):
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.undo_stack.setUndoLimit(500)
        self.scene: Scene = scene if scene is not None else Scene()
        self.path: Path | None = path
        self.selection: SelectionKey = CAMERA
        #: more selected lights and objects besides ``selection`` (the active one): Shift or
        #: Ctrl-click adds; G/R/S, Delete and Duplicate act on all of them
        self.extra: list[SelectionKey] = []
        self.revision = 0  # bumped on every scene replacement

    # ------------------------------------------------------------------ state

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

    def set_scene(self, scene: Scene, path: Path | None, *, dirty: bool = False) -> None:
        """Start over with ``scene`` (New, Open); forgets the undo history."""
        self.undo_stack.clear()
        self.scene = scene
        self.path = path
        self.selection = CAMERA
        self.extra = []
        self.revision += 1
        if dirty:  # a recovered autosave: not what the file on disk says
            self.undo_stack.resetClean()
        self.path_changed.emit()
        self.reset.emit()
        self.changed.emit(self.selection)
        self.selection_changed.emit(self.selection)

    def mark_saved(self, path: Path, scene: Scene) -> None:
        self.scene = scene
        self.path = path
        self.undo_stack.setClean()
        self.path_changed.emit()

    def show_pose(self, scene: Scene) -> None:
        """Make ``scene`` current without an undo step: the timeline posing the scene at a
        frame (the values its tracks drive), which is a view of the scene, not an edit."""
        self._replace(scene, self.selection)

    def item(self, key: SelectionKey | None = None) -> BaseModel | None:
        return item_of(self.scene, self.selection if key is None else key)

    def selected_keys(self) -> list[SelectionKey]:
        """Everything selected, the active item (``selection``) first."""
        keys = [self.selection] if self.selection is not None else []
        return keys + [k for k in self.extra if k != self.selection]

    def select(self, key: SelectionKey | list | None) -> None:
        """Select ``key`` (None or []: nothing; a list: all of them, the last one active);
        every view follows through ``selection_changed``."""
        keys = key if isinstance(key, list) else [] if key is None else [key]
        keys = [k for k in keys if item_of(self.scene, k) is not None]
        active = keys[-1] if keys else None
        extra = [k for k in keys[:-1] if len(k) == 2 and k != active]
        if active is not None and len(active) != 2:
            extra = []  # the camera, the settings, the background: alone
        if active != self.selection or extra != self.extra:
            self.selection, self.extra = active, extra
            self.selection_changed.emit(active)

    def toggle_selected(self, key: SelectionKey | None) -> None:
        """Shift/Ctrl-click: add a light or an object to the selection, or take it out."""
        if key is None or len(key) != 2:
            return
        keys = [k for k in self.selected_keys() if len(k) == 2]
        if key in keys:
            keys.remove(key)
        else:
            keys.append(key)
        self.select(keys)

    # ------------------------------------------------------------------ edits

    def apply(self, scene: Scene, text: str, *, select: SelectionKey | None = None,
              merge_key: object = None) -> bool:
        """Make ``scene`` (already validated) current as one undoable step."""
        if scene == self.scene:
            return False
        after = select if select is not None else self.selected_keys()
        self.undo_stack.push(SceneEdit(self, self.scene, scene, text,
                                       select_before=self.selected_keys(),
                                       select_after=after, merge_key=merge_key))
        return True

    def edit_item(self, key: SelectionKey, data: dict[str, Any], text: str, *,
                  merge_key: object = None, select: bool = True) -> None:
        """Replace the item at ``key`` by one built from ``data`` (and select it, unless
        ``select`` is False: moving the view keeps what is selected); raises EditRefused."""
        old = item_of(self.scene, key)
        if old is None:
            raise EditRefused("nothing selected")
        new_item = validate_like(old, data)
        self.apply(with_item(self.scene, key, new_item), text,
                   select=key if select else None, merge_key=merge_key)

    def set_field(self, key: SelectionKey, path: tuple, value: Any, text: str, *,
                  merge_key: object = None) -> None:
        old = item_of(self.scene, key)
        if old is None:
            raise EditRefused("nothing selected")
        data = old.model_dump()
        self.edit_item(key, set_path(data, path, value), text, merge_key=merge_key)

    def add(self, kind: str, item: BaseModel, text: str) -> SelectionKey:
        items = [*getattr(self.scene, kind), item]
        key = (kind, len(items) - 1)
        self.apply(rebuild_scene(self.scene, **{kind: items}), text, select=key)
        return key

    def delete(self, key: SelectionKey | list) -> bool:
        """Delete a light or an object (or each of a list of them) as one undo step; then
        nothing is selected (a second Delete removes nothing more)."""
        keys = [k for k in (key if isinstance(key, list) else [key])
                if k is not None and k not in SINGLETONS and item_of(self.scene, k) is not None]
        if not keys:
            return False
        update, names = {}, []
        for kind in ("lights", "objects"):
            gone = {i for k, i in keys if k == kind}
            if gone:
                items = getattr(self.scene, kind)
                update[kind] = [it for i, it in enumerate(items) if i not in gone]
                names += [label_of(items[i]) for i in sorted(gone)]
        text = f"Delete {names[0]}" if len(names) == 1 else f"Delete {len(names)} items"
        self.apply(rebuild_scene(self.scene, **update), text, select=[])
        return True

    def duplicate(self, key: SelectionKey) -> SelectionKey | None:
        item = item_of(self.scene, key)
        if key in SINGLETONS or item is None:
            return None
        kind, index = key
        names = {getattr(i, "name", None) for i in getattr(self.scene, kind)}
        copy_ = item.model_copy(update={"name": copy_name(item, names)}, deep=True)
        items = list(getattr(self.scene, kind))
        items.insert(index + 1, copy_)
        self.apply(rebuild_scene(self.scene, **{kind: items}), f"Duplicate {label_of(item)}",
                   select=(kind, index + 1))
        return (kind, index + 1)

    def rename(self, key: SelectionKey, name: str) -> None:
        item = item_of(self.scene, key)
        if key in SINGLETONS or item is None:
            return
        name = name.strip() or None
        if name == item.name:
            return
        self.set_field(key, ("name",), name, f"Rename {label_of(item)}")

    def _replace(self, scene: Scene, select: SelectionKey | list | None) -> None:
        """Called by the undo commands only. ``select``: a key, a list of keys (the last
        active; [] is nothing), or None to keep the selection."""
        self.scene = scene
        self.revision += 1
        before = (self.selection, list(self.extra))
        if isinstance(select, list):
            keys = [k for k in select if item_of(scene, k) is not None]
            self.selection = keys[0] if keys else None
            self.extra = keys[1:]
        elif select is not None and item_of(scene, select) is not None:
            self.selection, self.extra = select, []
        else:
            if self.selection is not None and item_of(scene, self.selection) is None:
                self.selection = None
            self.extra = [k for k in self.extra if item_of(scene, k) is not None]
        self.changed.emit(self.selection)
        if (self.selection, self.extra) != before:
            self.selection_changed.emit(self.selection)


def copy_name(item: Any, names: set) -> str:
    """A copy's name as Blender gives it: "ball.001", then "ball.002" (the copy of
    "ball.001" is "ball.002" too), the first not in ``names``."""
    base = re.sub(r"\.\d{3,}$", "", getattr(item, "name", None) or item.type)
    n = 1
    while f"{base}.{n:03d}" in names:
        n += 1
    return f"{base}.{n:03d}"


def label_of(item: Any) -> str:
    """How the tree and the undo history name an item."""
    name = getattr(item, "name", None)
    kind = getattr(item, "type", None)
    if name:
        return f"{name}"
    return f"{kind}" if kind else type(item).__name__
