"""scene/shapes.py: every shape's own checks, each a one-line error naming the shape and the
problem; the array fields of inline meshes (what they accept and refuse); CSG's solid-only
children and its size bound; the tree a CSG object lists."""

from __future__ import annotations

import numpy as np
import pytest

from whitted import scene as S
from whitted.errors import SceneError
from whitted.scene.shapes import ArrayData

TRI = {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "faces": [[0, 1, 2]]}

CASES = [
    (S.Rectangle, {"corner": (0, 0, 0), "edge1": (1, 0, 0), "edge2": (2, 0, 0)},
     "Rectangle: edge1 and edge2 are parallel: the rectangle has no area"),
    (S.Triangle, {"vertices": ((0, 0, 0), (1, 1, 1), (2, 2, 2))},
     "Triangle: the three vertices are collinear: the triangle has no area"),
    (S.Box, {}, "Box: give either corner + edges, or min + max"),
    (S.Box, {"min": (0, 0, 0), "edges": ((1, 0, 0), (0, 1, 0), (0, 0, 1))},
     "Box: give either corner + edges, or min + max"),
    (S.Box, {"corner": (0, 0, 0)}, "Box: corner and edges go together"),
    (S.Box, {"max": (1, 1, 1)}, "Box: min and max go together"),
    (S.Box, {"min": (0, 0, 0), "max": (1, 0, 1)},
     "Box: max must be greater than min on every axis"),
    (S.Box, {"corner": (0, 0, 0), "edges": ((1, 0, 0), (0, 1, 0), (1, 1, 0))},
     "Box: the three edges are coplanar: the box has no volume"),
    (S.Cylinder, {"base": (1, 2, 3), "top": (1, 2, 3), "radius": 1},
     "Cylinder: base and top coincide: zero height"),
    (S.Cone, {"top": (0, 0, 0), "radius": 1}, "Cone: base and top coincide: zero height"),
    (S.Mesh, {"vertices": [[0, 0, 0]], "faces": [[0, 0, 1]]},
     "Mesh: faces index vertices 0..0; found 0..1"),
    (S.Mesh, {"vertices": [[0, 0, 0]]}, "Mesh: vertices and faces go together"),
    (S.Mesh, {"file": "a.obj", **TRI}, "Mesh: give either file, or vertices + faces"),
    (S.Mesh, {}, "Mesh: give either file, or vertices + faces"),
    (S.Mesh, {"file": "a.obj", "normals": [[0, 0, 1]]},
     "Mesh: normals and uvs go with vertices + faces, not with file"),
    (S.Mesh, {**TRI, "uvs": [[0, 0], [1, 1]]}, "Mesh: uvs has 2 rows, vertices has 3"),
    (S.Mesh, {**TRI, "normals": [[0, 0, 1]] * 4}, "Mesh: normals has 4 rows, vertices has 3"),
    (S.Mesh, {"vertices": [[0, 0, True]], "faces": [[0, 0, 0]]},
     "Mesh.vertices: expected rows of 3 numbers, not true/false"),
    (S.Mesh, {"vertices": [[0, 0, 0]], "faces": [[0, 0, 0.5]]},
     "Mesh.faces: indices must be whole numbers"),
    (S.Mesh, {"vertices": [[0, 0, "x"]], "faces": [[0, 0, 0]]},
     "Mesh.vertices: expected rows of 3 numbers (no text, booleans or ragged rows)"),
    (S.Mesh, {"vertices": [[0, 0, 0]], "faces": np.array([[0, 0, 2**70]], dtype=object)},
     "Mesh.faces: expected rows of 3 whole numbers (no text, booleans or ragged rows)"),
    (S.Mesh, {"vertices": [[0, 0, 0]], "faces": [[0, 0, 2**70]]},
     "Mesh: faces: number 1180591620717411303424 is too large (scene values are limited to "
     "1e+15 in magnitude)"),
    (S.Mesh, {"vertices": [[0, 0]], "faces": [[0, 0, 0]]},
     "Mesh.vertices: expected rows of 3 numbers, got shape (1, 2)"),
    (S.Mesh, {"vertices": [[0, 0, float("nan")]], "faces": [[0, 0, 0]]},
     "Mesh.vertices: values must be finite"),
    (S.Mesh, {"vertices": np.array([[0, 0, 1e300]]), "faces": [[0, 0, 0]]},
     "Mesh.vertices: a value is too large (scene values are limited to 1e+15 in magnitude)"),
    (S.Mesh, {"vertices": [[0, 0, 0], [0, 0]], "faces": [[0, 0, 0]]},
     "Mesh.vertices: expected a list of [3 numbers] rows"),
    (S.Mesh, {"vertices": [[0, 0, 0]], "faces": [[0, 0, 0]], "uvs": [1, 2]},
     "Mesh.uvs: expected rows of 2 numbers, got shape (2,)"),
    (S.CSG, {"operation": "union", "objects": [S.Plane()]},
     "CSG: objects[0] (plane): a plane bounds no volume, so it cannot take part in CSG"),
    (S.CSG, {"operation": "merge", "objects": [S.Sphere(radius=1), S.Cylinder(
        radius=1, capped=False, name="tube")]},
     "CSG: objects[1] (tube): an uncapped cylinder is open, so it cannot take part in CSG"),
    (S.CSG, {"operation": "union", "objects": [S.Mesh(**TRI, solid=False)]},
     "CSG: objects[0] (mesh): a mesh with solid = false bounds no volume, so it cannot take "
     "part in CSG"),
    (S.CSG, {"operation": "union", "objects": [S.Sphere(radius=1)] * 64},
     "CSG: a CSG object holds at most 63 solids and operations together; this one has 64 "
     "solids in 1 operation, nested 1 deep"),
    (S.CSG, {"operation": "union", "objects": [S.CSG(operation="union", objects=[
        S.Sphere(radius=1)] * 31)] * 2},
     "CSG: a CSG object holds at most 63 solids and operations together; this one has 62 "
     "solids in 3 operations, nested 2 deep"),
]


