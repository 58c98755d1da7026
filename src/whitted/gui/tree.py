"""The scene tree: Camera, Render settings, Background, then the lights and the objects.
Selecting an item selects it in the document (the properties panel follows); Shift or
Ctrl-click selects more lights and objects; double-click or F2 renames one in place. Letters
typed here do not jump to a row (no type-to-find): they are the window's shortcuts (G moves
the selection, wherever the focus is)."""

from __future__ import annotations

from PySide6.QtCore import QItemSelectionModel, Qt, QTimer, Signal
from PySide6.QtWidgets import QAbstractItemView, QTreeWidget, QTreeWidgetItem

from .document import BACKGROUND, CAMERA, RENDER, SceneDocument, label_of
from .icons import icon_for

KEY_ROLE = Qt.ItemDataRole.UserRole


class SceneTree(QTreeWidget):
    selected = Signal(object)  # selection key

    def __init__(self, doc: SceneDocument, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.setHeaderHidden(True)
        # a long name is cut with "…" in the middle, never widening the panel
        self.setTextElideMode(Qt.TextElideMode.ElideMiddle)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.header().setStretchLastSection(True)
        self.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.DoubleClicked
                             | QAbstractItemView.EditTrigger.EditKeyPressed)
        self.setContextMenuPolicy(Qt.ContextMenuPolicy.ActionsContextMenu)
        self._filling = False
        self.itemSelectionChanged.connect(self._selection_changed)
        self.itemChanged.connect(self._renamed)
        doc.changed.connect(self.fill)
        doc.selection_changed.connect(self.select_key)
        self.fill()

    def fill(self, *_: object) -> None:
        """Rebuild the tree from the document's scene and select the document's selection
        (only the texts change when the lists keep their lengths)."""
        scene = self.doc.scene
        shape = (len(scene.lights), len(scene.objects), self._csg_shape())
        if shape == getattr(self, "_shape", None):
            self._update_texts()
            return
        self._shape = shape
        self._filling = True
        try:
            expanded = {self.topLevelItem(i).text(0).split(" ")[0]: self.topLevelItem(i)
                        .isExpanded() for i in range(self.topLevelItemCount())}
            self.clear()
            for key, text in ((CAMERA, "Camera"), (RENDER, "Render settings"),
                              (BACKGROUND, "Background")):
                item = QTreeWidgetItem([text])
                item.setData(0, KEY_ROLE, key)
                item.setIcon(0, icon_for(key[0]))
                self.addTopLevelItem(item)
            for kind, title in (("lights", "Lights"), ("objects", "Objects")):
                items = getattr(scene, kind)
                group = QTreeWidgetItem([f"{title} ({len(items)})"])
                group.setData(0, KEY_ROLE, None)
                group.setFlags(group.flags() & ~Qt.ItemFlag.ItemIsSelectable)
                self.addTopLevelItem(group)
                for i, obj in enumerate(items):
                    child = QTreeWidgetItem([self.text_of(obj)])
                    child.setData(0, KEY_ROLE, (kind, i))
                    child.setIcon(0, icon_for(obj.type if kind == "objects" else
                                              f"light:{obj.type}"))
                    child.setToolTip(0, f"{obj.type} {'light' if kind == 'lights' else ''}")
                    child.setFlags(child.flags() | Qt.ItemFlag.ItemIsEditable)
                    group.addChild(child)
                    if kind == "objects" and obj.type == "csg":
                        self._add_csg_children(child, obj, (kind, i))
                group.setExpanded(expanded.get(title, True))
        finally:
            self._filling = False
        self.select_key()

    def _add_csg_children(self, node: QTreeWidgetItem, csg, key: tuple) -> None:
        """A CSG object's children under its node, keyed ("objects", i, k, ...), to any
        depth (expanded: the tree of the solid shows at once)."""
        for k, obj in enumerate(csg.objects):
            child = QTreeWidgetItem([self.text_of(obj)])
            child.setData(0, KEY_ROLE, (*key, k))
            child.setIcon(0, icon_for(obj.type))
            child.setToolTip(0, f"{obj.type} in {csg.operation}")
            child.setFlags(child.flags() | Qt.ItemFlag.ItemIsEditable)
            node.addChild(child)
            if obj.type == "csg":
                self._add_csg_children(child, obj, (*key, k))
        node.setExpanded(True)

    def _items(self):
        """Every item of the tree, depth first."""
        stack = [self.topLevelItem(i) for i in range(self.topLevelItemCount())][::-1]
        while stack:
            item = stack.pop()
            yield item
            stack.extend(item.child(j) for j in range(item.childCount() - 1, -1, -1))

    def _csg_shape(self) -> tuple:
        """The children counts of every CSG object (a change rebuilds the tree)."""
        def counts(obj):
            if obj.type != "csg":
                return ()
            return (len(obj.objects), *(counts(c) for c in obj.objects))
        return tuple(counts(obj) for obj in self.doc.scene.objects)

    def _update_texts(self) -> None:
        self._filling = True
        try:
            for child in self._items():
                key = child.data(0, KEY_ROLE)
                if key is None or child.parent() is None:
                    continue
                obj = self.doc.item(key)
                if obj is not None and child.text(0) != self.text_of(obj):
                    child.setText(0, self.text_of(obj))
        finally:
            self._filling = False
        self.select_key()

    @staticmethod
    def text_of(obj) -> str:
        name = label_of(obj)
        return name if name == obj.type else f"{name}  ({obj.type})"

    def item_for(self, key) -> QTreeWidgetItem | None:
        for item in self._items():
            if item.data(0, KEY_ROLE) == key:
                return item
        return None

    def keyboardSearch(self, search: str) -> None:  # noqa: N802 - Qt's name
        """No type-to-find: a letter never changes the selection."""

    def select_key(self, *_: object) -> None:
        """Show the document's selection (all of it; its active item current)."""
        keys = self.doc.selected_keys()
        wanted = {id(it): it for k in keys if (it := self.item_for(k)) is not None}
        if {id(it) for it in self.selectedItems()} == set(wanted) and (
                not keys or self.currentItem() is self.item_for(keys[0])):
            return
        self._filling = True
        try:
            self.clearSelection()
            active = self.item_for(keys[0]) if keys else None
            if active is not None:
                self.setCurrentItem(active, 0,
                                    QItemSelectionModel.SelectionFlag.NoUpdate)
            for item in wanted.values():
                item.setSelected(True)
        finally:
            self._filling = False

    def _selection_changed(self) -> None:
        if self._filling:
            return
        keys = [k for it in self.selectedItems() if (k := it.data(0, KEY_ROLE)) is not None]
        current = self.currentItem()
        active = current.data(0, KEY_ROLE) if current is not None else None
        if active in keys:  # the clicked row is the active one (the document's last)
            keys.remove(active)
            keys.append(active)
        if len(keys) > 1:
            keys = [k for k in keys if len(k) == 2] or keys[-1:]
        before = self.doc.selected_keys()
        self.doc.select(keys)  # the properties panel follows through the document
        if keys and self.doc.selected_keys() != before:
            self.selected.emit(keys[-1])

    def _renamed(self, item: QTreeWidgetItem, column: int) -> None:
        if self._filling:
            return
        key = item.data(0, KEY_ROLE)
        if key is None or len(key) < 2:
            return
        text = item.text(0).strip()
        # after the editor has closed: renaming rebuilds the tree
        QTimer.singleShot(0, lambda: self._rename(key, text))

    def _rename(self, key, text: str) -> None:
        obj = self.doc.item(key)
        if obj is None:
            return
        suffix = f"  ({obj.type})"  # "name  (type)" as shown: keep only the name part
        name = text[: -len(suffix)] if text.endswith(suffix) else text
        if text != self.text_of(obj):
            self.doc.rename(key, name)
        self._update_texts()  # an unchanged name: show the model's text again
