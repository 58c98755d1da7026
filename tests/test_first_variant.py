"""Which kernels a first render compiles first: a scene that certainly runs the general
kernels (a torus, a CSG object) compiles only those, not the plain ones before them."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.compile.scene import compile_scene, scene_needs_general_kernels
from whitted.kernels.features import EXTRAS_DTYPE
from whitted.render import api, warm_up
from whitted.scene import Scene
from whitted.scene import shapes as sh

BALL = sh.Sphere(radius=1.0)
SHAPES = [
    BALL,
    sh.Plane(),
    sh.Rectangle(corner=(0, 0, 0), edge1=(1, 0, 0), edge2=(0, 1, 0)),
    sh.Disk(radius=1.0),
    sh.Triangle(vertices=((0, 0, 0), (1, 0, 0), (0, 1, 0))),
    sh.Box(min=(-1, -1, -1), max=(1, 1, 1)),
    sh.Cylinder(base=(0, -1, 0), top=(0, 1, 0), radius=0.5),
    sh.Cone(base=(0, -1, 0), top=(0, 1, 0), radius=1.0, top_radius=0.5),
    sh.Torus(major_radius=1.0, minor_radius=0.25),
    sh.CSG(operation="difference", objects=[sh.Box(min=(-1, -1, -1), max=(1, 1, 1)), BALL]),
    sh.Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]]),
]


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.type)
def test_the_scene_test_agrees_with_the_compiled_arrays(shape):
    # without mesh instances, what the scene says before compiling is what the compiled
    # arrays' types say: the general kernels exactly for a torus or a CSG object
    scene = Scene(objects=[BALL, shape])
    general = compile_scene(scene).geometry.unbounded.dtype == np.dtype(EXTRAS_DTYPE)
    assert scene_needs_general_kernels(scene) is general
    assert general is (shape.type in ("torus", "csg"))


def test_an_empty_scene_and_a_scene_of_many_plain_shapes():
    assert scene_needs_general_kernels(Scene()) is False
    many = [sh.Sphere(center=(k, 0, 0), radius=0.5) for k in range(2000)]
    assert scene_needs_general_kernels(Scene(objects=[*many, sh.Plane()])) is False
    assert scene_needs_general_kernels(Scene(objects=[*many, SHAPES[8]])) is True


@pytest.mark.parametrize("shape, given, compiled_first", [
    (BALL, False, [None]),  # the default (plain) kernels first, then the scene's: the same
    (sh.Torus(major_radius=1.0, minor_radius=0.25), False, []),  # the general ones only
    (sh.Torus(major_radius=1.0, minor_radius=0.25), True, []),  # the arrays given: the same
])
def test_a_first_render_compiles_the_plain_kernels_only_for_a_plain_scene(
        monkeypatch, shape, given, compiled_first):
    class Stop(Exception):
        pass

    calls = []

    def warm_up_kernels(compiled=None, builders=False):
        calls.append(compiled)
        if compiled is not None:  # the scene's own variant: enough seen
            raise Stop
        return 0.0

    monkeypatch.setattr(api, "kernels_cached", lambda *key: False)  # a first run
    monkeypatch.setattr(api, "warm_up_kernels", warm_up_kernels)
    scene = Scene(objects=[shape])
    compiled = compile_scene(scene) if given else None
    with pytest.raises(Stop):
        api.RenderJob(scene, compiled=compiled, threads=1).run()
    assert calls[:-1] == compiled_first
    assert warm_up.kernel_variant(calls[-1]) is (shape.type == "torus")


def test_a_large_scene_with_a_torus_compiles_the_plain_kernels_and_builders_first(
        monkeypatch):
    # the plain variant's helper compiles the builders a large scene needs before its
    # arrays can be built; the general kernels come after
    scene = Scene(objects=[sh.Torus(major_radius=1.0, minor_radius=0.25)])
    assert warm_up.first_variant(scene, builders=True) is False
    assert warm_up.first_variant(scene, builders=False) is True
    calls = []

    class Stop(Exception):
        pass

    def warm_up_kernels(compiled=None, builders=False):
        calls.append((compiled, builders))
        raise Stop

    monkeypatch.setattr(api, "kernels_cached", lambda *key: False)
    monkeypatch.setattr(api, "scene_needs_builders", lambda scene: True)
    monkeypatch.setattr(api, "warm_up_kernels", warm_up_kernels)
    with pytest.raises(Stop):
        api.RenderJob(scene, threads=1).run()
    assert calls == [(None, True)]  # the plain kernels, their helper compiling the builders
