"""A big closed mesh used several times (twice in one CSG object, in two CSG objects, in a CSG
object and as a plain instance) is stored once in the mesh table, and every use still finds
the crossings it found with a copy of its own."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

from whitted.compile.csg import CSG_MESH_SCAN
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, surface_normals
from whitted.kernels.layout import BVH_STACK, PRIM_XFORM, SHAPE_CSG_MESH
from whitted.scene import CSG, Box, Material, Mesh, Scene, Transform

SUBDIVISIONS = 3  # 1,280 triangles, 642 vertices: over CSG_MESH_SCAN, so stored with a BVH
TRIANGLES = 20 * 4**SUBDIVISIONS
VERTICES = 10 * 4**SUBDIVISIONS + 2
RIGHT = Transform(translate=(3.0, 0.0, 0.0))
CUT = Box(min=(-2.0, -2.0, -2.0), max=(2.0, 2.0, 0.0))  # keeps the balls' lower halves
RED = Material(color=(0.9, 0.1, 0.1))


@pytest.fixture(scope="module")
def ball_files(tmp_path_factory):
    """A unit icosphere as an OBJ file, and the same bytes under a second name."""
    import trimesh

    folder = tmp_path_factory.mktemp("balls")
    first = folder / "ball.obj"
    trimesh.creation.icosphere(subdivisions=SUBDIVISIONS).export(first)
    second = folder / "ball_copy.obj"
    shutil.copyfile(first, second)
    return first, second


def _scenes(path_a, path_b):
    """name -> objects, the two uses of the ball loaded from ``path_a`` and ``path_b``."""
    a, b = Mesh.from_file(path_a), Mesh.from_file(path_b)
    return {
        "twice in one csg": [CSG(operation="union", objects=[
            a, b.model_copy(update={"transform": RIGHT, "material": RED})])],
        "two csg objects": [CSG(operation="intersection", objects=[a, CUT]),
                            CSG(operation="intersection", objects=[b, CUT], transform=RIGHT)],
        "csg and plain": [CSG(operation="intersection", objects=[a, CUT]),
                          b.model_copy(update={"transform": RIGHT})],
        "plain and csg": [a.model_copy(update={"transform": RIGHT}),
                          CSG(operation="intersection", objects=[b, CUT])],
    }


def _compile(objects):
    # flatten_limit=0: a plain mesh object is an instance of the stored mesh, never copied
    return compile_scene(Scene(objects=objects), flatten_limit=0, light_buffers=False)


def _hits(compiled, rays):
    geo = compiled.geometry
    stack = np.empty(BVH_STACK, np.int32)
    out = []
    for o, d in rays:
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, 0.0, math.inf, stack)
        if prim < 0:
            out.append(None)
            continue
        p = tuple(a + t * c for a, c in zip(o, d, strict=True))
        n, _ = surface_normals(geo, prim, tri, b1, b2, p)
        out.append((t, tuple(n)))
    return out


# down onto and up into each ball (centres x = 0 and 3), at distances 0, 0.3 and 0.5 from
# its axis
RAYS = [((x + dx, 0.0, z0), (0.0, 0.0, -1.0 if z0 > 0 else 1.0))
        for x in (0.0, 3.0) for dx in (0.0, 0.3, 0.5) for z0 in (5.0, -5.0)]


@pytest.mark.parametrize("name", ["twice in one csg", "two csg objects", "csg and plain",
                                  "plain and csg"])
def test_one_big_mesh_used_twice_is_stored_once(ball_files, name):
    assert TRIANGLES > CSG_MESH_SCAN  # a leaf's crossings through the stored mesh's BVH
    same_file, other_file = ball_files
    shared = _compile(_scenes(same_file, same_file)[name])
    apart = _compile(_scenes(same_file, other_file)[name])  # two files: two stored meshes
    assert apart.triangles == 2 * TRIANGLES
    assert len(apart.geometry.mesh_info) == 2
    assert shared.triangles == TRIANGLES
    assert len(shared.geometry.mesh_info) == 1
    assert len(shared.geometry.mesh_vertices) == VERTICES
    assert len(shared.geometry.mesh_faces) == TRIANGLES
    assert shared.instanced_triangles == apart.instanced_triangles
    # every big mesh leaf names the one stored mesh (+1), each with its own transform
    geo = shared.geometry
    leaves = np.flatnonzero(geo.prim_info[:, 0] == SHAPE_CSG_MESH)
    assert len(leaves) == (1 if "plain" in name else 2)
    assert set(geo.prim_params[leaves, 2]) == {1.0}
    if "plain" not in name:
        xforms = geo.prim_info[leaves, PRIM_XFORM]
        assert (xforms >= 0).all() and len(set(xforms)) == 2
        offsets = geo.xforms[xforms][:, :, 3]  # world -> leaf: -translation
        np.testing.assert_allclose(sorted(offsets[:, 0]), [-3.0, 0.0], atol=1e-12)
    # the same crossings as with a stored copy of its own per use: exactly
    a, b = _hits(shared, RAYS), _hits(apart, RAYS)
    assert a == b
    # and the balls': a ray up meets the lower half, one down the top or, where the ball is
    # cut, the box's face z = 0 at t = 5; the flat faces lie within 1 - cos(half an edge's
    # angle) ~ 1.2e-2 of the unit sphere (subdivision 3: edges of about 0.15 radians)
    cut = {"twice in one csg": (), "two csg objects": (0.0, 3.0)}.get(name, (0.0,))
    for (o, d), h in zip(RAYS, a, strict=True):
        centre = 3.0 if o[0] > 1.5 else 0.0
        assert h is not None, o
        if d[2] < 0 and centre in cut:
            assert h[0] == pytest.approx(5.0, rel=1e-12), o
            assert h[1] == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)
        else:
            expected = 5.0 - math.sqrt(1.0 - (o[0] - centre) ** 2)
            assert h[0] == pytest.approx(expected, abs=1.5e-2), o


def test_inline_arrays_reused_share_too():
    # a Mesh object from arrays, used again through model_copy (the same arrays): one entry
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=SUBDIVISIONS)
    mesh = Mesh(vertices=ball.vertices.tolist(), faces=ball.faces.tolist())
    objects = [CSG(operation="intersection", objects=[mesh, CUT]),
               CSG(operation="intersection", objects=[mesh.model_copy(
                   update={"transform": RIGHT})]),
               mesh.model_copy(update={"transform": Transform(translate=(6.0, 0.0, 0.0))})]
    compiled = _compile(objects)
    assert compiled.triangles == TRIANGLES
    assert len(compiled.geometry.mesh_info) == 1
    # the same arrays written again are another mesh (keys are the arrays, not their values)
    again = Mesh(vertices=ball.vertices.tolist(), faces=ball.faces.tolist())
    assert _compile([objects[0], CSG(operation="union", objects=[again])]).triangles == (
        2 * TRIANGLES)


def test_a_leaf_takes_the_entry_of_the_same_mesh_shaded_otherwise(ball_files):
    # the plain instance is smooth-shaded (its entry carries corner normals); a CSG leaf of
    # the same file needs only the triangles and their BVH: it takes that entry
    path, _ = ball_files
    smooth = Mesh.from_file(path, smooth=True)
    compiled = _compile([smooth, CSG(operation="intersection", objects=[
        Mesh.from_file(path), CUT], transform=RIGHT)])
    assert compiled.triangles == TRIANGLES
    # the other way round the instance needs its own normals: a second entry
    flat_first = _compile([CSG(operation="intersection", objects=[Mesh.from_file(path), CUT],
                               transform=RIGHT), smooth])
    assert flat_first.triangles == 2 * TRIANGLES
