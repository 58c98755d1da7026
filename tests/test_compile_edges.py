"""compile/: a mesh of nothing but degenerate triangles is left out with two warnings, and the
scene's own ``render.epsilon`` is the ray offset when given (else 1e-7 of the scene's scale)."""

from __future__ import annotations

import whitted
from whitted.compile.params import render_params
from whitted.compile.scene import compile_scene


def test_a_mesh_with_nothing_to_draw_and_a_given_epsilon():
    scene = whitted.Scene(render={"epsilon": 0.01}, objects=[
        whitted.Mesh(vertices=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], faces=[[0, 1, 2]]),
        whitted.Sphere(radius=1)])
    compiled = compile_scene(scene)
    assert compiled.warnings == [
        "objects[0]: dropped 1 degenerate triangle (zero area or not finite)",
        "objects[0]: no triangles to draw"]
    assert compiled.triangles == 0
    assert render_params(scene, compiled, scene.render).epsilon == 0.01
    # unset: 1e-7 of the scene's scale, here the camera's distance (5) beyond the unit sphere
    auto = scene.with_settings(epsilon=0.0)
    assert render_params(auto, compile_scene(auto), auto.render).epsilon == 5e-7
