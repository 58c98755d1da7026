"""The editor's tree shows a CSG object as a node with its children, to any depth; a child
can be selected, edited (an undoable step) and renamed."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest  # noqa: E402

pytest.importorskip("PySide6.QtWidgets")

import whitted  # noqa: E402
from gui_input import make_window  # noqa: E402, F401
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


def _turned_die_window(make_window):  # noqa: F811
    """The die turned 90 degrees about y and moved, in a small starter scene: its pip's
    transform is in the die's space, whose x is the world's -z."""
    from whitted.gui.main_window import starter_scene

    die = _die_scene().objects[1].model_copy(update={"transform": whitted.Transform(
        rotate=(0.0, 90.0, 0.0), translate=(0.5, 0.5, 0.0))})
    scene = starter_scene().with_settings(width=160, height=120)
    scene = scene.model_copy(update={"objects": [*scene.objects, die]})
    return make_window(scene, preview=False, warm_up=False), ("objects", len(scene.objects) - 1)


def test_g_r_s_move_turn_and_scale_a_csg_child(make_window, qtbot):  # noqa: F811
    import numpy as np
    from PySide6.QtCore import Qt

    from gui_input import click_tree, mouse  # noqa: I001

    window, die = _turned_die_window(make_window)
    tree, vp = window.tree, window.viewport
    pip, body = (*die, 1), (*die, 0, 0)
    click_tree(qtbot, tree, pip)
    assert window.doc.selection == pip
    centre = vp.picture_rect().center()
    mouse(vp, "move", centre, Qt.MouseButton.NoButton)
    steps = window.doc.undo_stack.count()
    # G X 1 Enter: the pip (a ball placed by its centre) moves one unit along the die's x
    qtbot.keyClick(tree, Qt.Key.Key_G)
    assert vp.tool is not None
    qtbot.keyClick(vp, Qt.Key.Key_X)
    qtbot.keyClicks(vp, "1")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    assert vp.tool is None and window.doc.selection == pip
    assert window.doc.item(pip).center == pytest.approx((1.0, 0.0, 1.0))
    assert window.doc.item(die).objects[0] == _die_scene().objects[1].objects[0]  # its sibling
    assert window.doc.undo_stack.count() == steps + 1
    # G by the pointer: the pip follows it on the ground, in world space, whatever the turn
    qtbot.keyClick(tree, Qt.Key.Key_G)
    tool = vp.tool
    mouse(vp, "move", centre + type(centre)(30, 12), Qt.MouseButton.NoButton)
    world_move = tool.lead._ground_delta()
    mouse(vp, "press", centre + type(centre)(30, 12))
    mouse(vp, "release", centre + type(centre)(30, 12))
    assert vp.tool is None
    assert np.linalg.norm(world_move) > 0.05 and abs(world_move[1]) < 1e-9
    m = window.doc.item(die).transform.matrix()
    moved = m[:3, :3] @ (np.array(window.doc.item(pip).center) - (1.0, 0.0, 1.0))
    np.testing.assert_allclose(moved, world_move, atol=2e-6)
    # R 90 Enter on the box inside the die's intersection: turned about the die's y
    click_tree(qtbot, tree, body)
    qtbot.keyClick(tree, Qt.Key.Key_R)
    qtbot.keyClicks(vp, "90")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    turned = window.doc.item(body).transform
    assert turned.rotate == pytest.approx((0.0, 90.0, 0.0))
    # S 2 Enter: twice the size about its centre (the die's origin)
    qtbot.keyClick(tree, Qt.Key.Key_S)
    qtbot.keyClicks(vp, "2")
    qtbot.keyClick(vp, Qt.Key.Key_Return)
    grown = window.doc.item(body).transform
    assert grown.scale == pytest.approx(2.0) and grown.translate == pytest.approx((0, 0, 0))
    assert window.errors == []
    # each a step of its own; undone, the die is as it was
    for _ in range(4):
        qtbot.keyClick(tree, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.doc.item(die).objects == _die_scene().objects[1].objects
