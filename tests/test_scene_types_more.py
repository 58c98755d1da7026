"""scene/types.py: transforms with a zero scale (a number or one axis of three), NumPy vectors
taken as lists, non-finite numbers deep in a model, and assignments checked like
construction; each problem one line naming the field's path."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whitted.errors import SceneError
from whitted.scene import Scene, Sphere, Transform


@pytest.mark.parametrize(("make", "message"), [
    (lambda: Transform(scale=0), "Transform.scale: scale must not be zero (got 0)"),
    (lambda: Transform(scale=(1, 0, 1)), "Transform.scale: scale must not be zero"),
    (lambda: Transform(axis_angle={"axis": [0, 1, 0], "angle": math.inf}),
     "Transform.axis_angle.angle: expected a finite number, got inf"),
    (lambda: setattr(Sphere(radius=1), "radius", -1),
     "Sphere.radius: input should be greater than 0 (got -1)"),
    (lambda: Scene.model_validate({"objects": [{"type": "sphere", "radius": -1}]}),
     "Scene.objects[0].radius: input should be greater than 0 (got -1)"),
    (lambda: Sphere.model_validate({"radius": "x"}), "Sphere.radius: expected a number (got 'x')"),
])
def test_one_line_problems(make, message):
    with pytest.raises(SceneError) as info:
        make()
    assert str(info.value) == message


def test_numpy_vectors_are_lists():
    sphere = Sphere(center=np.array([1.0, 2, 3]), radius=1)
    assert sphere.center == (1.0, 2.0, 3.0) and type(sphere.center[0]) is float
