"""The editor's tree shows a CSG object as a node with its children, to any depth; a child
can be selected, edited (an undoable step) and renamed."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest  # noqa: E402

pytest.importorskip("PySide6.QtWidgets")

import whitted  # noqa: E402
from whitted.gui.document import SceneDocument, item_of  # noqa: E402
from whitted.gui.tree import KEY_ROLE, SceneTree  # noqa: E402


def _die_scene():
    return whitted.Scene(objects=[
        whitted.Sphere(radius=0.5, center=(3, 0, 0)),
        whitted.CSG(name="die", operation="difference", objects=[
            whitted.CSG(operation="intersection", objects=[
                whitted.Box(min=(-1, -1, -1), max=(1, 1, 1)), whitted.Sphere(radius=1.35)]),
            whitted.Sphere(name="pip", center=(0, 0, 1), radius=0.2)]),
    ])


def test_the_tree_shows_the_csg_children(qtbot):
    doc = SceneDocument(_die_scene())
    tree = SceneTree(doc)
    qtbot.addWidget(tree)
    keys = [item.data(0, KEY_ROLE) for item in tree._items()]
    assert ("objects", 1) in keys
    assert ("objects", 1, 0) in keys and ("objects", 1, 0, 1) in keys
    assert ("objects", 1, 1) in keys
    node = tree.item_for(("objects", 1, 1))
    assert node.text(0) == "pip  (sphere)"
    assert node.parent() is tree.item_for(("objects", 1))
    assert item_of(doc.scene, ("objects", 1, 0, 1)).radius == 1.35
    assert item_of(doc.scene, ("objects", 1, 5)) is None


def test_a_child_is_selected_edited_and_renamed(qtbot):
    doc = SceneDocument(_die_scene())
    tree = SceneTree(doc)
    qtbot.addWidget(tree)
    tree.setCurrentItem(tree.item_for(("objects", 1, 0, 1)))
    assert doc.selection == ("objects", 1, 0, 1)
    doc.set_field(("objects", 1, 0, 1), ("radius",), 1.5, "Ball radius")
    assert doc.scene.objects[1].objects[0].objects[1].radius == 1.5
    assert doc.scene.objects[1].objects[1].radius == 0.2  # its siblings as they were
    doc.rename(("objects", 1, 1), "one pip")
    assert tree.item_for(("objects", 1, 1)).text(0) == "one pip  (sphere)"
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert doc.scene.objects[1].objects[0].objects[1].radius == 1.35