@pytest.mark.parametrize(("cls", "fields", "message"), CASES,
                         ids=[f"{c[0].__name__}-{k}" for k, c in enumerate(CASES)])
def test_each_check_is_one_line(cls, fields, message):
    with pytest.raises(SceneError) as info:
        cls(**fields)
    assert str(info.value) == message


def test_a_model_file_that_is_not_there():
    with pytest.raises(SceneError) as info:
        S.Mesh.from_file("/nonexistent/a.obj", material="matte")
    assert str(info.value) == "/nonexistent/a.obj: no such file"


def test_a_model_file_that_is_there(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\n")
    mesh = S.Mesh.from_file(path, material="matte", smooth=True)
    assert (mesh.file, mesh.material, mesh.smooth) == (str(path), "matte", True)


def test_array_data_compares_hashes_and_converts_by_value():
    a = ArrayData(np.array([[0, 1, 2]], np.int64))
    b = ArrayData(np.array([[0, 1, 2]], np.int64))
    c = ArrayData(np.array([[0, 1, 3]], np.int64))
    assert a == b and hash(a) == hash(b) and a != c
    assert a != ArrayData(np.array([0, 1, 2], np.int64))  # another shape
    assert a.__eq__([[0, 1, 2]]) is NotImplemented and len(a) == 1
    assert not a.array.flags.writeable
    assert np.asarray(a, dtype=np.float32).dtype == np.float32
    assert np.asarray(a) is a.array
    assert repr(a) == "ArrayData(shape=(1, 3), dtype=int64)"
    mesh = S.Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=a)
    assert mesh.faces == a
    assert mesh.model_dump()["faces"] == [[0, 1, 2]]
    empty = S.Mesh(vertices=[], faces=[])
    assert empty.vertices.array.shape == (0, 3) and empty.faces.array.shape == (0, 3)


def test_the_tree_of_a_csg_object():
    inner = S.CSG(operation="intersection", name="core", material="glass",
                  objects=[S.Sphere(radius=1), S.Box(min=(0, 0, 0), max=(1, 1, 1),
                                                     material=S.Material(kr=0.5))])
    body = S.CSG(operation="difference", objects=[S.Sphere(radius=2, name="ball"), inner])
    assert (body.leaves(), body.rows()) == (3, 5)
    assert body.tree_lines(indent="  ") == [
        "  objects[0] sphere 'ball' material=inherited",
        "  objects[1] csg intersection 'core' material=glass",
        "    objects[1].objects[0] sphere material=inherited",
        "    objects[1].objects[1] box material=inline",
    ]
