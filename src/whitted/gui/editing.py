"""Edits of the selection: G/R/S (on every selected object and light at once, one undo
step), Delete, Duplicate, Rename, the Add menus, and picking in the picture (a click selects,
Shift or Ctrl-click adds or takes out). These act on the document's selection wherever the
keyboard focus is, and never change what is selected (except Delete: nothing is selected
after it)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, Qt

from ..errors import WhittedError
from . import catalog
from .document import EditRefused, copy_name, item_of, label_of, rebuild_scene, with_item
from .picking import id_at
from .transform_tool import TransformTool, light_position


def _moves_its_centre(obj) -> bool:
    """A shape with a ``center`` and no transform of its own: G moves the centre."""
    return getattr(obj, "center", None) is not None and getattr(obj, "transform", 1) is None


class GroupTool:
    """One G/R/S operation on several items: a :class:`TransformTool` per item gets the
    same pointer and keys; their results make one edit (``commit(results, merge_key, group)``)."""

    def __init__(self, mode: str, scene, keys: list, start, size, commit, finish,
                 status) -> None:
        self.mode = mode
        self.keys = keys
        self.results: dict = {}
        self._commit, self._finish = commit, finish
        self.done = False
        self.tools = []
        for n, key in enumerate(keys):
            self.tools.append(TransformTool(
                mode, scene, key[1], start, size, kind=key[0], path=tuple(key[2:]),
                finish=lambda *a: None,
                apply=lambda value, merge, k=key: self.results.__setitem__(k, value),
                status=status if n == 0 else (lambda text: None)))
        if mode in ("rotate", "scale") and len(self.tools) > 1:
            # several objects turn and grow about their median point (Blender's default
            # pivot), not each about its own centre
            median = np.mean([t.centre for t in self.tools], axis=0)
            for t in self.tools:
                t.centre = median
                t.own_centre = np.linalg.solve(t.parent[:3, :3], median - t.parent[:3, 3])
        self.merge_key = self.tools[0].merge_key
        self.start_uv = self.uv = None

    @property
    def lead(self) -> TransformTool:
        return self.tools[0]

    @property
    def centre(self):
        return self.lead.centre

    def _apply(self) -> None:
        if self.results:
            self._commit(dict(self.results), self.merge_key, self)

    def set_start(self, uv) -> None:
        for tool in self.tools:
            tool.start_uv = tool.uv = uv

    def move(self, pos, uv) -> None:
        for tool in self.tools:
            tool.move(pos, uv)
        self._apply()

    def wants(self, event) -> bool:
        """The keys a running move takes before the window's shortcuts (X, Y, Z, digits,
        Enter, Esc, Backspace...)."""
        k = event.key()
        return k in (Qt.Key.Key_Escape, Qt.Key.Key_Return, Qt.Key.Key_Enter,
                     Qt.Key.Key_Backspace, Qt.Key.Key_X, Qt.Key.Key_Y, Qt.Key.Key_Z) or \
            bool(event.text()) and (event.text().isdigit() or event.text() in ".-")

    def key(self, event) -> bool:
        if event.key() == Qt.Key.Key_Escape:
            self.cancel()
            return True
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.confirm()
            return True
        handled = False
        for tool in self.tools:
            handled = tool.key(event) or handled
        if handled:
            self._apply()
        return handled

    def confirm(self) -> None:
        if self.done:
            return
        for tool in self.tools:
            if tool.typed:
                tool.update()
        self._apply()
        self.done = True
        self._finish(True, self)

    def cancel(self) -> None:
        if self.done:
            return
        self.done = True
        self._finish(False, self)


class Editing(QObject):
    def __init__(self, window) -> None:
        super().__init__(window)
        self.window_ = window
        self.doc = window.doc
        self._tool_edits = 0

    def _status(self, text: str, ms: int = 0) -> None:
        self.window_.statusBar().showMessage(text, ms)

    # ------------------------------------------------------------------ G, R, S

    def move(self) -> bool:
        return self.start_tool("move")

    def rotate(self) -> bool:
        return self.start_tool("rotate")

    def scale(self) -> bool:
        return self.start_tool("scale")

    def start_tool(self, mode: str) -> bool:
        """Start moving, rotating or scaling the selected objects (and, moving, the lights
        that have a place) from where the pointer is; the picture takes the keys."""
        window = self.window_
        viewport = window.viewport
        if viewport.tool is not None:
            return False
        # objects, the children of CSG objects (keys ("objects", i, k, ...)), and to move,
        # the lights that have a place
        keys = [k for k in self.doc.selected_keys() if len(k) >= 2 and (
            k[0] == "objects" or len(k) == 2 and mode == "move"
            and light_position(self.doc.item(k)) is not None)]
        if not keys:
            what = "an object" if mode != "move" else "an object or a light"
            self._status(f"{TransformTool.NAMES[mode]}: select {what} first", 3000)
            return False
        start = viewport.hover
        if viewport.to_picture(start) is None:
            start = viewport.picture_rect().center()
        scene = self.doc.scene.model_copy(update={"camera": window.navigation.camera()})
        tool = GroupTool(mode, scene, keys, start, (viewport.width(), viewport.height()),
                         commit=lambda results, merge, group: self._tool_edit(results, merge, mode,
                                                                      group),
                         finish=self._tool_finished,
                         status=lambda text: self._status(text))
        tool.set_start(viewport.to_picture(start))
        viewport.tool = tool
        viewport.setFocus()  # its keys (X, Y, Z, a typed value, Enter) go to the picture
        self._tool_edits = 0
        window.interacting(True)
        return True

    def _tool_edit(self, results: dict, merge, mode: str, tool: GroupTool) -> None:
        scene = self.doc.scene
        update = {kind: list(getattr(scene, kind)) for kind in ("lights", "objects")}
        children = {}  # the CSG children's new items, put in place after the rest
        for key, value in results.items():
            kind, index = key[:2]
            item = item_of(scene, key)
            data = item.model_dump()
            sub = next(t for t in tool.tools if (t.kind, t.index, *t.path) == key)
            if kind == "lights":  # a light moves by the vector, from where it was at the start
                field = "position" if "position" in data else "center"
                data[field] = tuple(round(float(v), 6) + 0.0 for v in sub.centre + value)
            elif mode == "move" and _moves_its_centre(sub.obj):
                # a shape placed by its centre moves its centre: the panel shows where it is
                data["center"] = tuple(round(float(c + t), 6) + 0.0 for c, t in zip(
                    sub.obj.center, value.translate, strict=True))
            else:
                data["transform"] = value.model_dump()
            if len(key) > 2:
                children[key] = type(item).model_validate(data)
            else:
                update[kind][index] = type(item).model_validate(data)
        names = [label_of(item_of(scene, key)) for key in results]
        what = names[0] if len(names) == 1 else f"{len(names)} items"
        try:
            before = self.doc.undo_stack.index()
            new = rebuild_scene(scene, **update)
            for key, item in children.items():
                new = with_item(new, key, item)
            self.doc.apply(new, f"{TransformTool.NAMES[mode]} {what}", merge_key=merge)
            self._tool_edits += self.doc.undo_stack.index() != before or self._tool_edits > 0
        except (EditRefused, ValueError) as exc:
            self._status(str(exc).splitlines()[0], 3000)

    def _tool_finished(self, confirmed: bool, tool) -> None:
        window = self.window_
        window.viewport.tool = None
        window.interacting(False)
        if not confirmed and self._tool_edits:
            stack = self.doc.undo_stack
            command = stack.command(stack.index() - 1)
            if command is not None and getattr(command, "merge_key", None) == tool.merge_key:
                command.forget_on_undo = True  # no redo of a cancelled move
                stack.undo()
        self._status("" if confirmed else "Cancelled", 2000)
        window.viewport.update()

    # ------------------------------------------------------------------ the selection

    def _items(self) -> list:
        return [k for k in self.doc.selected_keys() if len(k) == 2]

    def delete_selected(self) -> bool:
        if self.window_.viewport.tool is not None:
            return False
        return self.doc.delete(self._items())

    def duplicate_selected(self):
        keys = self._items()
        if len(keys) <= 1:
            return self.doc.duplicate(self.doc.selection)
        scene = self.doc.scene
        update = {kind: list(getattr(scene, kind)) for kind in ("lights", "objects")}
        new_keys = []
        for kind in ("lights", "objects"):
            names = {getattr(i, "name", None) for i in update[kind]}
            for index in sorted(i for k, i in keys if k == kind):
                item = getattr(scene, kind)[index]
                name = copy_name(item, names)
                names.add(name)
                update[kind].append(item.model_copy(update={"name": name}, deep=True))
                new_keys.append((kind, len(update[kind]) - 1))
        self.doc.apply(rebuild_scene(scene, **update), f"Duplicate {len(keys)} items",
                       select=new_keys)
        return new_keys

    def duplicate_and_grab(self):
        """Shift+D (and Ctrl+D): duplicate the selection, then move the copies with the
        mouse as G does (Esc or a right-click leaves them on the originals)."""
        if self.window_.viewport.tool is not None:
            return None
        keys = self.duplicate_selected()
        if keys:
            self.start_tool("move")
        return keys

    def select_all(self) -> None:
        """A: every light and object (the active one stays active when it is one of them)."""
        scene = self.doc.scene
        keys = [(kind, i) for kind in ("lights", "objects")
                for i in range(len(getattr(scene, kind)))]
        active = self.doc.selection
        if active in keys:
            keys.remove(active)
            keys.append(active)
        self.doc.select(keys)

    def rename_selected(self) -> None:
        key = self.doc.selection
        tree = self.window_.tree
        item = tree.item_for(key) if key is not None else None
        if item is not None and len(key) == 2:
            tree.editItem(item, 0)

    def _in_view(self):
        """The scene as the picture shows it (new things go where the view looks)."""
        return self.doc.scene.model_copy(update={"camera": self.window_.navigation.camera()})

    def add_object(self, kind: str) -> tuple:
        obj = catalog.new_object(self._in_view(), kind)
        return self.doc.add("objects", obj, f"Add {kind}")

    def add_light(self, kind: str) -> tuple:
        light = catalog.new_light(self._in_view(), kind)
        return self.doc.add("lights", light, f"Add {kind} light")

    def add_model(self, path: Path | None = None) -> tuple | None:
        window = self.window_
        if path is None:
            from .fields import MODEL_FILTER

            name = window.choose_file("Add a model", MODEL_FILTER)
            if not name:
                return None
            path = Path(name)
        try:
            obj = catalog.new_model(self._in_view(), Path(path))
        except (ValueError, EditRefused) as exc:
            window.show_error("Cannot add the model", str(exc))
            return None
        scale = obj.transform.scale if obj.transform is not None else 1.0
        if scale != 1.0:
            self._status(f"{Path(path).name} was scaled by {scale:g} to a sensible size "
                         "(Placement > Scale)", 8000)
        return self.doc.add("objects", obj, f"Add model {Path(path).name}")

    # ------------------------------------------------------------------ pointing

    def pick(self, u: float, v: float, modifiers=None) -> tuple | None:
        """A click on the picture at (u, v): select the object seen there (through the
        renderer's object-id image) or the light mark; a click on the background
        deselects. With Shift or Ctrl the item is added to the selection (or taken out)."""
        if not (0 <= u <= 1 and 0 <= v <= 1):
            return None
        window = self.window_
        try:
            ids = window.ids.ids_for(window.shown_scene())
        except WhittedError as exc:
            self._status(f"Cannot pick: {exc}", 4000)
            return None
        light = window.overlays.light_at(u, v)
        index = id_at(ids, u, v)
        key = light if light is not None else ("objects", index) if index >= 0 else None
        extend = modifiers is not None and bool(modifiers & (
            Qt.KeyboardModifier.ShiftModifier | Qt.KeyboardModifier.ControlModifier))
        if extend:
            self.doc.toggle_selected(key)
        else:
            self.doc.select(key)
        return key


__all__ = ["Editing", "GroupTool"]
