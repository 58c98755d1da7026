"""scene/paths.py's refusals, one line each: paths written wrong, names that are ambiguous or
unknown, values that have no parts (of every kind), unset values that cannot be made, a mesh
whose materials come from its file, and a value whose material name the scene does not
know."""

from __future__ import annotations

import pytest

import whitted
from whitted.errors import PathError
from whitted.scene.paths import get_value, set_value


def _scene() -> whitted.Scene:
    return whitted.Scene(objects=[
        whitted.Sphere(radius=1, name="a"), whitted.Sphere(radius=2, name="a"),
        whitted.Mesh(file="m.obj", name="m"), whitted.Cylinder(radius=1, name="c"),
        whitted.Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]], name="v"),
    ], materials={"gold": whitted.Material()})


@pytest.mark.parametrize(("path", "message"), [
    ("objects[0]radius", "cannot read path 'objects[0]radius': '.' missing before 'radius'"),
    ("camera.", "cannot read path 'camera.': it ends with '.'"),
    ("", "empty path"),
    ("objects[a].radius", "objects[a]: 2 items are named 'a'; use an index"),
    ("materials[silver].kd", "materials[silver]: unknown name 'silver' (known: gold)"),
    ("render.transfer.x", "render.transfer.x: render.transfer is a value (text), it has no "
                          "parts"),
    ("camera.fov.x", "camera.fov.x: camera.fov is a value (a number), it has no parts"),
    ("objects[c].capped.x", "objects[c].capped.x: objects[c].capped is a value (true/false), "
                            "it has no parts"),
    ("objects[v].vertices.x", "objects[v].vertices.x: objects[v].vertices is a value "
                              "(ArrayData), it has no parts"),
    ("objects[m].material.kd", "objects[m].material: this mesh takes its materials from its "
                               "file; give it a material first"),
    ("camera.axis_angle.angle", "camera.axis_angle: is not set; set it whole first (e.g. "
                                "camera.axis_angle = {...})"),
])
def test_paths_that_name_nothing(path, message):
    with pytest.raises(PathError) as info:
        get_value(_scene(), path)
    assert str(info.value) == message


def test_unset_values_made_when_they_can_be():
    scene = _scene()
    assert get_value(scene, "render.antialias.threshold") == 0.3  # a default Antialias
    assert get_value(scene, "objects[c].transform.scale") == 1.0
    assert set_value(scene, "render.antialias.threshold", 0.5).render.antialias.threshold == 0.5


def test_a_value_naming_a_material_the_scene_does_not_know():
    with pytest.raises(PathError) as info:
        set_value(whitted.Scene(), "objects", [{"type": "sphere", "radius": 1,
                                                "material": "nope"}])
    assert str(info.value) == ("objects[0].material: unknown material 'nope' (known: chrome, "
                               "glass, ice, matte, mirror, plastic, water)")
